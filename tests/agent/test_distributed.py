"""Training under torchrun: 2 ranks on one machine, a simulated 2-node run, resume, a killed rank.

The runs are real ``torchrun ... -m neurosym train --algo ppo`` launches on
the CPU (gloo). What is checked: every rank ends with bit-identical
parameters (the learners compare SHA-256 digests of their weights when they
stop, and rank 0 records the verdict in the checkpoint), rank 0 alone
writes, resume continues the frame count, a killed rank still leaves a
loadable checkpoint, and one DDP update on 2 ranks equals the
single-process update on the same total batch.
"""

from __future__ import annotations

import contextlib
import csv
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
import torch

from neurosym.agent.agent import load_agent
from neurosym.agent.checkpoint import read_checkpoint
from neurosym.agent.learners import distributed
from neurosym.errors import ConfigError

REPO = Path(__file__).resolve().parents[2]
TORCHRUN = [sys.executable, "-m", "torch.distributed.run"]
TINY = ["--env", "rgw2", "--module", "predinet", "--algo", "ppo", "--envs", "4", "--n-steps", "16",
        "--ppo-minibatches", "2", "--ppo-epochs", "1", "--quiet", "--eval-episodes", "2"]  # fmt: skip


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def env() -> dict[str, str]:
    path = os.pathsep.join(p for p in (str(REPO), os.environ.get("PYTHONPATH")) if p)
    clean = {k: v for k, v in os.environ.items() if k not in ("RANK", "WORLD_SIZE", "LOCAL_RANK")}
    return {**clean, "PYTHONPATH": path, "PYTHONHASHSEED": "0"}


def torchrun(*args: object, timeout: float = 240) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [*TORCHRUN, *map(str, args)], capture_output=True, text=True, cwd=REPO, env=env(),
        timeout=timeout,
    )  # fmt: skip


def rows(out: Path) -> list[dict[str, str]]:
    with (out / "metrics.csv").open(newline="") as fh:
        return list(csv.DictReader(fh))


