"""Searches over Relational-Grid-World levels that follow the env's own rules.

Two questions about a level, asked of many levels at once with array operations:

* :func:`solve_levels`: the best return any route earns within the step limit,
  and whether any route reaches a terminal at all (solvable, whatever the
  limit). The search runs over the env's own state space -- agent cell x which swords and enemies are gone
  (holding the sword is "a sword is gone") -- and its transitions are built
  from the very tables the env steps with (:func:`rgw_rules.compile_moves`,
  :func:`rgw_rules.rule_tables`): walls, borders, teleports, mountains' costs,
  pits, the sword, the enemy mode (pass, block, end), classic rules included.
  There is no step cost in RGW; the step limit is the horizon. The values are
  kept in integer tenths (every RGW reward is a multiple of 0.1), so the
  search is exact: a layered Bellman backup ``V_k(s) = max_a r(s, a) +
  V_{k-1}(s')`` (``V_0 = 0``: the episode is cut off) up to ``max_steps``
  layers, stopped early once a layer changes nothing (every later layer would
  be the same).
* :func:`level_kinds`: what a level asks of the agent, by breadth-first search
  over cells: ``guarded`` (every route to a terminal meets an enemy),
  ``needs_teleport`` (every route goes through the teleport),
  ``hazard_on_route`` (every shortest route to a terminal crosses a mountain or
  a pit: the agent pays or detours).

:class:`Plan` keeps every layer of the search and acts optimally from any
state; :class:`Planner` wraps it as a policy for a batched env, the scripted
agent whose evaluation must show ``optimal_rate`` 1.0 (tests/agent/test_evaluation.py).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from neurosym.envs import rgw_rules as rules

UNREACHED = np.int32(1 << 30)

MAX_REMOVABLE = 8
"""swords + enemies a level may have for the optimal-return search (2**8 masks); more gives NaN"""


@dataclass(frozen=True)
class Rules:
    """The rule options the search must share with the env it describes."""

    classic: bool = False
    """the original release's rules (see RGWEnv)"""
    enemy: str = "pass"
    """what an unarmed meeting with the enemy does (rgw_rules.ENEMY_MODES)"""
    max_steps: int | None = 100
    """the env's step limit: the search's horizon (None: until nothing changes)"""


THESIS_RULES = Rules()
"""the default rules: the thesis text, enemy="pass", 100 steps"""


class Solution(NamedTuple):
    """Per level (B,) arrays."""

    optimal_return: np.ndarray
    """float64: best return of any route within the step limit (NaN: not searched)"""
    solvable: np.ndarray
    """bool: some route reaches a terminal (without a step limit)"""


# -- breadth-first search over cells ---------------------------------------------------


def _swap(flat: np.ndarray, i1: np.ndarray, i2: np.ndarray) -> None:
    """Exchange the entries at flat indices i1 and i2 (the two ends of each level's teleport)."""
    a = flat[i1]
    flat[i1] = flat[i2]
    flat[i2] = a


def _padded(x: np.ndarray, height: int, width: int) -> np.ndarray:
    """(B, N) bool -> flat (B * (H + 1) * (W + 1),) with a False guard row and column per level."""
    B = len(x)
    out = np.zeros((B, height + 1, width + 1), dtype=bool)
    out[:, :height, :width] = x.reshape(B, height, width)
    return out.reshape(-1)


