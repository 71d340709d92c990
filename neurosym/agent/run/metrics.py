"""What a run writes as it goes: metrics.csv rows, TensorBoard scalars, running figures.

:class:`RunningStats` turns the learners' update messages into one row per
log interval; :class:`FrameRate` says how fast the learners go.
"""

from __future__ import annotations

import collections
import csv
import io
import math
from dataclasses import astuple
from pathlib import Path
from typing import Any

import numpy as np

from neurosym.agent.learners.messages import LossStats, Update
from neurosym.agent.rollout import SUCCESS_OUTCOMES
from neurosym.atomic import write_bytes_atomic

METRIC_COLUMNS = (
    "wall_s",
    "frames",
    "episodes",
    "fps",
    "mean_return",
    "success_rate",
    "mean_length",
    "greedy_return",
    "greedy_success",
    "policy_loss",
    "value_loss",
    "entropy",
    "grad_norm",
    "approx_kl",
    "clip_fraction",
    "explained_variance",
)
LOSS_FORMATS = {
    "policy_loss": ".5g",
    "value_loss": ".5g",
    "entropy": ".5g",
    "grad_norm": ".5g",
    "approx_kl": ".3g",
    "clip_fraction": ".3g",
    "explained_variance": ".3g",
}
"""metrics.csv's loss columns (:class:`LossStats` fields) and their number formats"""

def read_rows(path: Path) -> list[dict[str, str]]:
    if not path.exists():
        return []
    with path.open(newline="") as fh:
        return list(csv.DictReader(fh))


def row_frames(row: dict[str, Any]) -> int:
    try:
        return int(row.get("frames") or 0)
    except ValueError:
        return 0


def write_rows(path: Path, rows: list[dict[str, Any]]) -> None:
    buf = io.StringIO()
    writer = csv.DictWriter(
        buf, fieldnames=METRIC_COLUMNS, extrasaction="ignore", lineterminator="\n"
    )
    writer.writeheader()
    writer.writerows(rows)
    write_bytes_atomic(path, buf.getvalue().encode())


class TensorBoard:
    """The metrics rows as TensorBoard scalars against frames, namespaced as SB3/CleanRL do.

    torch's own ``SummaryWriter`` (the ``tensorboard`` package writes the files).
    Tags: ``charts/*`` for returns, success and speed, ``losses/*`` for the
    learner's loss parts.
    """

    TAGS = {
        "mean_return": "charts/episodic_return",
        "success_rate": "charts/success_rate",
        "mean_length": "charts/episodic_length",
        "greedy_return": "charts/greedy_return",
        "greedy_success": "charts/greedy_success",
        "fps": "charts/fps",
        "episodes": "charts/episodes",
        "policy_loss": "losses/policy_loss",
        "value_loss": "losses/value_loss",
        "entropy": "losses/entropy",
        "grad_norm": "losses/grad_norm",
        "approx_kl": "losses/approx_kl",
        "clip_fraction": "losses/clipfrac",
        "explained_variance": "losses/explained_variance",
    }

    def __init__(self, directory: Path) -> None:
        from torch.utils.tensorboard import SummaryWriter

        self.writer = SummaryWriter(log_dir=str(directory))

    def add(self, row: dict[str, Any]) -> None:
        step = int(row["frames"])
        for column, tag in self.TAGS.items():
            text = str(row.get(column, ""))
            if text:
                self.writer.add_scalar(tag, float(text), step)
        self.writer.flush()

    def close(self) -> None:
        self.writer.close()


def fmt(value: float | None, spec: str = ".3f") -> str:
    return (
        ""
        if value is None or (isinstance(value, float) and math.isnan(value))
        else format(value, spec)
    )


class RunningStats:
    """Running figures in the parent, fed by the workers' messages."""

    def __init__(self, frames: int, episodes: int, window: int) -> None:
        self.frames, self.episodes = frames, episodes
        self.returns: collections.deque[float] = collections.deque(maxlen=window)
        self.success: collections.deque[bool] = collections.deque(maxlen=window)
        self.lengths: collections.deque[int] = collections.deque(maxlen=window)
        self.losses: list[LossStats] = []

    def add(self, update: Update) -> None:
        done = update.finished
        self.frames += update.frames
        self.episodes += len(done.returns)
        self.returns.extend(done.returns)
        self.lengths.extend(done.lengths)
        self.success.extend(o in SUCCESS_OUTCOMES for o in done.outcomes)
        self.losses.append(update.stats)

    def mean_return(self) -> float | None:
        return float(np.mean(self.returns)) if self.returns else None

    def success_rate(self) -> float | None:
        return float(np.mean(self.success)) if self.success else None

    def window_full(self) -> bool:
        return len(self.success) == self.success.maxlen

    def row(
        self, wall: float, fps: float, greedy: float | None, greedy_success: float | None
    ) -> dict[str, Any]:
        """One metrics.csv row (strings, blank where unknown); takes the losses since the last row."""
        losses = self.take_losses()
        return {
            "wall_s": fmt(wall, ".2f"),
            "frames": self.frames,
            "episodes": self.episodes,
            "fps": fmt(fps, ".1f"),
            "mean_return": fmt(self.mean_return(), ".4f"),
            "success_rate": fmt(self.success_rate(), ".4f"),
            "mean_length": fmt(float(np.mean(self.lengths)) if self.lengths else None, ".2f"),
            "greedy_return": fmt(greedy, ".4f"),
            "greedy_success": fmt(greedy_success, ".4f"),
            **{
                name: fmt(None if losses is None else getattr(losses, name), spec)
                for name, spec in LOSS_FORMATS.items()
            },
        }

    def take_losses(self) -> LossStats | None:
        """The mean of each loss part over the updates since the last call (None: no update)."""
        if not self.losses:
            return None
        losses = np.asarray([astuple(s) for s in self.losses], dtype=np.float64)  # (updates, parts)
        # a part an update could not measure (NaN: a learner without it, or returns that did
        # not vary for explained_variance) is left out of the mean, not allowed to blank it
        counts = (~np.isnan(losses)).sum(axis=0)
        sums = np.nansum(losses, axis=0)
        self.losses = []
        return LossStats(
            *(float(s / c) if c else math.nan for s, c in zip(sums, counts, strict=True))
        )


class FrameRate:
    """Frames per second between the learners' reports of the last ``window`` seconds.

    A row's own interval is the wrong span for a synchronous learner, which
    reports a large batch of frames once every several seconds: per-row rates
    would alternate between bursts and zeros. Measured from the first to the
    last report in the window, a steady learner's rate is the same on every
    row; once no report has come for a whole window the rate runs to now and
    falls towards 0.
    """

    def __init__(self, now: float, frames: int, window: float = 30.0) -> None:
        self.window = window
        self.points: collections.deque[tuple[float, int]] = collections.deque([(now, frames)])

    def update(self, now: float, frames: int) -> float:
        """Record the frame count at ``now``; the current rate."""
        if frames != self.points[-1][1]:
            self.points.append((now, frames))
        while len(self.points) > 2 and now - self.points[1][0] >= self.window:
            self.points.popleft()
        (t0, f0), (t1, f1) = self.points[0], self.points[-1]
        if len(self.points) > 1 and now - t1 < self.window:
            return (f1 - f0) / max(t1 - t0, 1e-9)
        return (frames - f0) / max(now - t0, 1e-9)