def start_two_ranks(out: Path) -> subprocess.Popen[str]:
    """A 2-rank torchrun training into ``out``, returned once it is under way (a row with frames)."""
    proc = subprocess.Popen(
        [*TORCHRUN, "--standalone", "--nproc_per_node", "2", "-m", "neurosym", "train", *TINY,
         "--minutes", "5", "--checkpoint-interval", "600", "--out", str(out)],
        cwd=REPO, env=env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    deadline = time.monotonic() + 180
    while time.monotonic() < deadline:
        if (out / "metrics.csv").exists() and any(int(r["frames"]) > 0 for r in rows(out)):
            return proc
        time.sleep(0.5)
    proc.kill()
    pytest.fail("the run wrote no metrics row with frames in 180 s")


# --- pieces -------------------------------------------------------------------------------


def test_world_from_env_reads_torchrun_variables() -> None:
    assert distributed.world_from_env({}) == distributed.World(0, 1, 0, 1)
    w = distributed.world_from_env(
        {"RANK": "3", "WORLD_SIZE": "4", "LOCAL_RANK": "1", "LOCAL_WORLD_SIZE": "2"}
    )
    assert (w.rank, w.size, w.local_rank, w.distributed, w.leader) == (3, 4, 1, True, False)
    with pytest.raises(ConfigError, match="RANK='x' in the environment is not an integer"):
        distributed.world_from_env({"RANK": "x"})
    with pytest.raises(ConfigError, match="inconsistent torchrun variables"):
        distributed.world_from_env({"RANK": "2", "WORLD_SIZE": "2"})


def test_device_falls_back_with_one_line_and_a3c_stays_on_the_cpu() -> None:
    said: list[str] = []
    assert distributed.resolve_device("cpu", "ppo", said.append) == "cpu"
    with pytest.raises(ConfigError, match="--device cuda needs --algo ppo"):
        distributed.resolve_device("cuda", "a3c")
    assert distributed.resolve_device("auto", "a3c") == "cpu"
    with pytest.raises(ConfigError, match="unknown device 'tpu'; expected one of cpu, cuda, auto"):
        distributed.resolve_device("tpu", "ppo")
    if torch.cuda.is_available():
        pytest.skip("a GPU is visible: the fallback cannot be seen here")
    assert distributed.resolve_device("cuda", "ppo", said.append) == "cpu"
    assert distributed.resolve_device("auto", "ppo", said.append) == "cpu"
    assert len(said) == 1 and "no CUDA GPU is visible" in said[0]


def _ddp_update(rank: int, world: int, port: int, data: str, out: str) -> None:
    """One rank of the DDP half of the equivalence test (forked)."""
    import torch.distributed as dist
    from torch.nn.parallel import DistributedDataParallel

    from neurosym.agent.learners.optimizers import shared_optimizer
    from neurosym.agent.learners.ppo import ppo_update
    from neurosym.agent.rollout import Rollout

    torch.set_num_threads(1)
    os.environ.update(MASTER_ADDR="127.0.0.1", MASTER_PORT=str(port))
    dist.init_process_group("gloo", rank=rank, world_size=world)
    saved = torch.load(data, weights_only=False)
    model, config = saved["model"], saved["config"]
    full = saved["rollout"]
    k = full.actions.shape[1] // world
    mine = slice(rank * k, (rank + 1) * k)  # this rank's envs
    part = Rollout(
        **{
            name: t[:, mine]
            for name, t in full._asdict().items()
            if name != "last_obs" and t is not None  # no planner labels here
        },
        last_obs=full.last_obs[mine],
    )
    ddp = DistributedDataParallel(model)
    opt = shared_optimizer(model.parameters(), config)
    ppo_update(ddp, opt, part, config, torch.Generator().manual_seed(rank))
    torch.save(model.state_dict(), f"{out}.{rank}")
    dist.destroy_process_group()


def test_two_rank_update_equals_one_rank_update_on_the_same_batch(tmp_path: Path) -> None:
    """DDP's gradient average over two halves is the full batch's gradient: same weights after."""
    import copy
    import multiprocessing

    from neurosym.agent.config import ModelConfig, TrainConfig
    from neurosym.agent.learners.optimizers import shared_optimizer
    from neurosym.agent.learners.ppo import ppo_update
    from neurosym.agent.networks.model import ActorCritic
    from neurosym.agent.rollout import RolloutState, collect_rollout
    from neurosym.envs import make_batched

    torch.manual_seed(0)
    venv = make_batched("rgw2", 4, seed=5)
    model = ActorCritic(
        ModelConfig.for_family("rgw", "predinet", venv.single_observation_space.shape, 1.0)
    )
    rollout, _ = collect_rollout(
        model, RolloutState(venv, 5), 8, torch.Generator().manual_seed(1), record=True
    )
    assert bool(rollout.valid.all()), "the equivalence needs equal halves: no episode may end"
    # one minibatch per epoch, advantages as they are: the loss is a plain mean over the batch
    config = TrainConfig.for_family(
        "rgw", algo="ppo", ppo_minibatches=1, ppo_epochs=2, normalize_advantages=False
    )
    data = tmp_path / "data.pt"
    torch.save({"model": copy.deepcopy(model), "config": config, "rollout": rollout}, data)

    single = copy.deepcopy(model)
    opt = shared_optimizer(single.parameters(), config)
    ppo_update(single, opt, rollout, config, torch.Generator().manual_seed(0))

    ctx = multiprocessing.get_context("fork")
    port = free_port()
    procs = [
        ctx.Process(target=_ddp_update, args=(r, 2, port, str(data), str(tmp_path / "w")))
        for r in range(2)
    ]
    for p in procs:
        p.start()
    for p in procs:
        p.join(120)
        assert p.exitcode == 0
    ranks = [torch.load(tmp_path / f"w.{r}") for r in range(2)]
    for name, value in single.state_dict().items():
        assert torch.equal(ranks[0][name], ranks[1][name]), name
        assert torch.allclose(ranks[0][name], value, atol=1e-5, rtol=1e-4), name
    before = model.state_dict()
    assert any(not torch.equal(before[n], v) for n, v in single.state_dict().items())


# --- real torchrun launches ----------------------------------------------------------------


@pytest.mark.expensive
def test_two_ranks_train_one_model_and_resume(tmp_path: Path) -> None:
    out = tmp_path / "run"
    proc = torchrun("--standalone", "--nproc_per_node", 2, "-m", "neurosym", "train", *TINY,
                    "--frames", 400, "--out", out)  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-3000:]
    # rank 0 alone reports; both ranks' learners agreed bit for bit on the weights
    assert proc.stdout.count("stopped (frames) after") == 1, proc.stdout
    payload = read_checkpoint(out / "checkpoint.pt")
    assert payload["metrics"]["ranks"] == 2 and payload["metrics"]["ranks_identical"] is True
    assert payload["frames"] >= 400
    assert payload["command"].startswith("torchrun (WORLD_SIZE=2) -m neurosym train")
    assert sorted(p.name for p in out.iterdir()) == ["checkpoint.pt", "metrics.csv"]
    first = payload["frames"]

    proc = torchrun("--standalone", "--nproc_per_node", 2, "-m", "neurosym", "train", "--resume",
                    "--frames", first + 400, "--out", out, "--quiet")  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-3000:]
    payload = read_checkpoint(out / "checkpoint.pt")
    assert payload["frames"] >= first + 400 and payload["metrics"]["ranks_identical"] is True
    frames = [int(r["frames"]) for r in rows(out)]
    assert frames == sorted(frames) and frames[-1] == payload["frames"]
    load_agent(out / "checkpoint.pt", env="rgw2")  # a plain checkpoint, usable without torchrun


