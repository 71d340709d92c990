"""The episode player's data: the recording's tables, split per episode, as JSON-ready columns.

Every table the player draws from (``positions``, ``holding``, ``events``,
``attends``, ``relations``, ``attention``; Minigrid's ``facing`` and ``doors``) is embedded as it was recorded,
one column list per schema column without ``episode``, floats at full
precision: the page shows the recording's own values, and
``tests/reports/test_webreport_data.py`` checks that the embedded columns put back
together equal the recording's tables. The map's terrain (walls, mountains,
pits: cells the recording does not list) comes from the environment's layout
after ``reset(seed)``, as :func:`neurosym.viz.recorded.trace_from_recording`
rebuilds it; equal layouts are stored once.
"""

from __future__ import annotations

import math
from typing import Any

import pandas as pd

from neurosym.record.recording import SCHEMA, Recording, empty_table

PLAYER_TABLES = ("positions", "holding", "events", "attends", "relations", "attention")
"""recording tables embedded per episode"""

MINIGRID_TABLES = ("facing", "doors")
"""Minigrid's own tables (the agent's direction, each door's state by its id), embedded per
episode as well when the recording has rows in them: the map draws the agent's direction and
open, closed and locked doors from them"""


def finite(value: float) -> float | None:
    """``value``, or None for NaN and +-inf: JSON has neither, and the page's data block is JSON."""
    return value if math.isfinite(value) else None


def columns(df: pd.DataFrame, drop: tuple[str, ...] = ("episode",)) -> dict[str, list[Any]]:
    """``{column: values}`` of ``df`` without ``drop``; NaN and +-inf become None (not JSON)."""
    out: dict[str, list[Any]] = {}
    for name in df.columns:
        if name in drop:
            continue
        values = df[name].tolist()
        if df[name].dtype.kind == "f":
            values = [v if math.isfinite(v) else None for v in values]
        elif df[name].dtype.kind not in "iub":
            values = [str(v) for v in values]
        out[name] = values
    return out


def _terrain(rec: Recording, episode: int) -> list[list[str]]:
    """(H, W) entity names of the episode's map without the recorded objects and the agent."""
    from neurosym.viz.recorded import trace_from_recording

    grid = trace_from_recording(rec, episode).grids[0].copy()
    first = rec.positions.loc[(rec.positions["episode"] == episode) & (rec.positions["t"] == 0)]
    h, w = grid.shape
    for r, c in zip(first["row"], first["col"], strict=True):
        if 0 <= r < h and 0 <= c < w:
            grid[r, c] = "empty"
    return [[str(x) for x in row] for row in grid]


def player_data(rec: Recording) -> dict[str, Any]:
    """Module, heads, grid shape, terrains and the episodes, each with its tables as columns."""
    meta = rec.meta
    heads = sorted({int(h) for name in ("attends", "attention") for h in rec.tables[name]["head"]})
    if not heads:
        heads = list(range(int(meta.get("heads") or 0)))
    terrains: list[list[list[str]]] = []
    names = PLAYER_TABLES + tuple(n for n in MINIGRID_TABLES if not rec.tables[n].empty)
    by_episode = {name: dict(tuple(rec.tables[name].groupby("episode"))) for name in names}
    steps = dict(tuple(rec.steps.groupby("episode")))
    episodes = []
    for row in rec.episodes.sort_values("episode").to_dict("records"):
        e = int(row["episode"])
        terrain = _terrain(rec, e)
        if terrain not in terrains:
            terrains.append(terrain)
        own = steps.get(e, pd.DataFrame(columns=["t", "action", "reward"])).sort_values("t")
        episodes.append(
            {
                **{c: _cell(row[c], dtype) for c, dtype in SCHEMA["episodes"]},
                "terrain": terrains.index(terrain),
                "actions": [str(a) for a in own["action"]],
                "rewards": [finite(float(r)) for r in own["reward"]],
                "tables": {
                    name: columns(by_episode[name].get(e, _empty(name))) for name in names
                },
            }
        )
    shape = [len(terrains[0]), len(terrains[0][0])] if terrains else [0, 0]
    return {
        "module": str(meta.get("module", "")),
        "heads": heads,
        "relations": int(meta.get("relations") or 0),
        "shape": shape,
        "terrains": terrains,
        "episodes": episodes,
    }


def _cell(value: Any, dtype: str) -> Any:
    """One cell of a recording table as JSON data, by the recording schema's dtype."""
    if dtype == "int64":
        return int(value)
    if dtype == "float64":
        return finite(float(value))
    return str(value)


def _empty(name: str) -> pd.DataFrame:
    if name not in _EMPTY:
        _EMPTY[name] = empty_table(name)
    return _EMPTY[name]


_EMPTY: dict[str, pd.DataFrame] = {}


def entity_styles(names: set[str]) -> dict[str, dict[str, str]]:
    """Fill, text colour and label of every entity name on the page (the viz style's)."""
    from neurosym.viz.style import entity_colour, entity_label, text_colour_on

    out = {}
    for name in sorted(names):
        fill = entity_colour(name)
        out[name] = {"fill": fill, "text": text_colour_on(fill), "label": entity_label(name)}
    return out


def names_in(player: dict[str, Any]) -> set[str]:
    """Every entity name the player draws: terrain cells and recorded object types."""
    names = {x for terrain in player["terrains"] for row in terrain for x in row}
    for ep in player["episodes"]:
        names.update(ep["tables"]["positions"].get("type", []))
    names.add("agent")
    return names
