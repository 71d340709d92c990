"""Search over Box-World levels: is the gem reachable, how, and are the distractors dead ends?

Used by the tests (generator properties over thousands of seeds) and for
checking hand-built levels. The search runs over abstract states (agent cell,
held key, objects consumed); between two interactions the agent may walk
anywhere in the connected empty region around it, computed by flood fill on
196-bit integer masks (a few big-int operations per dilation), so a level takes
well under a millisecond.

It follows the rules of :mod:`neurosym.envs.boxworld_rules`: a key or gem with
a lock to its right is locked in; walking into a loose key takes it (the held
one is lost); a lock opens with its colour's key and hands over its content;
opening a distractor box ends the episode unless ``stop_at_distractor=False``,
which lets the search go on to show that nothing after a distractor leads to
the gem.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

import numpy as np

from neurosym.envs.boxworld_entities import AGENT, EMPTY, GEM, HELD, KEY, LOCK
from neurosym.envs.boxworld_gen import CELLS, GRID, HELD_CELL, LevelArrays, base_grid
from neurosym.envs.boxworld_rules import DELTA

_STEPS = tuple(int(d) for d in DELTA)  # up, right, down, left as flat-index offsets


@dataclass
class SearchResult:
    """What the search found from a level's start."""

    solvable: bool
    """the gem can be got"""
    min_boxes: int | None
    """fewest boxes opened on a way to the gem (None when unsolvable)"""
    route: list[int] = field(default_factory=list)
    """object cells walked into, in order, on such a way (keys picked, locks opened)"""
    distractors_openable: set[int] = field(default_factory=set)
    """lock cells of distractor boxes the agent can open in some reachable state"""
    gem_after_distractor: bool = False
    """with stop_at_distractor=False: the gem is still reachable after opening a distractor"""
    untouchable_from_start: set[int] = field(default_factory=set)
    """key and lock cells not next to the agent's start region (an object blocks them)"""


def level_grid(levels: LevelArrays, i: int) -> tuple[np.ndarray, np.ndarray, int]:
    """Level i of a batch as (codes (CELLS,), distractor (CELLS,), agent cell)."""
    grid = base_grid()
    distractor = np.zeros(CELLS, bool)
    real = levels.cells[i] >= 0
    cells = levels.cells[i][real].astype(np.int64)
    grid[cells] = levels.codes[i][real]
    distractor[cells] = levels.distractor[i][real]
    agent = int(levels.agent[i])
    grid[agent] = AGENT
    return grid, distractor, agent


def _bits(mask: np.ndarray) -> int:
    return int.from_bytes(np.packbits(mask.astype(bool), bitorder="little").tobytes(), "little")


def _flood(start: int, passable: int) -> int:
    region = 1 << start
    while True:
        grown = (
            region | (region << 1) | (region >> 1) | (region << GRID) | (region >> GRID)
        ) & passable
        grown |= region
        if grown == region:
            return region
        region = grown


def _ring(region: int) -> int:
    return ((region << 1) | (region >> 1) | (region << GRID) | (region >> GRID)) & ~region


def search(
    grid: np.ndarray,
    distractor: np.ndarray,
    agent: int,
    *,
    held: int = -1,
    stop_at_distractor: bool = True,
) -> SearchResult:
    """Search from a state given as codes (CELLS,), distractor flags (CELLS,), the agent's
    cell and the held key's colour (-1 for none)."""
    grid = np.asarray(grid).copy()
    grid[agent] = EMPTY
    objects = [int(c) for c in np.flatnonzero((grid >= GEM) & (grid < HELD))]
    codes = {c: int(grid[c]) for c in objects}
    empty_bits = _bits(grid == EMPTY)
    all_bits = (1 << CELLS) - 1

    def interactions(cell: int, held: int, consumed: int) -> list[tuple[int, int, int, int, bool]]:
        """(object cell, new held, new consumed, boxes opened, is distractor) for each move possible."""
        passable = empty_bits | consumed
        ring = _ring(_flood(cell, passable)) & all_bits
        out = []
        for c in objects:
            if consumed >> c & 1 or not ring >> c & 1:
                continue
            code = codes[c]
            right_is_lock = (
                (c + 1) in codes and not consumed >> (c + 1) & 1 and LOCK <= codes[c + 1] < HELD
            )
            if KEY <= code < LOCK and not right_is_lock:
                out.append((c, code - KEY, consumed | 1 << c, 0, False))
            elif code == GEM and not right_is_lock:
                out.append((c, -2, consumed | 1 << c, 0, False))  # held -2 marks the gem
            elif LOCK <= code < HELD and code - LOCK == held:
                inner = codes.get(c - 1)
                if inner is not None and consumed >> (c - 1) & 1:
                    inner = None
                new_held = (
                    -1
                    if inner is None
                    else (-2 if inner == GEM else (inner - KEY if KEY <= inner < LOCK else -1))
                )
                gone = consumed | 1 << c | (1 << (c - 1) if inner is not None else 0)
                out.append((c, new_held, gone, 1, bool(distractor[c])))
        return out

    result = SearchResult(solvable=False, min_boxes=None)
    start_ring = _ring(_flood(agent, empty_bits)) & all_bits
    boxed = {c for c in objects if codes[c] < LOCK and LOCK <= codes.get(c + 1, -1) < HELD}
    result.untouchable_from_start = {
        c for c in objects if c not in boxed and not start_ring >> c & 1
    }

    # 0-1 BFS: opening a box costs 1, picking a key 0. State: (cell, held, consumed, tainted).
    start = (agent, held, 0, False)
    best: dict[tuple[int, int, int, bool], int] = {start: 0}
    parent: dict[tuple[int, int, int, bool], tuple[tuple[int, int, int, bool], int] | None] = {
        start: None
    }
    queue: deque[tuple[int, int, int, bool]] = deque([start])
    goal: tuple[int, int, int, bool] | None = None
    while queue:
        state = queue.popleft()
        cell, held, consumed, tainted = state
        cost = best[state]
        if held == -2:  # the gem is got
            if tainted:
                result.gem_after_distractor = True
            elif goal is None or cost < best[goal]:
                goal = state
            continue
        for c, new_held, gone, opened, is_distractor in interactions(cell, held, consumed):
            if is_distractor:
                result.distractors_openable.add(c)
                if stop_at_distractor:
                    continue
            nxt = (c, new_held, gone, tainted or is_distractor)
            if nxt not in best or cost + opened < best[nxt]:
                best[nxt] = cost + opened
                parent[nxt] = (state, c)
                if opened:
                    queue.append(nxt)
                else:
                    queue.appendleft(nxt)
    if goal is not None:
        result.solvable = True
        result.min_boxes = best[goal]
        route = []
        node = goal
        while parent[node] is not None:
            node, c = parent[node]
            route.append(c)
        result.route = route[::-1]
    return result