@pytest.mark.expensive
def test_two_nodes_rendezvous_on_localhost(tmp_path: Path) -> None:
    """Two torchrun launches, one per simulated node, meeting at a c10d rendezvous on 127.0.0.1."""
    out = tmp_path / "run"
    port = free_port()
    common = ["--nnodes", 2, "--nproc_per_node", 1, "--rdzv_backend", "c10d",
              "--rdzv_endpoint", f"127.0.0.1:{port}", "--rdzv_id", "neurosym-test"]  # fmt: skip
    args = ["-m", "neurosym", "train", *TINY, "--frames", 300, "--out", out]
    nodes = [
        subprocess.Popen(
            [*TORCHRUN, *map(str, common), "--node_rank", str(i), *map(str, args)],
            cwd=REPO,
            env=env(),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )  # fmt: skip
        for i in range(2)
    ]
    outputs = [n.communicate(timeout=240) for n in nodes]
    for n, (_, err) in zip(nodes, outputs, strict=False):
        assert n.returncode == 0, err[-3000:]
    assert sum(o.count("stopped (frames) after") for o, _ in outputs) == 1
    metrics = read_checkpoint(out / "checkpoint.pt")["metrics"]
    assert metrics["ranks"] == 2 and metrics["ranks_identical"] is True


@pytest.mark.expensive
def test_ctrl_c_to_torchrun_stops_every_rank_with_a_checkpoint(tmp_path: Path) -> None:
    """torchrun passes the SIGINT on to the ranks; they stop together and rank 0 checkpoints."""
    out = tmp_path / "run"
    proc = start_two_ranks(out)
    try:
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    metrics = read_checkpoint(out / "checkpoint.pt")["metrics"]
    assert metrics["stop_reason"] in ("interrupted", "peer"), err[-2000:]
    assert metrics["ranks_identical"] is True, err[-2000:]


def _rank_pid(torchrun_pid: int, rank: int) -> int | None:
    """The pid of the ``neurosym train`` of ``rank`` started by this torchrun (its environment says)."""
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            status = (entry / "status").read_text()
            environ = (entry / "environ").read_bytes().split(b"\0")
        except OSError:
            continue
        ppid = int(
            next(line.split()[1] for line in status.splitlines() if line.startswith("PPid:"))
        )
        if ppid == torchrun_pid and f"RANK={rank}".encode() in environ:
            return int(entry.name)
    return None


@pytest.mark.expensive
def test_a_killed_rank_stops_the_run_with_a_checkpoint(tmp_path: Path) -> None:
    out = tmp_path / "run"
    proc = start_two_ranks(out)
    victim: int | None = None
    try:
        victim = _rank_pid(proc.pid, 1)
        assert victim is not None
        os.kill(victim, signal.SIGKILL)
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
        if victim is not None:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(victim, signal.SIGKILL)  # the killed rank's orphaned learner
    assert proc.returncode != 0  # torchrun reports the failed rank
    assert (out / "checkpoint.pt").exists(), err[-4000:]
    payload = read_checkpoint(out / "checkpoint.pt")  # rank 0 still wrote a whole checkpoint
    assert payload["frames"] > 0
    # torchrun's SIGTERM (interrupted), the learner's lost peer (error), or the killed rank's
    # orphaned learner noticing its parent is gone and ending the run on every rank (peer)
    reason = payload["metrics"]["stop_reason"]
    assert reason in ("interrupted", "error", "peer"), (reason, err[-2000:])
    load_agent(out / "checkpoint.pt", env="rgw2")


def test_a3c_under_torchrun_is_refused_with_one_line(tmp_path: Path) -> None:
    from neurosym.agent.run.trainer import train

    os.environ.update(RANK="0", WORLD_SIZE="2", LOCAL_RANK="0", LOCAL_WORLD_SIZE="2")
    try:
        with pytest.raises(
            ConfigError, match="torchrun trains the synchronous learner: pass --algo ppo"
        ):
            train("rgw2", "predinet", tmp_path / "run")
    finally:
        for name in ("RANK", "WORLD_SIZE", "LOCAL_RANK", "LOCAL_WORLD_SIZE"):
            os.environ.pop(name, None)