def bfs(
    sources: np.ndarray,
    visit: np.ndarray,
    expand: np.ndarray,
    teleports: np.ndarray,
    height: int,
    width: int,
    backward: bool = False,
) -> np.ndarray:
    """Layered search over many levels at once: (B, N) steps from (or, backward, to) ``sources``.

    Forward: a step enters one of the four neighbours; entering a teleport end
    (``teleports`` (B, 2) cells; the same cell twice for no teleport) lands on
    the other end; a cell is entered when ``visit`` allows it and expanded
    further when ``expand`` allows it. Backward gives the steps needed to
    reach the source instead.

    All levels sit in one flat boolean array, each padded with a guard row and
    column that ``visit`` keeps False, so a layer is four shifted ORs over the
    whole batch plus a few masks: no per-level work, no gathers of neighbour lists.
    Unreached cells hold UNREACHED.
    """
    B, N = visit.shape
    W1 = width + 1
    P = (height + 1) * W1
    lvl = np.arange(B)

    def flat_index(cells: np.ndarray) -> np.ndarray:
        r, c = np.divmod(cells, width)
        return lvl * P + r * W1 + c

    i1, i2 = flat_index(teleports[:, 0]), flat_index(teleports[:, 1])
    visit_p = _padded(visit, height, width)
    expand_p = _padded(expand, height, width)
    visited = np.zeros(B * P, dtype=bool)
    visited[flat_index(sources)] = True
    dist = np.full(B * P, UNREACHED, dtype=np.int32)
    dist[visited] = 0
    front = visited.copy()
    d = 0
    while True:
        d += 1
        if backward:
            src = front  # a fresh array each layer, safe to modify
            _swap(src, i1, i2)  # reaching end 1 means entering end 2
        else:
            src = front & expand_p
        new = np.zeros_like(src)
        new[1:] = src[:-1]
        new[:-1] |= src[1:]
        new[W1:] |= src[:-W1]
        new[:-W1] |= src[W1:]
        if not backward:
            _swap(new, i1, i2)  # entering end 1 lands on end 2
        new &= visit_p
        new = new > visited
        if not new.any():
            return dist.reshape(B, height + 1, W1)[:, :height, :width].reshape(B, N)
        visited |= new
        np.copyto(dist, d, where=new)
        front = new


def teleport_pairs(cells: np.ndarray) -> np.ndarray:
    """(B, 2) cells of each level's teleport ends; a level without a teleport gets (0, 0)."""
    is_tele = (cells == rules.TELEPORT) | (cells == rules.TELEPORT_MOUNTAIN)
    first = np.argmax(is_tele, axis=1)
    last = cells.shape[1] - 1 - np.argmax(is_tele[:, ::-1], axis=1)
    has = is_tele.any(axis=1)
    return np.stack([np.where(has, first, 0), np.where(has, last, 0)], axis=1)


def terminal_steps(
    cells: np.ndarray, starts: np.ndarray, height: int, width: int, passable: np.ndarray
) -> np.ndarray:
    """Fewest steps from the start to any terminal over ``passable`` cells (UNREACHED: none).

    ``passable`` may stack several variants of the levels: (V, B, N) gives (V, B).
    """
    is_terminal = cells == rules.TERMINAL
    B, N = cells.shape
    stacked = passable.ndim == 3
    passable = passable.reshape(-1, B, N)
    V = len(passable)
    term = np.broadcast_to(is_terminal, (V, B, N)).reshape(V * B, N)
    d = bfs(
        np.tile(starts, V),
        passable.reshape(V * B, N) | term,
        ~term,
        np.tile(teleport_pairs(cells), (V, 1)),
        height,
        width,
    )
    steps = np.where(term, d, UNREACHED).min(axis=1).reshape(V, B)
    return steps if stacked else steps[0]


class LevelKinds(NamedTuple):
    """Per level (B,) bool arrays: what a level asks of the agent (see the module docstring)."""

    guarded: np.ndarray
    needs_teleport: np.ndarray
    hazard_on_route: np.ndarray


def level_kinds(cells: np.ndarray, starts: np.ndarray, height: int, width: int) -> LevelKinds:
    """The kinds of levels (B, N) with agent starts (B,), by search over cells.

    ``guarded``: with enemies impassable (and pits, which end the episode), no
    route reaches a terminal. ``needs_teleport``: with teleport ends
    impassable, no route does (and with them one does). ``hazard_on_route``:
    the shortest route with mountains and pits counted as empty cells is
    shorter than the shortest route that avoids them, or only the former exists.
    """
    return kinds_and_route(cells, starts, height, width)[0]


