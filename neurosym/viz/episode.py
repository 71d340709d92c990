"""An episode drawn state by state: a strip of panels (PNG/SVG) or an animated GIF.

Each panel shows the grid in entity colours, the agent's route so far (solid
for a step, dotted for a jump such as a teleport) and, for every head, an
arrow from the cell it attends to as its first argument to the cell of its
second (PrediNet: argmax of a1 -> argmax of a2). An MHDPA head gets an arrow
from the agent to the cell the agent's cell attends to most. The last state
has no arrows: the model never acted there.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from neurosym.errors import ConfigError
from neurosym.viz.grid import (
    cell_xy,
    draw_entities,
    draw_route,
    head_arrow,
    label_size,
    mark_agent,
    mark_direction,
    mark_doors,
)
from neurosym.viz.output import save_gif
from neurosym.viz.panels import widen_for_text
from neurosym.viz.sources import EnvLike, Source, load_trace
from neurosym.viz.style import data_as_text, head_colour, legend_text
from neurosym.viz.trace import EpisodeTrace

STRIP_PANEL_INCHES = 2.0
"""width and height of one state in the strip"""

STRIP_COLUMNS = 6
"""states per row of the strip"""

DEFAULT_FRAMES = 12
"""states shown in a strip unless asked otherwise"""

GIF_INCHES = (4.0, 4.6)
"""(width, height) of one GIF frame"""

GIF_DPI = 80
"""resolution of GIF frames: 320 x 368 pixels"""


def parse_steps(text: str | None) -> tuple[int, int | None] | None:
    """``"A:B"`` -> (A, B) (either may be empty), the states to draw; None for all."""
    if text is None:
        return None
    start, sep, stop = text.partition(":")
    try:
        if not sep:
            raise ValueError
        lo = int(start) if start.strip() else 0
        hi = int(stop) if stop.strip() else None
    except ValueError:
        raise ConfigError(f"--steps {text!r}: expected START:STOP, e.g. 0:20 or 5:") from None
    if lo < 0 or (hi is not None and hi < lo):
        raise ConfigError(f"--steps {text!r}: expected 0 <= START <= STOP")
    return lo, hi


def choose_states(
    trace: EpisodeTrace, steps: tuple[int, int | None] | None, frames: int | None
) -> list[int]:
    """States to draw: those in ``steps`` (inclusive), thinned evenly to ``frames`` keeping both ends."""
    last = trace.steps
    lo, hi = steps if steps is not None else (0, None)
    hi = last if hi is None else hi
    if lo > last:
        raise ConfigError(
            f"--steps starts at {lo}, but episode {trace.episode} has states 0..{last}"
        )
    hi = min(hi, last)
    states = np.arange(lo, hi + 1)
    if frames is not None:
        if frames < 1:
            raise ConfigError(f"--frames must be at least 1, got {frames}")
        if len(states) > frames:
            states = states[np.unique(np.linspace(0, len(states) - 1, frames).round().astype(int))]
    return [int(t) for t in states]


def head_pairs(trace: EpisodeTrace, t: int, heads: Sequence[int]) -> list[tuple[int, int, int]]:
    """(head position, from cell, to cell) of each head's arrow at state t ([] at the final state)."""
    if t >= trace.steps:
        return []
    out = []
    for hd in heads:
        i = trace.head_index(hd)
        if trace.attention1 is not None and trace.attention2 is not None:  # PrediNet's pairs
            a1, a2 = trace.attention1[t, i], trace.attention2[t, i]
            if np.isfinite(a1).any() and np.isfinite(a2).any():
                out.append((i, int(np.nanargmax(a1)), int(np.nanargmax(a2))))
        elif trace.mhdpa_focus is not None:
            key = int(trace.mhdpa_focus[t, i])
            agent = trace.grids[t].ravel() == "agent"
            if key >= 0 and agent.any():
                out.append((i, int(agent.argmax()), key))
    return out


