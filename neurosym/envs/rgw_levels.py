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
from typing import Protocol

import numpy as np

from neurosym.envs import rgw_rules as rules
from neurosym.envs.rgw_maps import GridMap

TERRAIN = np.array([rules.EMPTY, rules.WALL, rules.MOUNTAIN])
"""entity codes that are not named objects (see LevelObjects)"""

ObjectRow = tuple[str, str, int, int]
"""(id, type, row, col) as info["objects"] lists them"""


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

    def levels(self, seeds: np.ndarray, episodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(B, H * W) uint8 cells and (B,) start cells of the keyed levels."""
        ...

    def objects(self, seed: int, episode: int) -> LevelObjects:
        """The named objects of one keyed level."""
        ...

    # Sources with per_episode levels also offer ``ring(n)``: a buffer with
    # ``take(rows, seeds, episodes) -> (cells, starts)`` that generates ahead.


def batch_for(
    source: LevelSource, n: int, *, classic: bool, obs_mode: str, max_steps: int | None
) -> rules.RGWBatch:
    """The rules' state for n envs playing ``source``'s levels; a fixed level is set once here."""
    batch = rules.RGWBatch(
        n,
        source.height,
        source.width,
        classic=classic,
        obs_mode=obs_mode,
        max_steps=max_steps,
        per_env_levels=source.per_episode,
    )
    if not source.per_episode:
        cells, starts = source.levels(np.zeros(1, np.uint64), np.zeros(1, np.int64))
        batch.set_levels(np.zeros(1, np.intp), cells, starts)
    return batch


class FixedLevel:
    """One map for every episode (rgw1, rgw2 or a user's map)."""

    per_episode = False

    def __init__(self, grid_map: GridMap) -> None:
        self.map = grid_map
        self.name = grid_map.name
        self.height, self.width = grid_map.height, grid_map.width
        self._objects = LevelObjects(grid_map.cells, grid_map.width)

    def levels(self, seeds: np.ndarray, episodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        B = len(np.atleast_1d(seeds))
        return np.tile(self.map.cells, (B, 1)), np.full(B, self.map.start, dtype=np.intp)

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