def kinds_and_route(
    cells: np.ndarray, starts: np.ndarray, height: int, width: int
) -> tuple[LevelKinds, np.ndarray]:
    """:func:`level_kinds` and (B,) the fewest steps to a terminal avoiding pits, in one search.

    The five variants of the map (clear, no enemy, no teleport, hazards as
    empty, no hazards) are searched side by side as one batch.
    """
    cells = np.atleast_2d(np.asarray(cells))
    starts = np.atleast_1d(np.asarray(starts))
    wall = cells == rules.WALL
    pit = cells == rules.PIT
    enemy = cells == rules.ENEMY
    mountain = cells == rules.MOUNTAIN
    tele = (cells == rules.TELEPORT) | (cells == rules.TELEPORT_MOUNTAIN)
    clear = ~wall & ~pit
    variants = np.stack([clear, clear & ~enemy, clear & ~tele, ~wall, clear & ~mountain])
    route, unguarded, no_tele, geometric, avoiding = terminal_steps(
        cells, starts, height, width, variants
    )
    reach = route < UNREACHED
    kinds = LevelKinds(
        guarded=reach & (unguarded >= UNREACHED),
        needs_teleport=reach & (no_tele >= UNREACHED),
        hazard_on_route=(geometric < UNREACHED) & (avoiding > geometric),
    )
    return kinds, route


# -- the optimal-return search ---------------------------------------------------------


class _Graph(NamedTuple):
    """The search's state graph of B levels, flat: state (level b, mask m, cell p) is
    ``b * S1 + m * N + p``; ``b * S1 + S`` is the level's sink (episode over)."""

    nxt: np.ndarray  # (4, B * S1) intp: next state
    reward: np.ndarray  # (4, B * S1) int32: reward in tenths
    wins: np.ndarray  # (4, B * S1) bool: the step reaches a terminal
    start: np.ndarray  # (B,) intp: the start state
    states: int  # S1 = masks * N + 1


def _graph(cells: np.ndarray, starts: np.ndarray, height: int, width: int, r: Rules) -> _Graph:
    B, N = cells.shape
    removable = (cells == rules.SWORD) | (cells == rules.ENEMY)
    k = int(removable.sum(axis=1).max(initial=0))
    M = 1 << k
    S1 = M * N + 1
    bits = rules.removable_bits(cells)  # (B, N) uint64, bit per sword/enemy
    sword_bits = np.bitwise_or.reduce(
        np.where(cells == rules.SWORD, bits, np.uint64(0)), axis=1
    )  # (B,)
    masks = np.arange(M, dtype=np.uint64)
    holding = ((masks[None, :] & sword_bits[:, None]) != 0).astype(np.intp)[:, :, None]  # (B, M, 1)
    dest, code = rules.compile_moves(cells, height, width, r.classic)  # (B, N, 4)
    T = rules.rule_tables(r.classic, r.enemy)
    tenths = np.rint(T.reward * 10).astype(np.int32)
    assert np.allclose(tenths / 10, T.reward), "RGW rewards are multiples of 0.1"
    # One gather for four flags of the landing: 1 ends, 2 removes, 4 blocked, 8 wins.
    flag_table = (
        T.terminated * 1 + T.removes * 2 + T.blocked * 4 + ((T.events & rules.EV_TERMINAL) != 0) * 8
    ).astype(np.uint8)
    cells_i = cells.astype(np.intp)
    here = np.arange(N)
    base = (np.arange(B, dtype=np.intp) * S1)[:, None, None]
    nxt = np.empty((4, B, S1), dtype=np.intp)
    reward = np.zeros((4, B, S1), dtype=np.int32)
    wins = np.zeros((4, B, S1), dtype=bool)
    for a in range(4):
        d = dest[:, :, a]  # (B, N) where the action leads, before the landing's rule
        bits_d = np.take_along_axis(bits, d, axis=1)[:, None, :]  # (B, 1, N)
        cell_d = np.take_along_axis(cells_i, d, axis=1)[:, None, :]
        gone = (bits_d & masks[None, :, None]) != 0  # (B, M, N): the landing's object is gone
        c = np.where(gone, rules.EMPTY, cell_d)  # (B, M, N) code of the landing cell
        if r.classic:
            held = holding * (here != 0)[None, None, :]  # the original's `state > nS_pos`
            idx = c * 4 + held * 2 + holding
        else:
            stayed = (code[:, None, :, a] & rules.MV_STAY).astype(np.intp)
            idx = c * 4 + holding * 2 + stayed
        f = flag_table.take(idx)
        new_mask = masks[None, :, None] | np.where(f & 2, bits_d, np.uint64(0))
        new_pos = np.where(f & 4, here[None, None, :], d[:, None, :])
        to = np.where(f & 1, M * N, new_mask.astype(np.intp) * N + new_pos) + base
        nxt[a, :, : M * N] = to.reshape(B, M * N)
        reward[a, :, : M * N] = tenths.take(idx).reshape(B, M * N)
        wins[a, :, : M * N] = (f & 8).astype(bool).reshape(B, M * N)
        nxt[a, :, M * N] = base[:, 0, 0] + M * N  # the sink stays put, worth 0
    start = np.arange(B, dtype=np.intp) * S1 + np.asarray(starts, dtype=np.intp)
    return _Graph(nxt.reshape(4, -1), reward.reshape(4, -1), wins.reshape(4, -1), start, S1)


