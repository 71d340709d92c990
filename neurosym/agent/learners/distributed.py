"""Training across processes and machines with torch.distributed (``torchrun``).

``torchrun --nproc_per_node N [--nnodes M ...] -m neurosym train --algo ppo ...``
starts one ``neurosym train`` per rank. Each rank's trainer starts its PPO
learner process as usual; the learners (not the trainers) form the process
group: gloo on the CPU, NCCL on GPUs. Every rank steps its own batched
environments with its own seeds, ``DistributedDataParallel`` averages the
gradients of every minibatch across ranks, so all ranks apply the same
update to the same parameters. Rank 0's trainer alone evaluates, writes
progress, metrics, TensorBoard and checkpoints; its frame and episode counts
are those of all ranks (each update the learners gather their finished
episodes to rank 0). A stop anywhere (frames, minutes, target return on rank
0; Ctrl-C or SIGTERM on any rank) reaches every learner at the next update
through one collective, so all ranks stop together.

Why the learner and not the trainer joins the group: a trainer blocked in a
collective cannot answer a signal, and torchrun ends a failed run with
SIGTERM to every rank (and SIGKILL 30 s later). The trainer never blocks, so
it always writes its checkpoint. Without torchrun (no ``WORLD_SIZE`` in the
environment, or 1) nothing here runs and the command is unchanged.
"""

from __future__ import annotations

import hashlib
import os
import signal
import sys
from dataclasses import dataclass
from datetime import timedelta
from typing import Any

import torch

from neurosym.errors import ConfigError

DEVICES = ("cpu", "cuda", "auto")
COLLECTIVE_TIMEOUT = timedelta(minutes=5)


@dataclass(frozen=True)
class World:
    """This process's place in a torchrun launch (rank 0 of 1 without torchrun)."""

    rank: int = 0
    size: int = 1
    local_rank: int = 0
    local_size: int = 1

    @property
    def distributed(self) -> bool:
        return self.size > 1

    @property
    def leader(self) -> bool:
        """Rank 0: the one that evaluates and writes."""
        return self.rank == 0


def world_from_env(environ: dict[str, str] | None = None) -> World:
    """The torchrun variables (``RANK``, ``WORLD_SIZE``, ``LOCAL_RANK``, ``LOCAL_WORLD_SIZE``)."""
    environ = dict(os.environ if environ is None else environ)

    def read(name: str, default: int) -> int:
        text = environ.get(name)
        if text is None or text == "":
            return default
        try:
            return int(text)
        except ValueError:
            raise ConfigError(f"{name}={text!r} in the environment is not an integer") from None

    size = read("WORLD_SIZE", 1)
    world = World(
        rank=read("RANK", 0),
        size=size,
        local_rank=read("LOCAL_RANK", 0),
        local_size=read("LOCAL_WORLD_SIZE", 1),
    )
    if size < 1 or not 0 <= world.rank < size or not 0 <= world.local_rank < world.local_size:
        raise ConfigError(f"inconsistent torchrun variables: {world}")
    return world


def resolve_device(requested: str, algo: str, say: Any = None) -> str:
    """ "cpu" or "cuda" for ``--device``: cuda without a GPU falls back to the CPU with one line.

    A3C's workers apply their gradients to a model in the machine's shared
    memory (Hogwild); only the synchronous learner can use a GPU.
    """
    if requested not in DEVICES:
        raise ConfigError(f"unknown device {requested!r}; expected one of {', '.join(DEVICES)}")
    if requested == "cpu":
        return "cpu"
    if algo not in ("ppo", "imitate"):
        if requested == "cuda":
            raise ConfigError(
                "--device cuda needs --algo ppo or imitate: A3C's workers update a model in "
                "shared CPU memory"
            )
        return "cpu"
    available = torch.cuda.is_available()
    if requested == "cuda" and not available:
        (say or (lambda text: print(text, file=sys.stderr)))(
            "neurosym: --device cuda: no CUDA GPU is visible (torch.cuda.is_available() is False); "
            "training on the CPU"
        )
    return "cuda" if available else "cpu"


