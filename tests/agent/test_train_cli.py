"""`neurosym train` run for real in a subprocess on a tiny budget: outputs, resume, errors, Ctrl-C."""

from __future__ import annotations

import csv
import functools
import os
import re
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest
import torch

from neurosym.agent.agent import load_agent

ROOT = Path(__file__).resolve().parents[2]
ENV = {**os.environ, "PYTHONHASHSEED": "0"}


@pytest.fixture
def neurosym(
    run_neurosym: Callable[..., subprocess.CompletedProcess[str]],
) -> Callable[..., subprocess.CompletedProcess[str]]:
    """The CLI in a subprocess (conftest's run_neurosym) with these tests' 120 s limit."""
    return functools.partial(run_neurosym, timeout=120)


def metrics(out: Path) -> list[dict[str, str]]:
    with (out / "metrics.csv").open(newline="") as fh:
        return list(csv.DictReader(fh))


BW1 = ROOT / "checkpoints" / "bw1-predinet.pt"
MHDPA_RANDOM = ROOT / "checkpoints" / "rgw-random-mhdpa.pt"
TINY = ("--envs", "4", "--quiet", "--eval-interval", "0.5", "--eval-episodes", "2")


@pytest.mark.expensive
def test_train_writes_checkpoint_and_metrics_then_resumes(
    neurosym, train_refused, tmp_path: Path
) -> None:
    out = tmp_path / "run"
    proc = neurosym(
        "train",
        "--env",
        "rgw2",
        "--module",
        "predinet",
        "--out",
        str(out),
        "--workers",
        "2",
        "--frames",
        "3000",
        *TINY,
    )
    assert proc.returncode == 0, proc.stderr
    assert "stopped (frames) after" in proc.stdout
    agent = load_agent(out / "checkpoint.pt", env="rgw2")
    assert agent.config.module == "predinet" and agent.meta["frames"] >= 3000
    assert agent.meta["command"].startswith("neurosym train --env rgw2 --module predinet --out ")
    assert agent.meta["train_config"]["workers"] == 2 and agent.meta["train_config"]["envs"] == 4
    assert agent.meta["metrics"]["stop_reason"] == "frames"
    raw = torch.load(out / "checkpoint.pt", weights_only=True)
    assert raw["optimizer"] is not None  # resumable
    first = metrics(out)
    assert len(first) >= 1 and set(first[0]) >= {
        "wall_s",
        "frames",
        "episodes",
        "fps",
        "mean_return",
        "greedy_return",
    }
    assert int(first[-1]["frames"]) == agent.meta["frames"]

    again = train_refused(
        "train",
        "--env",
        "rgw2",
        "--module",
        "predinet",
        "--out",
        str(out),
        "--frames",
        "3000",
        *TINY,
    )
    assert again.returncode == 1 and "already exists; pass --resume" in again.stderr
    assert len(again.stderr.strip().splitlines()) == 1

    proc = neurosym(
        "train", "--out", str(out), "--resume", "--workers", "1", "--frames", "6000", *TINY
    )
    assert proc.returncode == 0, proc.stderr
    resumed = load_agent(out / "checkpoint.pt")
    assert resumed.meta["frames"] >= 6000 and resumed.meta["frames"] > agent.meta["frames"]
    assert resumed.meta["episodes"] >= agent.meta["episodes"]
    assert resumed.meta["train_config"]["workers"] == 1  # an override on resume
    first_command, _, resume_command = resumed.meta["command"].partition(" && ")
    assert first_command == agent.meta["command"] and "--resume" in resume_command
    rows = metrics(out)
    assert rows[: len(first)] == first and len(rows) > len(first)
    walls = [float(r["wall_s"]) for r in rows]
    assert walls == sorted(walls)

    other = train_refused(
        "train", "--out", str(out), "--resume", "--module", "mhdpa", "--frames", "9000", *TINY
    )
    assert other.returncode == 1
    assert "has a different model config: module 'predinet' (asked for 'mhdpa')" in other.stderr
    assert len(other.stderr.strip().splitlines()) == 1


