"""Drawing a Minigrid level: doors with their state, keys in their colour, the agent's direction,
from a recording and from a live run of the same scripted DoorKey episode."""

from __future__ import annotations

from functools import cache
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.colors import to_hex
from matplotlib.patches import Polygon, Rectangle
from minigrid_scripted import DOOR, DOORKEY, SCRIPT, doorkey_recording, scripted_agent

from neurosym.viz import save_figure, trace_from_agent, trace_from_recording
from neurosym.viz.episode import GIF_DPI, _Film, episode_trace_figure
from neurosym.viz.style import entity_colour
from neurosym.viz.trace import EpisodeTrace


@cache
def recorded() -> EpisodeTrace:
    return trace_from_recording(doorkey_recording())


def test_the_trace_has_directions_and_door_states() -> None:
    trace = recorded()
    assert trace.outcome == "goal" and trace.steps == len(SCRIPT)
    assert trace.facing == ("south",) * 3 + ("east",) * 5 + ("south",) * 2
    assert trace.door_states(4) == [(*DOOR, "locked")]
    assert trace.door_states(5) == [(*DOOR, "open")]
    assert trace.grids[0][DOOR] == "door(yellow)" and "key(yellow)" in set(trace.grids[0].ravel())
    live = trace_from_agent(scripted_agent(), DOORKEY, seed=1)
    assert live.facing == trace.facing
    assert live.doors.values.tolist() == trace.doors.values.tolist()


def _marks(ax: Any) -> dict[str, Any]:
    """What a panel shows on the door's cell and the agent's: keyhole, open outline, direction."""
    rects = [p for p in ax.patches if isinstance(p, Rectangle)]
    return {
        "keyhole": any(to_hex(p.get_facecolor()) == "#000000" and p.get_width() < 0.3
                       for p in rects),  # fmt: skip
        "open": any(p.get_fill() and to_hex(p.get_edgecolor()) == to_hex("yellow")
                    and p.get_width() == 1 for p in rects),  # fmt: skip
        "triangles": [p.get_xy()[0].tolist() for p in ax.patches if isinstance(p, Polygon)],
    }


def test_the_strip_draws_door_states_and_the_direction(tmp_path: Path) -> None:
    trace = recorded()
    fig = episode_trace_figure(trace, steps=(4, 5), frames=None)
    locked, opened = (_marks(ax) for ax in fig.axes[:2])
    assert locked["keyhole"] and not locked["open"]
    assert opened["open"] and not opened["keyhole"]
    # state 4: the agent at (2, 1) faces east: the triangle's tip points right of the centre
    (r, c) = trace.agent_path[4]
    assert len(locked["triangles"]) == 1
    tip_x, tip_y = locked["triangles"][0]
    assert tip_x > c + 0.3 and abs(tip_y - r) < 1e-9
    png = save_figure(fig, tmp_path / "doorkey.png")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_the_animation_redraws_when_the_door_opens() -> None:
    trace = recorded()
    film = _Film(trace, (), GIF_DPI)
    r, c = DOOR

    def pixel(frame: np.ndarray) -> str:  # inside the door's cell, off its label
        x, y = film.ax.transData.transform((c - 0.3, r - 0.3))
        return to_hex(frame[frame.shape[0] - int(round(y)), int(round(x))] / 255)

    locked, opened = film.frame(4), film.frame(5)
    assert pixel(locked) == to_hex("yellow")
    assert pixel(opened) == to_hex(entity_colour("empty"))
