"""Where Relational-Grid-World levels come from, and the names of their objects.

A level source hands out the cells and start cell of the level an episode is
played on, keyed by ``(seed, episode)``: a fixed map ignores the key, the
procedural generator (:mod:`neurosym.envs.rgw_random`) derives the level from it.
Because the key alone decides the level, the single env and every sub-env of
the batched env see the same levels for the same seeds, and the objects of a
past level can be named again from its key.
"""

from __future__ import annotations

from collections import OrderedDict
from typing import Any, NamedTuple, Protocol

import numpy as np

from neurosym.envs import rgw_rules as rules
from neurosym.envs.rgw_maps import GridMap
from neurosym.envs.rgw_solver import THESIS_RULES, Rules, level_kinds, solve_levels

TERRAIN = np.array([rules.EMPTY, rules.WALL, rules.MOUNTAIN])
"""entity codes that are not named objects (see LevelObjects)"""

ObjectRow = tuple[str, str, int, int]
"""(id, type, row, col) as info["objects"] lists them"""


class LevelInfo(NamedTuple):
    """What each level is, as (B,) arrays; the env's ``info`` reports them by these names.

    Computed once per level (rgw_solver), under the rules the env plays by.
    """

    optimal_return: np.ndarray
    """float64: the best return any route earns within the step limit (NaN: not searched)"""
    guarded: np.ndarray
    """bool: every route to a terminal meets an enemy"""
    needs_teleport: np.ndarray
    """bool: every route to a terminal goes through the teleport"""
    hazard_on_route: np.ndarray
    """bool: every shortest route to a terminal crosses a mountain or a pit"""

    def row(self, i: int) -> dict[str, Any]:
        """Level i's entries as plain Python values (what the single env's info holds)."""
        return {
            "optimal_return": float(self.optimal_return[i]),
            "guarded": bool(self.guarded[i]),
            "needs_teleport": bool(self.needs_teleport[i]),
            "hazard_on_route": bool(self.hazard_on_route[i]),
        }


LEVEL_KEYS: tuple[str, ...] = LevelInfo._fields
"""the info keys that describe the level (beside the state's)"""


def describe_levels(
    cells: np.ndarray, starts: np.ndarray, height: int, width: int, rules_: Rules
) -> LevelInfo:
    """LevelInfo of levels (B, N) by search: optimal return under ``rules_`` and the kinds."""
    sol = solve_levels(cells, starts, height, width, rules_)
    kinds = level_kinds(np.atleast_2d(cells), np.atleast_1d(starts), height, width)
    return LevelInfo(sol.optimal_return, *kinds)


class LevelObjects:
    """The named objects of one level: unique ids in row-major order.

    Walls and mountains are terrain, not objects: they never move, a map has
    dozens of them, and listing them would multiply the ``at/5`` facts of every
    recorded step; the entity grid still names their cells. An object type that
    occurs once is named by its type (``sword``, ``terminal``); types that occur
    several times are numbered ``pit_1``, ``pit_2``, ... The
    agent is always ``agent``. Swords and enemies carry a bit so that the objects
    still on the map can be listed from a ``removed`` bitmask.
    """

    def __init__(self, cells: np.ndarray, width: int) -> None:
        codes = rules.ENTITY_OF_CELL[np.asarray(cells)]
        present = np.flatnonzero(~np.isin(codes, TERRAIN))
        counts = np.bincount(codes[present], minlength=len(rules.ENTITY_NAMES))
        seen = [0] * len(rules.ENTITY_NAMES)
        rows: list[tuple[ObjectRow, int]] = []
        rank = 0
        for cell in present.tolist():
            code = int(codes[cell])
            kind = rules.ENTITY_NAMES[code]
            seen[code] += 1
            ident = kind if counts[code] == 1 else f"{kind}_{seen[code]}"
            bit = 0
            if code in (rules.SWORD, rules.ENEMY):
                bit = 1 << rank
                rank += 1
            r, c = divmod(cell, width)
            rows.append(((ident, kind, r, c), bit))
        self._rows = rows
        self.width = width
        self._visible: dict[int, tuple[ObjectRow, ...]] = {}

    def rows(self, removed: int = 0) -> tuple[ObjectRow, ...]:
        """Objects still on the map (without the agent) given the removed bitmask."""
        got = self._visible.get(removed)
        if got is None:
            got = tuple(row for row, bit in self._rows if not bit & removed)
            self._visible[removed] = got
        return got

    def with_agent(self, pos: int, removed: int = 0) -> tuple[ObjectRow, ...]:
        """info["objects"]: the agent first, then every object still on the map."""
        r, c = divmod(pos, self.width)
        return (("agent", "agent", r, c), *self.rows(removed))