@pytest.mark.expensive
def test_train_stops_at_target_success_with_learned_queries(neurosym, tmp_path: Path) -> None:
    """--target-success stops the run; --set query=learned trains (A3C's recorded-query path
    included), is kept in the checkpoint and its command, and the saved agent loads with one
    query vector and no projection (one run for both)."""
    # bw1's random policy solves ~20 % of levels: a full window of 10 reaches 10 % within seconds
    out = tmp_path / "run"
    proc = neurosym(
        "train", "--env", "bw1", "--module", "predinet", "--set", "query=learned", "--out", str(out),
        "--workers", "1", "--target-success", "0.1", "--window", "10", "--frames", "500000", *TINY,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "stopped (target) after" in proc.stdout
    agent = load_agent(out / "checkpoint.pt")
    summary = agent.meta["metrics"]
    assert summary["stop_reason"] == "target" and summary["success_rate"] >= 0.1
    assert 0 < summary["solved_frames"] <= agent.meta["frames"] < 500_000
    assert "--target-success 0.1 " in agent.meta["command"]
    last = metrics(out)[-1]
    assert float(last["success_rate"]) >= 0.1 and int(last["frames"]) == agent.meta["frames"]
    assert agent.config.query == "learned" and "--set query=learned" in agent.meta["command"]
    params = dict(agent.model.relational.named_parameters())
    assert "queries" in params and "query1.weight" not in params
    obs = torch.zeros((2, *agent.config.obs_shape), dtype=torch.uint8)
    assert agent.model(obs)[0].shape == (2, 4)


def test_train_keeps_snapshots(neurosym, tmp_path: Path) -> None:
    out = tmp_path / "run"
    proc = neurosym(
        "train", "--env", "rgw2", "--module", "mhdpa", "--out", str(out), "--workers", "1",
        "--frames", "6000", "--heads", "1", "--snapshot-every", "0.002", *TINY,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    snaps = sorted((out / "snapshots").iterdir())
    assert len(snaps) >= 2, snaps
    frames = [load_agent(p).meta["frames"] for p in snaps]
    assert [p.name for p in snaps] == [f"frames-{f:012d}.pt" for f in frames]
    assert (
        frames == sorted(set(frames))
        and frames[-1] <= load_agent(out / "checkpoint.pt").meta["frames"]
    )
    assert "--snapshot-every 0.002" in load_agent(out / "checkpoint.pt").meta["command"]


@pytest.mark.expensive
def test_train_init_from_starts_from_another_checkpoint(neurosym, tmp_path: Path) -> None:
    # a curriculum step: the shipped bw1 agent's weights and model on bw2, learning rate ~0
    out = tmp_path / "run"
    proc = neurosym(
        "train", "--env", "bw2", "--init-from", str(BW1), "--out", str(out), "--workers", "1",
        "--frames", "1000", "--lr", "1e-12", "--slim", *TINY,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    source, agent = load_agent(BW1), load_agent(out / "checkpoint.pt")
    assert agent.env_name == "bw2" and agent.config == source.config
    assert 1000 <= agent.meta["frames"] < source.meta["frames"]  # frames count afresh
    before, after = source.model.state_dict(), agent.model.state_dict()
    assert max(float((before[k] - after[k]).abs().max()) for k in before) < 1e-6
    first, _, last = agent.meta["command"].rpartition(" && ")
    assert first == source.meta["command"]
    assert last.startswith("neurosym train --env bw2 --out ") and f"--init-from {BW1}" in last
    metrics_ = agent.meta["metrics"]
    assert metrics_["init_from"] == str(BW1) and metrics_["init_env"] == "bw1"
    assert metrics_["init_frames"] == source.meta["frames"]
    # the first run may overshoot its budget by the updates in flight when it stops
    more = str(agent.meta["frames"] + 1000)
    resumed = neurosym(
        "train", "--out", str(out), "--resume", "--frames", more, "--lr", "1e-12", *TINY
    )  # fmt: skip
    assert resumed.returncode == 0, resumed.stderr
    again = load_agent(out / "checkpoint.pt")
    assert again.meta["metrics"]["init_frames"] == source.meta["frames"]  # kept on resume
    assert again.meta["command"].startswith(agent.meta["command"] + " && ")


@pytest.mark.expensive
def test_train_mhdpa_single_worker_classic_k1(neurosym, tmp_path: Path) -> None:
    out = tmp_path / "run"
    proc = neurosym(
        "train", "--env", "rgw1", "--module", "mhdpa", "--out", str(out), "--workers", "1", "--envs", "1",
        "--frames", "600", "--quiet", "--slim", "--heads", "2", "--sil", "0",
        "--conv-channels", "8,8,16", "--kernel-size", "3",
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    agent = load_agent(out / "checkpoint.pt")
    assert agent.meta["train_config"]["sil"] == 0.0  # the RGW default is 1.0
    assert "--sil 0" in agent.meta["command"]
    assert "--conv-channels 8,8,16 --kernel-size 3" in agent.meta["command"]
    assert agent.config.module == "mhdpa" and agent.config.heads == 2 and agent.env_name == "rgw1"
    assert agent.config.conv_channels == (8, 8, 16) and agent.config.kernel_size == 3
    assert len(agent.model.encoder.convs) == 3
    assert torch.load(out / "checkpoint.pt", weights_only=True)["optimizer"] is None


@pytest.mark.expensive
def test_train_ppo_on_boxworld_with_tensorboard_then_resumes(
    neurosym, train_refused, tmp_path: Path
) -> None:
    """The synchronous learner: one-hot Box-World by default, event files, resume keeps the algo."""
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    out = tmp_path / "run"
    proc = neurosym(
        "train", "--env", "bw1", "--module", "predinet", "--algo", "ppo", "--out", str(out),
        "--envs", "8", "--n-steps", "16", "--ppo-minibatches", "2", "--frames", "256",
        "--tensorboard", "--quiet", "--eval-interval", "0.5", "--eval-episodes", "2",
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    agent = load_agent(out / "checkpoint.pt")
    assert agent.meta["train_config"]["algo"] == "ppo"
    assert agent.meta["train_config"]["optimizer"] == "adam"
    assert agent.env_kwargs == {"obs_mode": "onehot"} and agent.config.obs_shape == (26, 14, 14)
    assert "--algo ppo" in agent.meta["command"] and "--tensorboard" in agent.meta["command"]
    assert agent.meta["frames"] >= 256
    events = EventAccumulator(str(out / "tensorboard"))
    events.Reload()
    tags = set(events.Tags()["scalars"])
    assert {
        "charts/fps",
        "losses/entropy",
        "losses/policy_loss",
        "losses/approx_kl",
        "losses/clipfrac",
        "losses/explained_variance",
    } <= tags  # no episode ends in 256 frames
    with open(out / "metrics.csv", newline="") as f:
        rows = [r for r in csv.DictReader(f) if r["approx_kl"]]
    assert rows and all(float(r["approx_kl"]) >= 0 for r in rows)
    assert all(0 <= float(r["clip_fraction"]) <= 1 for r in rows)
    steps = [e.step for e in events.Scalars("losses/policy_loss")]
    assert steps and steps == sorted(steps) and steps[-1] <= agent.meta["frames"]

    wrong = train_refused("train", "--out", str(out), "--resume", "--algo", "a3c", "--quiet")
    assert wrong.returncode == 1 and "trained with --algo ppo" in wrong.stderr
    sil = train_refused("train", "--out", str(out), "--resume", "--sil", "1", "--quiet")
    assert sil.returncode == 1 and "--sil is a setting of --algo a3c" in sil.stderr
    again = neurosym(
        "train", "--out", str(out), "--resume", "--frames", str(agent.meta["frames"] + 256),
        "--quiet", "--eval-interval", "0.5", "--eval-episodes", "2",
    )  # fmt: skip
    assert again.returncode == 0, again.stderr
    assert load_agent(out / "checkpoint.pt").meta["frames"] >= agent.meta["frames"] + 256


@pytest.mark.expensive
def test_train_thesis_preset_is_table_4(neurosym, tmp_path: Path) -> None:
    out = tmp_path / "run"
    proc = neurosym(
        "train", "--env", "bw1", "--module", "mhdpa", "--preset", "thesis", "--out", str(out),
        "--workers", "1", "--frames", "200", "--quiet", "--heads", "1",
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    agent = load_agent(out / "checkpoint.pt")
    train = agent.meta["train_config"]
    assert (train["preset"], train["optimizer"], train["rms_eps"], train["lr"]) == (
        "thesis",
        "rmsprop",
        0.1,
        2e-4,
    )
    assert (train["envs"], train["grad_clip"], train["normalize_advantages"]) == (1, 400.0, False)
    assert agent.env_kwargs == {"obs_mode": "rgb"} and agent.config.obs_shape == (3, 14, 14)
    assert (agent.config.entity_norm, agent.config.attention_gain, agent.config.init) == (
        False,
        1.0,
        "torch",
    )
    assert "--preset thesis" in agent.meta["command"]


@pytest.mark.expensive
def test_train_init_from_switches_to_cell_keys_and_resumes(neurosym, tmp_path: Path) -> None:
    """--init-from a trained PrediNet with --keys cells (the rgw2 agent, on rgw-random: the same
    observations): the run's model reads cells in W_K, the switch is in the config and the
    command, and --resume keeps it."""
    source = ROOT / "checkpoints" / "rgw2-predinet.pt"
    assert load_agent(source).config.keys != "cells"
    out = tmp_path / "run"
    proc = neurosym(
        "train", "--env", "rgw-random", "--init-from", str(source), "--keys", "cells",
        "--algo", "imitate", "--augment", "--out", str(out), "--frames", "600", "--slim", *TINY,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    agent = load_agent(out / "checkpoint.pt")
    assert agent.config.keys == "cells" and agent.config.conv_channels == (12, 24)
    assert agent.model.relational.key.weight.shape == (32, 9)
    last = agent.meta["command"].split(" && ")[-1]
    assert f"--init-from {source}" in last and "--keys cells" in last
    proc = neurosym("train", "--out", str(out), "--resume", "--frames", "1200", "--quiet")
    assert proc.returncode == 0, proc.stderr
    again = load_agent(out / "checkpoint.pt")
    assert again.config.keys == "cells" and again.meta["frames"] >= 1200
    obs = torch.zeros((2, *again.config.obs_shape), dtype=torch.uint8)
    assert again.model(obs)[0].shape == (2, 4)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--env", "rgw9", "--module", "predinet"), "rgw9"),
        (
            ("--env", "bw1", "--module", "mhdpa", "--set", "query=learned"),
            "query 'learned' is PrediNet's; mhdpa's queries come from each entity",
        ),
        (("--module", "predinet"), "--env is needed unless --resume"),
        (
            ("--env", "rgw2", "--module", "predinet", "--snapshot-every", "0"),
            "--snapshot-every must be positive minutes, got 0.0",
        ),
        (
            ("--env", "rgw2"),
            "--module (predinet or mhdpa) is needed unless --resume continues a run or --init-from",
        ),
        (
            ("--env", "rgw2", "--module", "predinet", "--lr", "-1"),
            "error: lr must be a finite number in (0, 1], got -1.0",
        ),
        (
            ("--env", "rgw2", "--module", "predinet", "--lr", "1e999"),
            "error: lr must be a finite number in (0, 1], got inf",
        ),
        (
            ("--env", "rgw2", "--module", "predinet", "--sil", "-1"),
            "error: sil must be a finite number in [0, 100], got -1.0",
        ),
        (
            ("--env", "bw1", "--module", "predinet", "--set", "attention_gain=1e999"),
            "error: --set attention_gain=1e999: attention_gain must be a finite number in "
            "(0, 1000], got inf",
        ),
        (
            ("--env", "bw1", "--module", "predinet", "--set", "reward_scale=1e999"),
            "error: --set reward_scale=1e999: reward_scale must be a finite number in (0, 1000], "
            "got inf",
        ),
        (
            ("--env", "bw1", "--module", "predinet", "--set", "value_coef=1e308"),
            "error: --set value_coef=1e308: value_coef must be a finite number in [0, 1000], "
            "got 1e+308",
        ),
        (
            ("--env", "bw1", "--module", "predinet", "--set", "hidden_sizes=100000000"),
            "error: --set hidden_sizes=100000000: hidden_sizes must be 1 to 8 entries, each an "
            "integer in [1, 8192], got 100000000",
        ),
        (
            ("--env", "bw1", "--module", "predinet", "--set", "n_actions=1000"),
            "error: --set n_actions: not a setting; the env's number of actions decides it",
        ),
        (
            ("--env", "bw1", "--module", "predinet", "--set", "hidden_sizes=8192,8192"),
            "error: the model would have 67,384,243 weights, more than the 50,000,000 a run may",
        ),
        (
            ("--env", "bw1", "--module", "predinet", "--envs", "4096", "--n-steps", "1000"),
            "error: envs x n_steps must be at most 1,048,576 states per rollout, got 4096 x 1000",
        ),
        (
            ("--env", "bw1", "--module", "predinet", "--algo", "ppo", "--sil", "1"),
            "--sil is a setting of --algo a3c; this run's learner is ppo",
        ),
        (
            ("--env", "rgw2", "--module", "predinet", "--seed", str(2**64)),
            "--seed must be an integer from 0 to 2**64 - 1, got 18446744073709551616",
        ),
        (
            ("--env", "rgw2", "--module", "predinet", "--set", "critic_warmup=5"),
            "--set wants NAME=VALUE with NAME a setting (adam_eps, attend_coef, attention_gain,",
        ),
        (
            ("--env", "rgw2", "--module", "predinet", "--set", "gae_lambda=high"),
            "--set gae_lambda wants a number (float), got 'high'",
        ),
        (
            ("--env", "bw1", "--module", "mhdpa", "--preset", "thesis", "--algo", "ppo"),
            "--preset thesis is A3C",
        ),
        (
            ("--env", "rgw2", "--module", "predinet", "--frames", "0"),
            "--frames must be a positive integer",
        ),
        (
            ("--env", "bw1", "--module", "predinet", "--target-success", "90"),
            "--target-success must be a rate in (0, 1], such as 0.9; got 90.0",
        ),
        (
            ("--env", "rgw2", "--init-from", str(BW1)),
            "rgw2 is a rgw environment: pick one of bw1, bw2, bw3, boxworld",
        ),
        (
            ("--env", "bw2", "--module", "mhdpa", "--init-from", str(BW1)),
            "has a different model config: module 'predinet' (asked for 'mhdpa')",
        ),
        (
            ("--env", "bw2", "--init-from", str(BW1), "--env-option", "obs_mode=rgb"),
            "expects observations (26, 14, 14), bw2 with these options gives (3, 14, 14)",
        ),
        (("--env", "bw2", "--init-from", str(BW1), "--resume"), "pass one of them"),
        (
            ("--env", "rgw2", "--module", "mhdpa", "--keys", "cells"),
            "keys 'cells' is PrediNet's; mhdpa's keys come from each entity (use keys 'entities')",
        ),
        (
            ("--env", "rgw-random", "--init-from", str(MHDPA_RANDOM), "--keys", "cells"),
            "keys 'cells' is PrediNet's; mhdpa's keys come from each entity",
        ),
        (
            ("--env", "rgw2", "--module", "predinet", "--safe-coef", "2"),
            "--safe-coef is a setting of --algo imitate; this run's learner is a3c",
        ),
        (
            ("--env", "rgw2", "--module", "predinet", "--env-option", "max_steps"),
            "--env-option wants KEY=VALUE",
        ),
    ],
)
def test_train_bad_input_is_one_line(
    train_refused, tmp_path: Path, args: tuple[str, ...], message: str
) -> None:
    proc = train_refused("train", "--out", str(tmp_path / "run"), "--quiet", *args)
    assert proc.returncode == 1, proc.stderr
    assert message in proc.stderr and len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    assert not (tmp_path / "run").exists()


@pytest.mark.parametrize("value", ["12,x", "0,24", ""])
def test_train_bad_conv_channels(train_refused, tmp_path: Path, value: str) -> None:
    proc = train_refused(
        "train", "--env", "rgw2", "--module", "predinet", "--out", str(tmp_path / "run"),
        "--conv-channels", value,
    )  # fmt: skip
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines()[-1] == (
        "neurosym train: error: argument --conv-channels: want comma-separated positive"
        f" channel counts such as 12,24, got {value!r}"
    )
    assert not (tmp_path / "run").exists()


def test_resume_without_checkpoint(neurosym, tmp_path: Path) -> None:
    proc = neurosym("train", "--out", str(tmp_path / "nothing"), "--resume", "--quiet")
    assert proc.returncode == 1
    assert proc.stderr.strip() == (
        f"neurosym train: error: cannot resume: {tmp_path / 'nothing'} does not exist "
        "(start the run without --resume)"
    )


@pytest.mark.expensive
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["ctrl-c", "sigterm"])
def test_ctrl_c_stops_cleanly_with_a_checkpoint(tmp_path: Path, sig: signal.Signals) -> None:
    out = tmp_path / "run"
    proc = subprocess.Popen(
        [sys.executable, "-m", "neurosym", "train", "--env", "rgw2", "--module", "predinet", "--out", str(out),
         "--workers", "2", "--minutes", "5", *TINY],
        cwd=ROOT, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not (out / "metrics.csv").exists():
            time.sleep(0.2)
        assert (out / "metrics.csv").exists(), "training never started"
        proc.send_signal(sig)
        stdout, stderr = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, stderr
    assert "stopped (interrupted)" in stdout
    agent = load_agent(out / "checkpoint.pt")
    assert agent.meta["metrics"]["stop_reason"] == "interrupted" and agent.meta["frames"] > 0


def test_resume_keeps_a_slim_run_slim_unless_told_otherwise(neurosym, tmp_path: Path) -> None:
    """--slim is remembered from the checkpoint (no optimizer state); --no-slim writes it again."""
    out = tmp_path / "run"
    first = neurosym(
        "train", "--env", "rgw1", "--module", "predinet", "--out", str(out), "--workers", "1",
        "--frames", "300", "--slim", *TINY,
    )  # fmt: skip
    assert first.returncode == 0, first.stderr
    ckpt = out / "checkpoint.pt"
    assert torch.load(ckpt, weights_only=True)["optimizer"] is None
    again = neurosym("train", "--out", str(out), "--resume", "--frames", "2000", *TINY)
    assert again.returncode == 0, again.stderr
    assert torch.load(ckpt, weights_only=True)["optimizer"] is None
    full = neurosym("train", "--out", str(out), "--resume", "--frames", "4000", "--no-slim", *TINY)
    assert full.returncode == 0, full.stderr
    payload = torch.load(ckpt, weights_only=True)
    assert payload["optimizer"] is not None
    assert "--no-slim" in payload["command"].split(" && ")[-1]


@pytest.mark.expensive
def test_a_full_disk_leaves_no_run_that_looks_resumable(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The checkpoint cannot be written (a full disk): the one-line error, and no run directory
    holding only metrics.csv, which --resume would take for a run."""
    from neurosym.agent.run import trainer
    from neurosym.agent.run.options import RunOptions
    from neurosym.errors import OutputError

    def full(path: Path, **kwargs: object) -> None:
        raise OutputError(f"cannot write {path}: No space left on device; it was left as it was")

    monkeypatch.setattr(trainer, "save_checkpoint", full)
    out = tmp_path / "run"
    options = RunOptions(frames=100, progress=False, eval_episodes=1, log_interval=0.1,
                         checkpoint_interval=0.2)  # fmt: skip
    with pytest.raises(OutputError, match="No space left on device"):
        trainer.train("rgw2", "predinet", out, train_overrides={"workers": 1, "envs": 2},
                      options=options, print_fn=lambda text: None)  # fmt: skip
    assert not out.exists()
    out.mkdir()
    with pytest.raises(OutputError):
        trainer.train("rgw2", "predinet", out, train_overrides={"workers": 1, "envs": 2},
                      options=options, print_fn=lambda text: None)  # fmt: skip
    assert out.exists() and list(out.iterdir()) == []  # a directory it did not make stays


def test_a_read_only_file_system_is_one_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Where --out cannot be made or written (a read-only file system), one line says so."""
    import errno

    from neurosym.agent.run.trainer import make_run_directory
    from neurosym.errors import ConfigError

    def read_only(self: Path, *args: object, **kwargs: object) -> None:
        raise OSError(errno.EROFS, "Read-only file system")

    with monkeypatch.context() as patch:
        patch.setattr(Path, "mkdir", read_only)
        with pytest.raises(ConfigError) as info:
            make_run_directory(tmp_path / "run")
    assert str(info.value) == (
        f"cannot create the run directory {tmp_path / 'run'}: Read-only file system"
    )
    monkeypatch.setattr(os, "access", lambda path, mode: False)
    with pytest.raises(
        ConfigError, match="^cannot write to the run directory .*: permission denied$"
    ):
        make_run_directory(tmp_path)


def _nan_once_checkpointed(
    checkpoint: Path, make_nan: Callable[..., object]
) -> Callable[..., object]:
    """``make_nan`` told whether to go NaN: once ``checkpoint`` holds some trained frames."""
    late: list[bool] = []

    def wrapped(*args: object, **kwargs: object) -> object:
        if not late and checkpoint.exists():
            if torch.load(checkpoint, weights_only=True)["frames"] > 0:
                late.append(True)
        return make_nan(bool(late), *args, **kwargs)

    return wrapped


@pytest.mark.parametrize("what", ["loss", "weights"])
def test_a_run_that_goes_nan_stops_and_keeps_its_last_finite_checkpoint(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, what: str
) -> None:
    """A loss that turns NaN (the worker refuses the step) or weights that do (the trainer
    finds them): the run stops with one line, and checkpoint.pt holds finite weights."""
    import math

    from neurosym.agent.learners import a3c
    from neurosym.agent.run import trainer
    from neurosym.agent.run.options import RunOptions

    real_loss, real_update = a3c.a3c_loss, a3c.apply_update

    def nan_loss(late: bool, *args: object, **kwargs: object) -> object:
        loss, stats = real_loss(*args, **kwargs)
        return (loss * math.nan if late else loss), stats

    def nan_weights(late: bool, local, shared, *args: object, **kwargs: object) -> object:
        norm = real_update(local, shared, *args, **kwargs)
        if late:  # a step that overflowed: the workers' own check never saw a NaN gradient
            with torch.no_grad():
                next(shared.parameters()).fill_(math.inf)
        return norm

    out = tmp_path / "run"
    if what == "loss":  # forked workers inherit the patch
        monkeypatch.setattr(
            a3c, "a3c_loss", _nan_once_checkpointed(out / "checkpoint.pt", nan_loss)
        )
    else:
        monkeypatch.setattr(
            a3c, "apply_update", _nan_once_checkpointed(out / "checkpoint.pt", nan_weights)
        )
    options = RunOptions(frames=10**7, progress=False, eval_episodes=1, eval_interval=0.2,
                         log_interval=0.1, checkpoint_interval=0.2)  # fmt: skip
    with pytest.raises(trainer.TrainingDiverged) as info:
        trainer.train("rgw1", "predinet", out, options=options, print_fn=lambda text: None,
                      train_overrides={"workers": 1, "envs": 2, "n_steps": 5})  # fmt: skip
    message = str(info.value)
    assert len(message.splitlines()) == 1
    cause = (
        "worker 0: its loss is nan"
        if what == "loss"
        else "its weights [^ ]+ are not finite|worker 0: its loss is nan"
    )
    match = re.fullmatch(
        rf"training diverged at ([\d,]+) frames \(({cause})\); {re.escape(str(out))}/checkpoint.pt "
        r"keeps the last finite weights \(([\d,]+) frames\): lower --lr or the settings that "
        r"scale the loss \(reward_scale, value_coef, attention_gain\)",
        message,
    )
    assert match, message
    kept = torch.load(out / "checkpoint.pt", weights_only=True)
    assert kept["frames"] == int(match.group(match.lastindex).replace(",", ""))
    assert 0 < kept["frames"] <= int(match.group(1).replace(",", ""))
    weights = load_agent(out / "checkpoint.pt").model.state_dict().values()
    assert all(torch.isfinite(v.float()).all() for v in weights)
    assert kept["metrics"]["stop_reason"] == "running"  # the last periodic checkpoint


def test_help_shows_every_flags_default_and_range() -> None:
    import argparse

    from neurosym.agent.run import cli_train

    parser = argparse.ArgumentParser()
    cli_train.configure(parser)
    helps = {a.dest: a.help for a in parser._actions}
    for _, f in cli_train.flag_fields():
        assert "(default " in helps[f.name], f.name
    assert helps["slim"].endswith("(default as the checkpoint a resumed run continues, else off)")
    assert helps["lr"].endswith(
        "(default rgw 0.002, bw 0.0005; --algo ppo 0.0005; --algo imitate 0.0005; range (0, 1])"
    )
    assert helps["frames"].endswith("(default none)")
    assert helps["conv_channels"].endswith("(default 12,24; each in [1, 1024])")
    assert "  query                  PrediNet's queries (default rgw scene, bw learned)" in (
        parser.epilog.splitlines()
    )


def test_every_numeric_setting_declares_its_range() -> None:
    """A number that sizes work or scales the loss is checked where it is declared."""
    from dataclasses import fields

    from neurosym.agent.run import cli_train

    for cls in [cls for _, cls, _ in cli_train.SETTINGS]:
        for f in fields(cls):
            numeric = any(kind in str(f.type) for kind in ("int", "float"))
            if numeric and f.name not in ("seed", "obs_shape"):
                assert "range" in f.metadata, f"{cls.__name__}.{f.name}"
