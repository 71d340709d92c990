"""Resolving a training run (new, resumed, --init-from) without starting a process or writing a file."""

from __future__ import annotations

from pathlib import Path

import pytest
import torch

from neurosym.agent.checkpoint import save_checkpoint
from neurosym.agent.config import A3CConfig, ModelConfig, PPOConfig, TrainConfig
from neurosym.agent.networks.model import ActorCritic
from neurosym.agent.run.options import RunOptions
from neurosym.agent.run.plan import CHECKPOINT_NAME, resolve_run
from neurosym.errors import CheckpointError, ConfigError

CONFIG = ModelConfig.for_family("rgw", "predinet", (9, 10, 10))


def write_run(out: Path, optimizer: bool = True) -> Path:
    """A checkpoint as a run on rgw2 leaves it: 1,234 frames, 5.5 s, one command."""
    out.mkdir(parents=True)
    torch.manual_seed(0)
    model = ActorCritic(CONFIG)
    state = torch.optim.Adam(model.parameters()).state_dict() if optimizer else None
    return save_checkpoint(
        out / CHECKPOINT_NAME,
        model=model,
        config=CONFIG,
        env_name="rgw2",
        train_config=TrainConfig.for_family("rgw", workers=3),
        optimizer_state=state,
        frames=1234,
        episodes=12,
        metrics={"wall_s": 5.5, "solved_frames": 1000},
        command="neurosym train --env rgw2 --module predinet --out run",
    )


def test_a_new_run_is_resolved_without_creating_its_directory(tmp_path: Path) -> None:
    plan = resolve_run("rgw2", "predinet", tmp_path / "run", command="neurosym train ...")
    assert not (tmp_path / "run").exists()
    assert (plan.env_name, plan.family, plan.model_config.module) == ("rgw2", "rgw", "predinet")
    assert (plan.resume, plan.frames0, plan.episodes0, plan.wall0) == (False, 0, 0, 0.0)
    assert plan.train_config == TrainConfig.for_family("rgw")
    assert plan.source is None and plan.optimizer_state is None
    assert plan.command == "neurosym train ..."
    assert plan.learners == plan.train_config.a3c.workers == 2


def test_a_resumed_run_continues_the_checkpoints_counts_settings_and_commands(
    tmp_path: Path,
) -> None:
    write_run(tmp_path / "run")
    plan = resolve_run(
        None, None, tmp_path / "run", resume=True, train_overrides={"lr": 0.01, "seed": None},
        command="neurosym train --out run --resume",
    )  # fmt: skip
    assert (plan.resume, plan.frames0, plan.episodes0, plan.wall0) == (True, 1234, 12, 5.5)
    assert (plan.train_config.a3c.workers, plan.train_config.lr) == (3, 0.01)
    assert plan.model_config == CONFIG
    assert plan.command == (
        "neurosym train --env rgw2 --module predinet --out run && neurosym train --out run --resume"
    )
    assert plan.optimizer_state is not None and plan.options.slim is False


def test_a_resumed_slim_run_stays_slim(tmp_path: Path) -> None:
    write_run(tmp_path / "run", optimizer=False)
    plan = resolve_run(None, None, tmp_path / "run", resume=True)
    assert plan.options.slim is True and plan.optimizer_state is None
    told = resolve_run(None, None, tmp_path / "run", resume=True, options=RunOptions(slim=False))
    assert told.options.slim is False


def test_init_from_starts_a_new_run_from_the_checkpoints_weights(tmp_path: Path) -> None:
    source = write_run(tmp_path / "source")
    plan = resolve_run("rgw1", None, tmp_path / "run", init_from=source, command="neurosym train x")
    assert (plan.resume, plan.frames0, plan.env_name) == (False, 0, "rgw1")
    assert plan.source_path == source and plan.optimizer_state is None
    assert plan.init_meta == {
        "init_from": str(source),
        "init_env": "rgw2",
        "init_frames": 1234,
        "init_wall_s": 5.5,
    }
    assert plan.command.endswith(" && neurosym train x")


def test_resume_of_a_run_that_never_wrote_its_checkpoint_says_what_is_there(
    tmp_path: Path,
) -> None:
    out = tmp_path / "run"
    out.mkdir()
    (out / "metrics.csv").write_text("wall_s,frames\n")
    with pytest.raises(CheckpointError) as info:
        resolve_run(None, None, out, resume=True)
    assert str(info.value) == (
        f"cannot resume: {out} has no checkpoint.pt (it holds metrics.csv); the run never wrote "
        "one: start it again without --resume"
    )
    with pytest.raises(CheckpointError, match="does not exist"):
        resolve_run(None, None, tmp_path / "nowhere", resume=True)


