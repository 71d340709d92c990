"""What learner processes tell the trainer: one typed message per event.

A learner sends an :class:`Update` after every update, :class:`Stopped` when
it ends on a stop, :class:`Diverged` when an update's gradient is not finite
(it did not take that step), and :class:`Failed` when anything else in it
raised. The trainer reads the fields by name.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from neurosym.agent.rollout import Finished


@dataclass(frozen=True)
class LossStats:
    """One update's diagnostics (per env, summed over time, or per minibatch step for PPO).

    ``approx_kl``, ``clip_fraction`` and ``explained_variance`` are PPO's (NaN
    for the other learners), as SB3 and CleanRL log them: how far each
    minibatch step moved the policy from the one that acted, and how much of
    the rollout's returns' variance the acting critic's values explained (1:
    all, 0: no better than their mean).
    """

    policy_loss: float
    value_loss: float
    entropy: float
    grad_norm: float
    approx_kl: float = math.nan
    clip_fraction: float = math.nan
    explained_variance: float = math.nan


@dataclass(frozen=True)
class Update:
    """A learner finished an update: the frames it trained on and the episodes that ended."""

    rank: int
    frames: int
    finished: Finished
    stats: LossStats


@dataclass(frozen=True)
class Stopped:
    """A learner ended on a stop; ``digests``: every rank's parameter digest (equal when the
    ranks of a distributed run agree; one entry otherwise)."""

    rank: int
    digests: tuple[str, ...] = field(default_factory=tuple)


@dataclass(frozen=True)
class Failed:
    """A learner raised; ``traceback`` is its text, which the trainer reports."""

    rank: int
    traceback: str


@dataclass(frozen=True)
class Diverged:
    """A learner's loss or gradient became inf or NaN; it stopped before stepping with it.
    ``what`` says which, in words."""

    rank: int
    what: str


Message = Update | Stopped | Failed | Diverged
