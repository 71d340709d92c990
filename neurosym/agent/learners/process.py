"""How every learner is started and what its process does around its work.

A learner is a function ``learner(ctx)`` run in a child process of the
trainer (:class:`Learner`); ``ctx`` (:class:`LearnerContext`) holds all it is
given, the same for A3C, PPO and imitation. It reports through ``ctx.queue``
with the messages of :mod:`neurosym.agent.learners.messages`.
"""

from __future__ import annotations

import contextlib
import math
import signal
import traceback
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any, Protocol

import torch

from neurosym.agent.config import ModelConfig, TrainConfig
from neurosym.agent.learners import distributed
from neurosym.agent.learners.allocator import keep_freed_memory
from neurosym.agent.learners.messages import Diverged, Failed, LossStats, Update
from neurosym.agent.networks.model import ActorCritic
from neurosym.agent.rollout import Finished


@dataclass
class LearnerContext:
    """Everything a learner process is started with."""

    rank: int
    """the learner's index in this trainer (A3C: worker w of W; else 0)"""
    shared: ActorCritic
    """the model in shared memory that the trainer evaluates and checkpoints"""
    optimizer: Any
    """the shared optimiser (:mod:`neurosym.agent.learners.optimizers`)"""
    model_config: ModelConfig
    train_config: TrainConfig
    env_name: str
    env_kwargs: dict[str, Any]
    env_seed: int
    """this learner's env and sampling seed"""
    stop: Any
    """a multiprocessing Event: set when the learner should stop"""
    queue: Any
    """a multiprocessing Queue for :mod:`~neurosym.agent.learners.messages`"""
    device: str = "cpu"
    """where a synchronous learner acts and learns (resolved: cpu or cuda)"""
    frames0: int = 0
    """frames the run trained before this session (a resumed run)"""


class Divergence(Exception):
    """Raised in a learner whose update is not finite; its process reports :class:`Diverged`."""


def check_finite(norm: torch.Tensor | float, loss: torch.Tensor | float) -> None:
    """Refuse a step whose clipped gradient's norm is inf or NaN (a loss that is: its gradient
    is too). Call after clipping, before the optimiser's step, so the weights stay finite."""
    if math.isfinite(float(norm)):
        return
    loss_value = float(loss)
    if not math.isfinite(loss_value):
        raise Divergence(f"its loss is {loss_value}")
    raise Divergence(f"its gradient's norm is {float(norm)} (loss {loss_value:.4g})")


class Learner(Protocol):
    """A learner process's entry point."""

    def __call__(self, ctx: LearnerContext) -> None: ...


def report_update(ctx: LearnerContext, frames: int, finished: Finished, stats: LossStats) -> None:
    """Tell the trainer that an update is done."""
    ctx.queue.put(Update(ctx.rank, frames, finished, stats))


@contextlib.contextmanager
def learner_process(
    queue: Any, rank: int, cleanup: Callable[[], None] | None = None
) -> Iterator[None]:
    """What every learner process does around its work (A3C worker, PPO, imitation).

    Freed memory stays in the process for the next update's tensors
    (:mod:`neurosym.agent.learners.allocator`); Ctrl-C is the parent's
    business (SIGINT ignored); the process dies with its trainer
    (:func:`distributed.die_with_parent`); a :class:`Divergence` becomes a
    :class:`~neurosym.agent.learners.messages.Diverged` message, any other exception a
    :class:`~neurosym.agent.learners.messages.Failed` one; the queue is
    flushed before ``cleanup`` runs (leaving a gloo group whose peer has gone
    can block while holding the GIL, which would starve the queue's feeder thread).
    """
    keep_freed_memory()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    distributed.die_with_parent()
    try:
        yield
    except Divergence as exc:
        queue.put(Diverged(rank, str(exc)))
    except BaseException:  # noqa: BLE001 - reported to the parent, which raises it
        queue.put(Failed(rank, traceback.format_exc()))
    finally:
        with contextlib.suppress(Exception):
            queue.close()
            queue.join_thread()
        if cleanup is not None:
            # a peer that died leaves nothing to say goodbye to
            with contextlib.suppress(Exception):
                cleanup()