@pytest.mark.parametrize("out", ["file", "/dev/null"])
def test_an_out_that_is_not_a_directory_is_one_line(tmp_path: Path, out: str) -> None:
    path = tmp_path / out if out == "file" else Path(out)
    if out == "file":
        path.write_text("x")
    with pytest.raises(ConfigError) as info:
        resolve_run("rgw2", "predinet", path)
    assert str(info.value) == f"--out {path} is not a directory; the run directory goes there"


def test_a_new_run_refuses_an_existing_checkpoint_and_resume_with_init_from(
    tmp_path: Path,
) -> None:
    source = write_run(tmp_path / "run")
    with pytest.raises(ConfigError, match="already exists; pass --resume"):
        resolve_run("rgw2", "predinet", tmp_path / "run")
    with pytest.raises(ConfigError, match="pass one of them"):
        resolve_run("rgw2", None, tmp_path / "other", resume=True, init_from=source)


def test_frames_at_or_below_what_was_trained_is_refused_before_anything_starts(
    tmp_path: Path,
) -> None:
    write_run(tmp_path / "run")
    with pytest.raises(ConfigError, match="--frames 1000 is not above the 1234 frames"):
        resolve_run(None, None, tmp_path / "run", resume=True, options=RunOptions(frames=1000))


OLD_FLAT_PPO = {
    # a checkpoint's train_config before the per-learner configs: every learner's fields flat
    "algo": "ppo", "preset": "default", "optimizer": "adam", "lr": 5e-4, "entropy": 0.01,
    "gamma": 0.99, "n_steps": 128, "value_coef": 0.5, "explore": 0.0, "explore_half_life": 2000.0,
    "sil": 0.0, "sil_episodes": 32, "rms_eps": 1e-5, "adam_eps": 1e-5, "reward_scale": 0.1,
    "normalize_advantages": True, "gae_lambda": 0.95, "ppo_epochs": 2, "ppo_minibatches": 8,
    "clip_range": 0.1, "ppo_advantages": "running", "rms_alpha": 0.99, "grad_clip": 0.5,
    "workers": 1, "envs": 64, "seed": 7, "critic_warmup": 0, "planner_coef": 0.0,
    "dagger_beta_frames": 200000, "dagger_buffer": 204800, "dagger_batch": 512,
    "dagger_steps": 8, "safe_coef": 0.0, "augment": False,
}  # fmt: skip


def test_the_old_flat_train_config_maps_onto_the_learners_config() -> None:
    config = TrainConfig.from_dict(OLD_FLAT_PPO)
    assert (config.algo, config.lr, config.seed, config.envs) == ("ppo", 5e-4, 7, 64)
    assert config.ppo == PPOConfig(
        ppo_epochs=2, ppo_minibatches=8, clip_range=0.1, ppo_advantages="running"
    )
    assert TrainConfig.from_dict(config.to_dict()) == config
    stored = config.to_dict()  # flat, with PPO's fields only
    assert {k: stored[k] for k in ("ppo_epochs", "clip_range", "lr")} == {
        "ppo_epochs": 2, "clip_range": 0.1, "lr": 5e-4,
    }  # fmt: skip
    assert not {"workers", "sil", "dagger_steps", "critic_warmup", "learner"} & set(stored)
    oldest = {k: v for k, v in OLD_FLAT_PPO.items() if k != "algo"}  # before --algo: A3C
    assert TrainConfig.from_dict(oldest).a3c == A3CConfig(workers=1, sil=0.0, sil_episodes=32)


@pytest.mark.parametrize(
    ("key", "value", "flag"),
    [("critic_warmup", 5000, "--critic-warmup"), ("planner_coef", 0.5, "--planner-coef")],
)
def test_a_run_that_used_a_retired_option_is_refused_in_one_line(
    tmp_path: Path, key: str, value: float, flag: str
) -> None:
    write_run(tmp_path / "run")
    path = tmp_path / "run" / CHECKPOINT_NAME
    payload = torch.load(path, weights_only=True)
    payload["train_config"] = {**OLD_FLAT_PPO, "algo": "a3c", key: value}
    torch.save(payload, path)
    with pytest.raises(CheckpointError) as info:
        resolve_run(None, None, tmp_path / "run", resume=True)
    assert str(info.value) == (
        f"{path}: it was trained with {flag} {value}, an option this version no longer has "
        "(neurosym before its removal plays it)"
    )
    payload["train_config"][key] = 0  # the neutral value of an old record: resumes
    torch.save(payload, path)
    plan = resolve_run(None, None, tmp_path / "run", resume=True)
    assert plan.train_config.a3c.workers == 1 and plan.frames0 == 1234


def test_an_old_model_config_with_the_local_view_off_loads_and_one_that_used_it_is_refused() -> (
    None
):
    data = {**CONFIG.to_dict(), "local_view": 0, "agent_plane": -1}
    assert ModelConfig.from_dict(data) == CONFIG
    with pytest.raises(ConfigError, match="trained with --local-view 3, an option this version"):
        ModelConfig.from_dict({**data, "local_view": 3, "agent_plane": 0})
