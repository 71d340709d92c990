"""Changed Relational-Grid-World levels for controlled experiments: remove, move, swap objects.

Every change is made on the baseline map's text (:mod:`neurosym.envs.rgw_maps`)
and returns the new map text with the list of cells it changed, so that an
experiment says exactly what it changed (and a test can compare the maps cell
by cell):

* ``remove(X)``: X's cell becomes empty;
* ``move(X, R, C)``: X's cell becomes empty and the free cell (R, C) gets X;
* ``swap(X, Y)``: X's and Y's cells exchange their contents.

Free cells are empty cells (``.``), never the agent's start. Where an object
should go is chosen from what the agent did on the baseline level
(:func:`off_route_cell`, :func:`behind_cell`), with reachability computed by
the env's own move tables (walls, borders, teleports) as a breadth-first
search in array operations.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from neurosym.envs import rgw_rules as rules
from neurosym.envs.rgw_maps import GridMap, parse_map
from neurosym.errors import ConfigError

SYMBOL_OF: dict[str, str] = {"sword": "S", "enemy": "E", "terminal": "T", "pit": "P"}
"""object type -> map character (the objects an experiment may change)"""
_NAME_OF = {
    "S": "sword",
    "E": "enemy",
    "T": "terminal",
    "P": "pit",
    ".": "empty",
    "W": "wall",
    "M": "mountain",
    "O": "teleport",
    "Q": "teleport",
    "A": "agent",
}


@dataclass(frozen=True)
class CellChange:
    """One cell an experiment changed: (row, col), what was there, what is there now."""

    row: int
    col: int
    before: str
    after: str


@dataclass(frozen=True)
class ChangedLevel:
    """A changed map and the cells that differ from the baseline's, row-major."""

    text: str
    changes: tuple[CellChange, ...]


def _chars(grid_map: GridMap) -> np.ndarray:
    """(H, W) map characters, the agent's start 'A'."""
    lines = grid_map.text().splitlines()
    return np.array([list(line) for line in lines])


def _text(chars: np.ndarray) -> str:
    return "\n".join("".join(row) for row in chars) + "\n"


def cell_of(grid_map: GridMap, obj: str) -> tuple[int, int]:
    """(row, col) of the one object of type ``obj``; ConfigError unless exactly one."""
    symbol = SYMBOL_OF.get(obj)
    if symbol is None:
        raise ConfigError(f"cannot change {obj!r}; experiments change {', '.join(SYMBOL_OF)}")
    where = np.argwhere(_chars(grid_map) == symbol)
    if len(where) != 1:
        raise ConfigError(
            f"map {grid_map.name} has {len(where)} {obj} cells; an experiment needs exactly one"
        )
    return int(where[0][0]), int(where[0][1])


def _changed(grid_map: GridMap, chars: np.ndarray) -> ChangedLevel:
    before = _chars(grid_map)
    rows, cols = np.nonzero(before != chars)
    changes = tuple(
        CellChange(int(r), int(c), _NAME_OF[before[r, c]], _NAME_OF[chars[r, c]])
        for r, c in zip(rows.tolist(), cols.tolist(), strict=True)
    )
    text = _text(chars)
    parse_map(text)  # still a playable map
    return ChangedLevel(text, changes)


def remove(grid_map: GridMap, obj: str) -> ChangedLevel:
    """The map with ``obj``'s cell emptied."""
    r, c = cell_of(grid_map, obj)
    chars = _chars(grid_map)
    chars[r, c] = "."
    return _changed(grid_map, chars)


def move(grid_map: GridMap, obj: str, row: int, col: int) -> ChangedLevel:
    """The map with ``obj`` moved onto the free cell (row, col)."""
    r, c = cell_of(grid_map, obj)
    chars = _chars(grid_map)
    if not (0 <= row < grid_map.height and 0 <= col < grid_map.width) or chars[row, col] != ".":
        raise ConfigError(f"cannot move {obj} to ({row}, {col}): not a free cell of the map")
    chars[row, col] = chars[r, c]
    chars[r, c] = "."
    return _changed(grid_map, chars)


def swap(grid_map: GridMap, a: str, b: str) -> ChangedLevel:
    """The map with the cells of ``a`` and ``b`` exchanged."""
    ra, ca = cell_of(grid_map, a)
    rb, cb = cell_of(grid_map, b)
    chars = _chars(grid_map)
    chars[ra, ca], chars[rb, cb] = chars[rb, cb], chars[ra, ca]
    return _changed(grid_map, chars)


def distances(grid_map: GridMap) -> np.ndarray:
    """(H * W,) steps from the start to every cell (-1: unreachable), by the env's move rules.

    Walls, borders and teleports as the env moves; a pit or the terminal ends
    an episode, so the search does not go on from them; the enemy lets the
    agent pass (the default rules).
    """
    cells = grid_map.cells[None, :]
    dest, _ = rules.compile_moves(cells, grid_map.height, grid_map.width, classic=False)
    dest = dest[0]  # (N, 4)
    N = grid_map.height * grid_map.width
    stops = np.isin(grid_map.cells, (rules.PIT, rules.TERMINAL))
    dist = np.full(N, -1, dtype=np.int64)
    dist[grid_map.start] = 0
    frontier = np.array([grid_map.start])
    step = 0
    while frontier.size:
        step += 1
        nxt = np.unique(dest[frontier[~stops[frontier]]].ravel())
        nxt = nxt[dist[nxt] < 0]
        dist[nxt] = step
        frontier = nxt
    return dist


def _free_cells(grid_map: GridMap) -> np.ndarray:
    """(H * W,) True on empty cells other than the start."""
    free = grid_map.cells == rules.EMPTY
    free[grid_map.start] = False
    return free


def off_route_cell(
    grid_map: GridMap, near: tuple[int, int], route: np.ndarray
) -> tuple[int, int] | None:
    """The reachable free cell off every baseline route nearest (Manhattan) to ``near``.

    ``route`` (H * W,) bool: cells the agent stood on in the baseline episodes.
    Ties go to the row-major first. None when every free cell is on a route.
    """
    W = grid_map.width
    ok = _free_cells(grid_map) & ~route & (distances(grid_map) >= 0)
    idx = np.flatnonzero(ok)
    if not idx.size:
        return None
    r, c = np.divmod(idx, W)
    best = idx[np.argmin(np.abs(r - near[0]) + np.abs(c - near[1]))]
    return int(best // W), int(best % W)


def behind_cell(
    grid_map: GridMap, obj: str, route: np.ndarray
) -> tuple[tuple[int, int], str] | None:
    """Where to put the sword "behind" ``obj``: (cell, how) or None.

    ``behind``: the reachable free cell off the routes nearest to ``obj`` among
    those farther from the start than ``obj`` itself (the agent passes ``obj``
    on the way there); ``near``: when no free cell lies farther, the free cell
    off the routes nearest to ``obj``.
    """
    W = grid_map.width
    r0, c0 = cell_of(grid_map, obj)
    dist = distances(grid_map)
    ok = _free_cells(grid_map) & ~route & (dist >= 0)
    farther = ok & (dist > dist[r0 * W + c0])
    for mask, how in ((farther, "behind"), (ok, "near")):
        idx = np.flatnonzero(mask)
        if idx.size:
            r, c = np.divmod(idx, W)
            best = idx[np.argmin(np.abs(r - r0) + np.abs(c - c0))]
            return (int(best // W), int(best % W)), how
    return None