def _backups(
    g: _Graph, horizon: int | None, keep: bool
) -> tuple[list[np.ndarray], np.ndarray, bool]:
    """Layered backups of every level: (the value layers kept, reach of the last layer, settled).

    ``keep`` keeps every layer (for :class:`Plan`, one level); otherwise only the last.
    """
    value = np.zeros(g.nxt.shape[1], dtype=np.int32)
    reach = np.zeros(g.nxt.shape[1], dtype=bool)
    layers = [value]
    limit = horizon if horizon is not None else 4 * g.states
    for _ in range(limit):
        new_value, new_reach = _layer(g.nxt, g.reward, g.wins, value, reach)
        if np.array_equal(new_value, value) and np.array_equal(new_reach, reach):
            return layers, reach, True
        value, reach = new_value, new_reach
        if keep:
            layers.append(value)
        else:
            layers[0] = value
    return layers, reach, horizon is not None


def _layer(
    nxt: np.ndarray, reward: np.ndarray, wins: np.ndarray, value: np.ndarray, reach: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """One Bellman backup of the values and of "a terminal is reachable"."""
    new_value = value.take(nxt[0])
    new_value += reward[0]
    new_reach = reach.take(nxt[0])
    new_reach |= wins[0]
    for a in range(1, 4):
        q = value.take(nxt[a])
        q += reward[a]
        np.maximum(new_value, q, out=new_value)
        w = reach.take(nxt[a])
        w |= wins[a]
        new_reach |= w
    return new_value, new_reach


def _settle(g: _Graph, horizon: int | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(B,) start value in tenths, (B,) reach from the start, (B,) value settled.

    The values stop at the horizon (the step limit); "a terminal is reachable"
    goes on until nothing changes, so solvability does not depend on the step
    limit. Levels are independent, and a level whose layer changed nothing
    stays unchanged, so settled levels leave the arrays once a quarter of them
    has settled (most settle in half the layers the slowest one needs).
    """
    B, S1 = len(g.start), g.states
    limit = 4 * S1 if horizon is None else horizon
    dtype = np.int16 if 10 * limit + 1000 < np.iinfo(np.int16).max else np.int32
    offset = (np.arange(B, dtype=np.intp) * S1)[None, :, None]
    nxt = g.nxt.reshape(4, B, S1) - offset  # (4, B, S1) local state indices
    reward = g.reward.reshape(4, B, S1).astype(dtype)
    wins = g.wins.reshape(4, B, S1)
    start = g.start - offset[0, :, 0]
    live = np.arange(B)
    value = np.zeros((B, S1), dtype=dtype)
    reach = np.zeros((B, S1), dtype=bool)
    out_v = np.zeros(B, dtype=np.int32)
    out_r = np.zeros(B, dtype=bool)
    settled = np.zeros(B, dtype=bool)
    flat = (g.nxt, g.reward.astype(dtype), g.wins)
    for t in range(max(limit, 4 * S1)):
        L = len(live)
        if t < limit:
            new_value, new_reach = _layer(*flat, value.reshape(-1), reach.reshape(-1))
            new_value, new_reach = new_value.reshape(L, S1), new_reach.reshape(L, S1)
        else:  # past the step limit: only reach goes on
            new_value = value
            new_reach = _reach_layer(flat[0], flat[2], reach.reshape(-1)).reshape(L, S1)
        same = (new_value == value).all(axis=1) & (new_reach == reach).all(axis=1)
        value, reach = new_value, new_reach
        fresh = same & ~settled[live]
        if fresh.any():
            rows = np.flatnonzero(fresh)
            out_v[live[rows]] = value[rows, start[live[rows]]]
            out_r[live[rows]] = reach[rows, start[live[rows]]]
            settled[live[rows]] = True
        n_same = int(same.sum())
        if n_same == L:
            return out_v, out_r, settled
        if n_same * 4 >= L:
            keep = np.flatnonzero(~same)
            live = live[keep]
            value, reach = value[keep], reach[keep]
            nxt, reward, wins = nxt[:, keep], reward[:, keep], wins[:, keep]
            local = (np.arange(len(live), dtype=np.intp) * S1)[None, :, None]
            flat = ((nxt + local).reshape(4, -1), reward.reshape(4, -1), wins.reshape(4, -1))
    # Without a step limit some values never settled (classic rules' reward loops).
    rows = np.flatnonzero(~settled[live])
    out_v[live[rows]] = value[rows, start[live[rows]]]
    out_r[live[rows]] = reach[rows, start[live[rows]]]
    return out_v, out_r, settled


def _reach_layer(nxt: np.ndarray, wins: np.ndarray, reach: np.ndarray) -> np.ndarray:
    """One backup of "a terminal is reachable" alone."""
    new_reach = reach.take(nxt[0])
    new_reach |= wins[0]
    for a in range(1, 4):
        w = reach.take(nxt[a])
        w |= wins[a]
        new_reach |= w
    return new_reach


def solve_levels(
    cells: np.ndarray,
    starts: np.ndarray,
    height: int,
    width: int,
    rules_: Rules = THESIS_RULES,
    chunk: int = 1024,
) -> Solution:
    """Best return within the step limit and solvability of levels (B, N) from starts (B,).

    Levels with more than MAX_REMOVABLE swords and enemies get NaN and False
    (the search would need 2**k masks of them).
    """
    cells = np.atleast_2d(np.asarray(cells, dtype=np.uint8))
    starts = np.atleast_1d(np.asarray(starts, dtype=np.intp))
    B = len(cells)
    best = np.full(B, np.nan)
    solvable = np.zeros(B, dtype=bool)
    k = ((cells == rules.SWORD) | (cells == rules.ENEMY)).sum(axis=1)
    for lo in range(0, B, chunk):
        rows = np.arange(lo, min(B, lo + chunk))
        rows = rows[k[rows] <= MAX_REMOVABLE]
        if not len(rows):
            continue
        g = _graph(cells[rows], starts[rows], height, width, rules_)
        value, reach, settled = _settle(g, rules_.max_steps)
        best[rows] = np.where(settled, value / 10.0, np.nan)
        solvable[rows] = reach
    return Solution(best, solvable)


CONTACT_CELLS = frozenset(
    {rules.SWORD, rules.ENEMY, rules.TERMINAL, rules.TELEPORT, rules.TELEPORT_MOUNTAIN, rules.PIT}
)
"""cell codes of the key objects a move contacts (a teleport standing on a mountain too)"""


class Plan:
    """Every layer of the search for a batch of levels: optimal actions from any state.

    ``action(b, pos, removed, remaining)`` picks, for level b with the agent on
    cell ``pos``, the env's ``removed`` bitmask of swords and enemies, and
    ``remaining`` steps left, an action whose value equals the best return
    from there: following it from the start earns the optimal return.
    """

    def __init__(
        self, cells: np.ndarray, starts: np.ndarray, height: int, width: int, rules_: Rules
    ) -> None:
        cells = np.atleast_2d(np.asarray(cells, dtype=np.uint8))
        self.graph = _graph(cells, np.atleast_1d(starts), height, width, rules_)
        self.layers, _, converged = _backups(self.graph, rules_.max_steps, keep=True)
        if not converged:
            raise ValueError("no finite optimal return: the search did not settle")
        self.cells_per_level = height * width
        self.cells = cells
        self.removable = rules.removable_bits(cells)
        self.entered, _ = rules.cell_geometry(height, width)  # (4, N) the cell a move enters
        self._contacts: dict[tuple[int, int, int, int], int] = {}

    def value(self, b: int, pos: int, removed: int, remaining: int) -> float:
        """Best return from that state with ``remaining`` steps left."""
        v = self.layers[min(remaining, len(self.layers) - 1)]
        return float(v[self._state(b, pos, removed)]) / 10.0

    def action(self, b: int, pos: int, removed: int, remaining: int) -> int:
        """An optimal action (0 up, 1 right, 2 down, 3 left) that secures it soonest.

        Among equally good actions it takes one of the fewest-step plan that
        earns the best value (the smallest horizon j <= remaining with
        V_j = V_remaining), so it does not dawdle; then the first of equals.
        """
        return int(np.argmax(self._q(b, pos, removed, remaining)))

    def action_set(self, b: int, pos: int, removed: int, remaining: int) -> np.ndarray:
        """(4,) bool: every action :meth:`action` could have picked (all of the fastest plan's equals).

        Imitation learns from this set, not from the first of equals: which
        of two equally short routes the planner lists first is no property
        of the level a network could see.
        """
        q = self._q(b, pos, removed, remaining)
        return q == q.max()

    def regret(self, b: int, pos: int, removed: int, remaining: int) -> np.ndarray:
        """(4,) return each action gives up: the best return from the state minus the best after it.

        0 for every action that keeps the optimum in reach (faster or not),
        0.1 for a step onto a mountain a free route avoids, and so on. What a
        sampled policy loses by its mass on an action, whatever the route's length.
        """
        s = self._state(b, pos, removed)
        last = len(self.layers) - 1  # V_i = V_last for every i >= last
        left = max(remaining, 1)
        g = self.graph
        after = self.layers[min(left - 1, last)]  # V_{remaining - 1}, not the layer before last
        q = g.reward[:, s] + after.take(g.nxt[:, s])
        return (int(self.layers[min(left, last)][s]) - q).astype(np.float32) / 10.0

    def next_contact(self, b: int, pos: int, removed: int, remaining: int) -> int:
        """The cell of the first key object (:data:`CONTACT_CELLS`) that :meth:`action`'s route
        from that state moves into, -1 when it meets none (the episode ends first).

        The cell moved into, before a teleport end moves the agent on: the object the agent
        contacts, as neurosym induce labels a state's next object. Every state the walk
        passes shares its answer, so a whole route is walked once (cached).
        """
        key = (b, pos, removed, remaining)
        found = self._contacts.get(key)
        if found is not None:
            return found
        walked = [key]
        cell = -1
        N = self.cells_per_level
        base = b * self.graph.states
        while remaining > 0:
            a = self.action(b, pos, removed, remaining)
            enter = int(self.entered[a, pos])
            if (
                enter != pos
                and self.cells[b, enter] in CONTACT_CELLS
                and not int(self.removable[b, enter]) & removed
            ):
                cell = enter
                break
            s = int(self.graph.nxt[a, base + removed * N + pos]) - base
            if s >= self.graph.states - 1:  # the sink: the episode is over
                break
            removed, pos = divmod(s, N)
            remaining -= 1
            key = (b, pos, removed, remaining)
            known = self._contacts.get(key)
            if known is not None:
                cell = known
                break
            walked.append(key)
        for k in walked:
            self._contacts[k] = cell
        return cell

    def _q(self, b: int, pos: int, removed: int, remaining: int) -> np.ndarray:
        """(4,) action values toward the best return, on the fewest-step plan that earns it."""
        s = self._state(b, pos, removed)
        last = len(self.layers) - 1  # V_i = V_last for every i >= last

        def layer(i: int) -> np.ndarray:
            return self.layers[min(i, last)]

        k = min(max(remaining, 1), max(last, 1))
        j = next(i for i in range(1, k + 1) if layer(i)[s] == layer(k)[s])
        v = layer(j - 1)
        g = self.graph
        return np.array([int(g.reward[a, s]) + int(v[g.nxt[a, s]]) for a in range(4)])

    def _state(self, b: int, pos: int, removed: int) -> int:
        return int(b * self.graph.states + int(removed) * self.cells_per_level + int(pos))


class Planner:
    """An optimal scripted policy for a batched RGW env: ``planner(obs, venv) -> actions``.

    Reads each sub-env's level and state (``venv.current_levels()``,
    ``venv.agent_states()``) and acts by :class:`Plan`, one per level (cached),
    so every episode earns its level's optimal return. For tests and for
    checking evaluation figures; it looks at the state, not at the pixels.
    """

    MAX_PLANS = 512
    """plans kept (each holds every layer of its search, up to a few MB): training meets a new
    level every few dozen steps in each sub-env, so the cache simply starts over when full"""

    def __init__(self) -> None:
        self._plans: dict[tuple[bytes, int], Plan] = {}

    def __call__(self, obs: np.ndarray, venv: object) -> np.ndarray:
        return np.array(
            [plan.action(0, *state) for plan, state in self._states(venv)], dtype=np.int64
        )

    def action_sets(self, venv: object) -> tuple[np.ndarray, np.ndarray]:
        """(n, 4) bool optimal actions per sub-env and (n,) the best return still to earn."""
        sets, values, _ = self.labels(venv, regret=False)
        return sets, values

    def labels(
        self, venv: object, regret: bool = True
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """:meth:`action_sets` and (n, 4) float32 each action's :meth:`Plan.regret` per sub-env.

        ``regret=False`` leaves the regrets out (None): they add about a quarter
        to the labelling time, which runs on every training step.
        """
        sets, values, regrets = [], [], []
        for plan, state in self._states(venv):
            sets.append(plan.action_set(0, *state))
            values.append(plan.value(0, *state))
            if regret:
                regrets.append(plan.regret(0, *state))
        return (
            np.stack(sets),
            np.asarray(values, dtype=np.float32),
            np.stack(regrets) if regret else None,
        )

    def next_contacts(self, venv: object) -> np.ndarray:
        """(n,) int16 per sub-env the cell (row-major) of the first key object on the planner's
        route from the current state (:meth:`Plan.next_contact`), -1 where it meets none."""
        return np.array(
            [plan.next_contact(0, *state) for plan, state in self._states(venv)], dtype=np.int16
        )

    def attention_targets(self, venv: object) -> np.ndarray:
        """(n, 2) int16 cells for PrediNet head 0's two arguments (``attend_coef``): none (-1)
        for the first, :meth:`next_contacts` for the second."""
        targets = np.full((venv.num_envs, 2), -1, dtype=np.int16)
        targets[:, 1] = self.next_contacts(venv)
        return targets

    def _states(self, venv: object) -> list[tuple[Plan, tuple[int, int, int]]]:
        env = getattr(venv, "unwrapped", venv)
        cells, starts = env.current_levels()
        pos, removed, t = env.agent_states()
        limit = env.rules.max_steps
        if len(self._plans) > self.MAX_PLANS:
            self._plans.clear()
        out = []
        for i in range(len(cells)):
            key = (cells[i].tobytes(), int(starts[i]))
            plan = self._plans.get(key)
            if plan is None:
                plan = Plan(cells[i], starts[i], env.height, env.width, env.rules)
                self._plans[key] = plan
            remaining = int(limit - t[i]) if limit is not None else len(plan.layers)
            out.append((plan, (int(pos[i]), int(removed[i]), max(remaining, 1))))
        return out


MAX_UNLIMITED_STEPS = 10_000
"""the most steps an optimal route is followed for under rules without a step limit"""

VISITS: dict[str, str] = {
    "picked(sword)": "sword",
    "teleported": "teleport",
    "defeated(enemy)": "enemy",
    "hurt_by(enemy)": "enemy",
    "reached(terminal)": "terminal",
    "fell(pit)": "pit",
}
"""event -> the key object it reaches (the visits rules/rgw.pl's visit_order/2 reads)"""


def optimal_visit_orders(venv: object, seeds: list[int]) -> list[tuple[str, ...] | None]:
    """The key objects each level's optimal route first reaches, in order, one per seed.

    Level k is the one ``venv.reset`` plays from ``seeds[k]`` (the recorder's
    episode k); it is played by :class:`Plan` on the env itself, ``num_envs``
    levels at a time, and the events the env reports are read through
    :data:`VISITS`, first visits only: rgw2 gives ``("sword", "teleport",
    "enemy", "terminal")``. None for a level the search cannot settle (more
    than MAX_REMOVABLE swords and enemies, classic rules without a step limit).
    """
    env = getattr(venv, "unwrapped", venv)
    n = int(env.num_envs)
    out: list[tuple[str, ...] | None] = []
    plans: dict[tuple[bytes, int], Plan | None] = {}  # a fixed map is searched once
    for first in range(0, len(seeds), n):
        wave = list(seeds[first : first + n])
        wave += [wave[-1] + 1 + i for i in range(n - len(wave))]  # idle sub-envs
        out += _wave_orders(env, wave, plans)[: len(seeds) - first]
        if len(plans) > Planner.MAX_PLANS:
            plans.clear()
    return out


def _wave_orders(
    env: Any, seeds: list[int], cache: dict[tuple[bytes, int], Plan | None]
) -> list[tuple[str, ...] | None]:
    """:func:`optimal_visit_orders` of one reset of every sub-env (plans kept in ``cache``)."""
    _, info = env.reset(seed=seeds)
    cells, starts = env.current_levels()
    plans: list[Plan | None] = []
    for i in range(len(seeds)):
        key = (cells[i].tobytes(), int(starts[i]))
        if key not in cache:
            try:
                ok = np.isfinite(info["optimal_return"][i])
                cache[key] = Plan(cells[i], starts[i], env.height, env.width, env.rules) if ok else None
            except ValueError:
                cache[key] = None
        plans.append(cache[key])
    limit = env.rules.max_steps
    visits: list[list[str]] = [[] for _ in seeds]
    live = np.array([p is not None for p in plans])
    for _ in range(limit if limit is not None else MAX_UNLIMITED_STEPS):
        if not live.any():
            break
        pos, removed, t = env.agent_states()
        actions = np.zeros(len(seeds), dtype=np.int64)
        for i in np.flatnonzero(live):
            left = int(limit - t[i]) if limit is not None else len(plans[i].layers)
            actions[i] = plans[i].action(0, int(pos[i]), int(removed[i]), max(left, 1))
        _, _, terminated, truncated, info = env.step(actions)
        for i in np.flatnonzero(live):
            for event in rules.EVENT_TUPLES[int(info["events"][i])]:
                reached = VISITS.get(event)
                if reached is not None and reached not in visits[i]:
                    visits[i].append(reached)
        live &= ~(np.asarray(terminated) | np.asarray(truncated))
    return [tuple(v) if p is not None else None for v, p in zip(visits, plans, strict=True)]
