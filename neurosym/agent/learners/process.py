"""How every learner is started and what its process does around its work.

A learner is a function ``learner(ctx)`` run in a child process of the
trainer (:class:`Learner`); ``ctx`` (:class:`LearnerContext`) holds all it is
given, the same for A3C, PPO and imitation. It reports through ``ctx.queue``
with the messages of :mod:`neurosym.agent.learners.messages`.
"""

from __future__ import annotations

import contextlib
import signal
import traceback
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any, Protocol

from neurosym.agent.config import ModelConfig, TrainConfig
from neurosym.agent.learners import distributed
from neurosym.agent.learners.allocator import keep_freed_memory
from neurosym.agent.learners.messages import Failed, LossStats, Update
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
    (:func:`distributed.die_with_parent`); any exception becomes a
    :class:`~neurosym.agent.learners.messages.Failed` message; the queue is
    flushed before ``cleanup`` runs (leaving a gloo group whose peer has gone
    can block while holding the GIL, which would starve the queue's feeder thread).
    """
    keep_freed_memory()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    distributed.die_with_parent()
    try:
        yield
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