def draw_state(
    ax: Axes, trace: EpisodeTrace, t: int, heads: Sequence[int], *, panel_inches: float
) -> None:
    """One state: grid, route so far, head arrows, and a title with the step's action."""
    w = trace.shape[1]
    fontsize = label_size(panel_inches, w)
    draw_entities(ax, trace.grids[t], fontsize=fontsize)
    mark_doors(ax, trace.grids[t], trace.door_states(t), fontsize=fontsize)
    draw_route(ax, trace.agent_path[: t + 1])
    row, col = trace.agent_path[t]
    direction = trace.direction(t)
    if row >= 0 and direction is not None:
        mark_direction(ax, int(row), int(col), direction)
    for i, a, b in head_pairs(trace, t, heads):
        head_arrow(
            ax,
            cell_xy(a, w),
            cell_xy(b, w),
            colour=head_colour(i),
            label=str(trace.heads[i]),
            fontsize=fontsize * 0.9,
        )
    ax.set_title(state_title(trace, t), fontsize=7)


def state_title(trace: EpisodeTrace, t: int) -> str:
    """``t=3 right +0.0`` (the step taken from state t) or ``t=12 end: terminal``; events below."""
    if t < trace.steps:
        head = f"t={t} {trace.actions[t]} {trace.rewards[t]:+.1f}"
    else:
        head = f"t={t} end: {trace.outcome or 'cut short'}"
    events = trace.event_text(t)
    return f"{head}\n{events}" if events else f"{head}\n "


def _heads(trace: EpisodeTrace, head: int | None) -> tuple[int, ...]:
    return trace.heads if head is None else (trace.heads[trace.head_index(head)],)


def _arrow_note(trace: EpisodeTrace, heads: Sequence[int]) -> str:
    if trace.attention1 is not None:
        what = "arrows: each head's E1 -> E2 (argmax of a1 -> a2)"
    else:
        what = "arrows: the cell the agent attends to most, per head"
    return f"{what}; heads " + ", ".join(str(h) for h in heads)


# ---------------------------------------------------------------------------
# strip


def episode_figure(
    source: Source,
    env: EnvLike = None,
    *,
    head: int | None = None,
    episode: int | None = None,
    seed: int = 0,
    steps: tuple[int, int | None] | None = None,
    frames: int | None = DEFAULT_FRAMES,
    max_steps: int | None = None,
) -> Figure:
    """A strip of states of one episode (``frames`` of them, evenly spaced over ``steps``)."""
    trace = load_trace(
        source, env, episode=episode, seed=seed, max_steps=max_steps, keep_attention=set()
    )
    return episode_trace_figure(trace, head=head, steps=steps, frames=frames)