def learner_device(device: str, world: World) -> torch.device:
    """The torch device of this rank's learner (one GPU per local rank)."""
    if device == "cuda":
        index = world.local_rank % max(torch.cuda.device_count(), 1)
        torch.cuda.set_device(index)
        return torch.device("cuda", index)
    return torch.device("cpu")


def init_group(device: torch.device) -> None:
    """Join torchrun's process group (``env://``): NCCL for GPUs, gloo on the CPU.

    A collective waits at most :data:`COLLECTIVE_TIMEOUT` for a rank that is
    gone (ranks wait for each other once per update, which takes seconds), so
    a run whose peer died ends with an error instead of gloo's 30 minutes.
    """
    import torch.distributed as dist

    if not dist.is_initialized():
        dist.init_process_group(
            backend="nccl" if device.type == "cuda" else "gloo", timeout=COLLECTIVE_TIMEOUT
        )


def check_same_config(*configs: Any) -> None:
    """Every rank must train the same model the same way: compare with rank 0 and say what differs."""
    import torch.distributed as dist

    mine = [c.to_dict() if hasattr(c, "to_dict") else c for c in configs]
    every: list[Any] = [None] * dist.get_world_size()
    dist.all_gather_object(every, mine)
    for rank, theirs in enumerate(every):
        if theirs != every[0]:
            diff = [
                f"{k}={b!r} (rank 0: {a!r})"
                for one, other in zip(every[0], theirs, strict=False)
                for k, (a, b) in _pairs(one, other)
                if a != b
            ]
            raise ConfigError(
                f"rank {rank} trains differently from rank 0: {'; '.join(diff) or theirs}; "
                "give every rank the same command"
            )


def _pairs(one: Any, other: Any) -> list[tuple[str, tuple[Any, Any]]]:
    if isinstance(one, dict) and isinstance(other, dict):
        return [(k, (one.get(k), other.get(k))) for k in sorted(set(one) | set(other))]
    return [("value", (one, other))]


def broadcast_optimizer_state(optimizer: torch.optim.Optimizer) -> None:
    """Rank 0's optimiser statistics to every rank (the parameters come with DDP's start)."""
    import torch.distributed as dist

    for group in optimizer.param_groups:
        for p in group["params"]:
            for value in optimizer.state[p].values():
                if torch.is_tensor(value):
                    if value.device.type == "cpu" and dist.get_backend() == "nccl":
                        moved = value.to(p.device)
                        dist.broadcast(moved, 0)
                        value.copy_(moved)
                    else:
                        dist.broadcast(value, 0)


def gather_to_leader(item: Any) -> list[Any] | None:
    """Every rank's ``item`` on rank 0 (in rank order), None on the others."""
    import torch.distributed as dist

    every: list[Any] = [None] * dist.get_world_size()
    dist.all_gather_object(every, item)
    return every if dist.get_rank() == 0 else None


def any_rank(flag: bool, device: torch.device) -> bool:
    """True on every rank when ``flag`` is True on any (one small all-reduce)."""
    import torch.distributed as dist

    value = torch.tensor([1.0 if flag else 0.0], device=device)
    dist.all_reduce(value, op=dist.ReduceOp.MAX)
    return bool(value.item() > 0)


def parameter_digest(model: torch.nn.Module) -> str:
    """SHA-256 of every parameter's bytes: equal digests mean bit-identical weights."""
    h = hashlib.sha256()
    for name, p in model.state_dict().items():
        h.update(name.encode())
        h.update(p.detach().to("cpu").contiguous().numpy().tobytes())
    return h.hexdigest()


def die_with_parent() -> None:
    """Linux: this learner process gets SIGKILL when its trainer dies (even by SIGKILL).

    Otherwise a learner whose trainer was killed lingers, under torchrun blocked in a
    collective until the timeout, holding the launcher's output pipes open.
    """
    if not sys.platform.startswith("linux"):
        return
    import ctypes

    try:
        libc = ctypes.CDLL("libc.so.6", use_errno=True)
        libc.prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except OSError:
        pass


def leave_group() -> None:
    import torch.distributed as dist

    if dist.is_initialized():
        dist.destroy_process_group()