class LevelSource(Protocol):
    """Levels keyed by (seed, episode); see the module docstring."""

    name: str
    height: int
    width: int
    per_episode: bool
    """True when every episode gets its own level (the key matters)"""

    rules: Rules
    """the rules the levels are played by (their optimal returns depend on them)"""

    def levels(
        self, seeds: np.ndarray, episodes: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, LevelInfo]:
        """(B, H * W) uint8 cells, (B,) start cells and the LevelInfo of the keyed levels."""
        ...

    def objects(self, seed: int, episode: int) -> LevelObjects:
        """The named objects of one keyed level."""
        ...

    # Sources with per_episode levels also offer ``ring(n)``: a buffer with
    # ``take(rows, seeds, episodes) -> (cells, starts, info)`` that generates ahead.


def batch_for(
    source: LevelSource,
    n: int,
    *,
    classic: bool,
    obs_mode: str,
    max_steps: int | None,
    enemy: str = "pass",
) -> rules.RGWBatch:
    """The rules' state for n envs playing ``source``'s levels; a fixed level is set once here."""
    assert source.rules == Rules(classic, enemy, max_steps), "the source's rules are the env's"
    batch = rules.RGWBatch(
        n,
        source.height,
        source.width,
        classic=classic,
        obs_mode=obs_mode,
        max_steps=max_steps,
        per_env_levels=source.per_episode,
        enemy=enemy,
    )
    if not source.per_episode:
        cells, starts, _ = source.levels(np.zeros(1, np.uint64), np.zeros(1, np.int64))
        batch.set_levels(np.zeros(1, np.intp), cells, starts)
    return batch


class FixedLevel:
    """One map for every episode (rgw1, rgw2 or a user's map)."""

    per_episode = False

    def __init__(self, grid_map: GridMap, rules_: Rules = THESIS_RULES) -> None:
        self.map = grid_map
        self.rules = rules_
        self.name = grid_map.name
        self.height, self.width = grid_map.height, grid_map.width
        self._objects = LevelObjects(grid_map.cells, grid_map.width)
        self.info = _fixed_info(grid_map, rules_)

    def levels(
        self, seeds: np.ndarray, episodes: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, LevelInfo]:
        B = len(np.atleast_1d(seeds))
        info = LevelInfo(*(np.repeat(a, B) for a in self.info))
        return np.tile(self.map.cells, (B, 1)), np.full(B, self.map.start, dtype=np.intp), info

    def objects(self, seed: int, episode: int) -> LevelObjects:
        return self._objects


class ObjectsCache:
    """A small LRU cache of LevelObjects by key, for sources that regenerate levels."""

    def __init__(self, size: int = 256) -> None:
        self.size = size
        self._items: OrderedDict[tuple[int, int], LevelObjects] = OrderedDict()

    def get(self, key: tuple[int, int]) -> LevelObjects | None:
        item = self._items.get(key)
        if item is not None:
            self._items.move_to_end(key)
        return item

    def put(self, key: tuple[int, int], value: LevelObjects) -> None:
        self._items[key] = value
        if len(self._items) > self.size:
            self._items.popitem(last=False)


_FIXED_INFO: OrderedDict[tuple[Any, ...], LevelInfo] = OrderedDict()


def _fixed_info(grid_map: GridMap, rules_: Rules) -> LevelInfo:
    """A map's LevelInfo, searched once per (map, rules) in a process (envs are made often)."""
    key = (grid_map.cells.tobytes(), grid_map.start, grid_map.height, grid_map.width, rules_)
    info = _FIXED_INFO.get(key)
    if info is None:
        info = describe_levels(
            grid_map.cells[None],
            np.array([grid_map.start]),
            grid_map.height,
            grid_map.width,
            rules_,
        )
        _FIXED_INFO[key] = info
        if len(_FIXED_INFO) > 64:
            _FIXED_INFO.popitem(last=False)
    return info