@data_as_text
def episode_trace_figure(
    trace: EpisodeTrace,
    *,
    head: int | None = None,
    steps: tuple[int, int | None] | None = None,
    frames: int | None = DEFAULT_FRAMES,
) -> Figure:
    """:func:`episode_figure` for a trace already built.

    Size: (2.0 * columns + 0.3) x (2.4 * rows + 0.9) inches, at most 6 columns.
    """
    heads = _heads(trace, head)
    states = choose_states(trace, steps, frames)
    n_cols = min(STRIP_COLUMNS, len(states))
    n_rows = -(-len(states) // n_cols)
    fig = Figure(
        figsize=(STRIP_PANEL_INCHES * n_cols + 0.3, (STRIP_PANEL_INCHES + 0.4) * n_rows + 0.9),
        layout="constrained",
    )
    axes = fig.subplots(n_rows, n_cols, squeeze=False)
    for k, ax in enumerate(axes.ravel()):
        if k < len(states):
            draw_state(ax, trace, states[k], heads, panel_inches=STRIP_PANEL_INCHES)
        else:
            ax.set_axis_off()
    outcome = f", outcome {trace.outcome}" if trace.outcome else ""
    total = float(np.sum(trace.rewards))
    title = fig.suptitle(
        f"Episode of {trace.steps} steps, return {total:+.1f}{outcome}\n{trace.title_name}",
        fontsize=10,
    )
    note = fig.supxlabel(
        legend_text(np.concatenate([trace.grids[t].ravel() for t in states]))
        + "\n"
        + _arrow_note(trace, heads),
        fontsize=7,
    )
    widen_for_text(fig, [title, note])
    return fig


# ---------------------------------------------------------------------------
# animation


@data_as_text
def episode_frames(
    trace: EpisodeTrace,
    *,
    head: int | None = None,
    steps: tuple[int, int | None] | None = None,
    every: int = 1,
    dpi: float = GIF_DPI,
) -> list[np.ndarray]:
    """RGB frames (one per drawn state) of the episode, each ``GIF_INCHES`` at ``dpi``."""
    if every < 1:
        raise ConfigError(f"--every must be at least 1, got {every}")
    film = _Film(trace, _heads(trace, head), dpi)
    return [film.frame(t) for t in choose_states(trace, steps, None)[::every]]


class _Film:
    """Frames by blitting: the terrain is rendered once and reused until it changes.

    Only the agent, its route, the head arrows and the step title are drawn per
    frame (a full redraw of every labelled cell costs ~10x more); the terrain
    changes only when an object disappears (a sword picked up, a box opened).
    """

    def __init__(self, trace: EpisodeTrace, heads: Sequence[int], dpi: float) -> None:
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        self.trace, self.heads = trace, heads
        self.fig = Figure(figsize=GIF_INCHES, dpi=dpi)
        self.canvas = FigureCanvasAgg(self.fig)
        self.fig.subplots_adjust(left=0.03, right=0.97, top=0.86, bottom=0.10)
        self.ax = self.fig.add_subplot()
        self.fig.suptitle(trace.title_name, fontsize=7, y=0.985)
        self.fig.text(0.5, 0.02, _arrow_note(trace, heads), ha="center", fontsize=6)
        self.fig.text(0.5, 0.055, legend_text(trace.grids.ravel()), ha="center", fontsize=6)
        self.fontsize = label_size(GIF_INCHES[0] * 0.94, trace.shape[1])
        self.terrain_key: tuple[str, ...] | None = None
        self.background: Any = None

    def _terrain(self, t: int) -> None:
        grid = self.trace.grids[t]
        terrain = np.where(grid == "agent", "empty", grid)  # the agent is drawn per frame
        doors = self.trace.door_states(t)
        key = (*terrain.ravel().tolist(), *map(str, doors))
        if key == self.terrain_key:
            self.canvas.restore_region(self.background)
            return
        self.ax.clear()
        draw_entities(self.ax, terrain, fontsize=self.fontsize)
        mark_doors(self.ax, terrain, doors, fontsize=self.fontsize)
        self.canvas.draw()
        self.background = self.canvas.copy_from_bbox(self.fig.bbox)
        self.terrain_key = key

    def frame(self, t: int) -> np.ndarray:
        self._terrain(t)
        trace, ax, w = self.trace, self.ax, self.trace.shape[1]
        row, col = trace.agent_path[t]
        moving: list[Any] = [draw_route(ax, trace.agent_path[: t + 1])]
        if row >= 0:
            moving += mark_agent(ax, int(row), int(col), fontsize=self.fontsize)
            moving += mark_direction(ax, int(row), int(col), trace.direction(t) or "")
        for i, a, b in head_pairs(trace, t, self.heads):
            moving += head_arrow(
                ax,
                cell_xy(a, w),
                cell_xy(b, w),
                colour=head_colour(i),
                label=str(trace.heads[i]),
                fontsize=self.fontsize * 0.9,
            )
        for artist in moving:
            ax.draw_artist(artist)
        title = self.fig.text(
            0.5, 0.925, state_title(trace, t), ha="center", va="center", fontsize=7
        )
        self.fig.draw_artist(title)
        pixels = np.asarray(self.canvas.buffer_rgba())[..., :3].copy()
        for artist in [*moving, title]:
            artist.remove()
        return pixels


def save_episode_gif(
    source: Source,
    path: str | os.PathLike[str],
    env: EnvLike = None,
    *,
    head: int | None = None,
    episode: int | None = None,
    seed: int = 0,
    steps: tuple[int, int | None] | None = None,
    every: int = 1,
    fps: float = 4.0,
    max_steps: int | None = None,
) -> Path:
    """Write the episode as an animated GIF (320 x 368 pixels per frame), one state per frame."""
    trace = load_trace(
        source, env, episode=episode, seed=seed, max_steps=max_steps, keep_attention=set()
    )
    return save_gif(episode_frames(trace, head=head, steps=steps, every=every), path, fps=fps)