def walk(grid: np.ndarray, agent: int, route: list[int]) -> list[int]:
    """Actions that walk into the route's object cells in order (plain BFS between them).

    The grid is updated as the rules would: keys picked and opened boxes vanish."""
    grid = np.asarray(grid).copy()
    grid[agent] = EMPTY
    actions: list[int] = []
    here = agent
    for target in route:
        prev = {here: (-1, -1)}
        queue = deque([here])
        found = None
        while queue and found is None:
            cell = queue.popleft()
            for a, d in enumerate(_STEPS):
                nxt = cell + d
                if nxt == target:
                    found = (cell, a)
                    break
                if nxt not in prev and grid[nxt] == EMPTY:
                    prev[nxt] = (cell, a)
                    queue.append(nxt)
        if found is None:
            raise ValueError(f"no way to cell {divmod(target, GRID)}")
        path = [found[1]]
        cell = found[0]
        while prev[cell][0] >= 0:
            cell, a = prev[cell]
            path.append(a)
        actions.extend(reversed(path))
        if LOCK <= grid[target] < HELD and grid[target - 1] != EMPTY:
            grid[target - 1] = EMPTY
        grid[target] = EMPTY
        here = target
    return actions


def nearest_interaction(grid: np.ndarray, agent: int, held: int) -> int | None:
    """First action towards the nearest object the agent can use now (a loose key or gem, or
    a lock its key opens, distractors included), or None when there is none.

    A scripted explorer: the tests drive environments with it so that keys, boxes,
    distractors and gems all happen, which random actions rarely reach."""
    grid = np.asarray(grid)

    def usable(cell: int) -> bool:
        code = int(grid[cell])
        boxed = LOCK <= int(grid[cell + 1]) < HELD
        if KEY <= code < LOCK or code == GEM:
            return not boxed
        return LOCK <= code < HELD and code - LOCK == held

    first = {agent: -1}
    queue = deque([agent])
    while queue:
        cell = queue.popleft()
        for a, d in enumerate(_STEPS):
            nxt = cell + d
            if nxt in first:
                continue
            start_action = a if cell == agent else first[cell]
            if usable(nxt):
                return start_action
            if grid[nxt] == EMPTY:
                first[nxt] = start_action
                queue.append(nxt)
    return None


class RouteTargets:
    """Where PrediNet head 0 is taught to look on Box-World (``attend_coef``): per sub-env the
    first object cell on a fewest-boxes route to the gem from the current state (a key to pick
    or a lock to open: the head's second argument) and, when that object is a lock the held key
    opens, the held key's cell (its first argument). A key and the lock it opens are then one
    head's pair, as the world's rule relates them; what the policy reads of that pair (the
    relation bits between them) stays learned.

    The route is searched per state (:func:`search`, a fraction of a millisecond) and kept per
    object layout and held key: walking between interactions leaves both alone.
    """

    MAX_ROUTES = 50_000

    def __init__(self) -> None:
        self._routes: dict[tuple[bytes, int], tuple[int, int]] = {}

    def attention_targets(self, venv: object) -> np.ndarray:
        """(n, 2) int16 cells (row-major, -1 none) for head 0's first and second arguments."""
        env = getattr(venv, "unwrapped", venv)
        grids, distractor, agents, held = env.solver_states()
        if len(self._routes) > self.MAX_ROUTES:
            self._routes.clear()
        out = np.full((len(grids), 2), -1, dtype=np.int16)
        for i in range(len(grids)):
            layout = grids[i].copy()
            layout[agents[i]] = EMPTY  # the agent walks its region without changing the route
            key = (layout.tobytes(), int(held[i]))
            found = self._routes.get(key)
            if found is None:
                found = self._first_contact(grids[i], distractor[i], int(agents[i]), int(held[i]))
                self._routes[key] = found
            out[i] = found
        return out

    @staticmethod
    def _first_contact(
        grid: np.ndarray, distractor: np.ndarray, agent: int, held: int
    ) -> tuple[int, int]:
        result = search(grid, distractor, agent, held=held)
        if not result.route:
            return (-1, -1)
        cell = result.route[0]
        opens = LOCK <= int(grid[cell]) < HELD and held >= 0
        return (HELD_CELL if opens else -1, cell)
