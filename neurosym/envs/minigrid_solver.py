"""An optimal planner for Minigrid's DoorKey levels: what ``neurosym train --algo imitate`` copies.

A DoorKey level holds one key, one locked door of the key's colour and the goal
square. The planner reads the fully observed grid (Minigrid's own, not the
network's observation) and searches the whole state space of the level: the
agent's cell and direction, where the key is (on any free cell, or carried) and
the door's state (open, closed, locked). Every action costs one step and the
episode pays ``1 - 0.9 * steps / max_steps`` on the goal, so the fewest steps is
the best return. The search is a vectorised Bellman sweep of shortest distances
to the goal over all states at once (:class:`DoorKeyPlan`); it covers the states that a
learner's own actions reach (a key dropped elsewhere, a door closed again), so
DAgger can label them too. Plans are cached per level layout.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from neurosym.envs import minigrid_state as ms
from neurosym.errors import ConfigError

N_ACTIONS = len(ms.ACTION_NAMES)
LEFT, RIGHT, FORWARD, PICKUP, DROP, TOGGLE, DONE = range(N_ACTIONS)
OPEN, CLOSED, LOCKED = range(len(ms.DOOR_STATES))
_STEP = np.array([(0, 1), (1, 0), (0, -1), (-1, 0)])  # (drow, dcol) of east, south, west, north
_TYPE = {name: i for i, name in enumerate(ms.TYPES)}
UNREACHABLE = np.iinfo(np.int32).max // 2


def level_cells(inner: Any) -> np.ndarray:
    """(H, W, 3) Minigrid's (type, colour, state) codes per cell, row-major (the agent not drawn)."""
    return np.ascontiguousarray(inner.grid.encode().transpose(1, 0, 2)).astype(np.int64)


def layout_key(cells: np.ndarray) -> bytes:
    """What a plan depends on: the cells with the key taken out and the door's state left out."""
    layout = cells.copy()
    layout[layout[..., 0] == _TYPE["key"]] = (_TYPE["empty"], 0, 0)
    layout[layout[..., 0] == _TYPE["door"], 2] = 0
    return layout.tobytes()


class DoorKeyPlan:
    """Shortest distances to the goal over every state of one DoorKey layout.

    A state is (free cell ``p``, direction, key place ``k``, door state): ``k``
    is a free cell's index or ``len(cells)`` for carried. ``dist[s]`` is the
    fewest steps from ``s`` to the goal (:data:`UNREACHABLE` when none).
    """

    def __init__(self, cells: np.ndarray) -> None:
        types = cells[..., 0]
        doors = np.argwhere(types == _TYPE["door"])
        if (
            len(doors) != 1
            or (types == _TYPE["goal"]).sum() != 1
            or (types == _TYPE["key"]).sum() > 1
        ):
            raise ConfigError(
                "the DoorKey planner needs one door, one goal and at most one key on the map; "
                f"this level has {len(doors)} doors, {(types == _TYPE['goal']).sum()} goals, "
                f"{(types == _TYPE['key']).sum()} keys (use --algo ppo or a3c)"
            )
        height, width = types.shape
        free = np.argwhere(types != _TYPE["wall"])
        self.index = np.full((height, width), -1, np.int64)
        self.index[free[:, 0], free[:, 1]] = np.arange(len(free))
        self.n_cells = len(free)
        self.next = self._transitions(types[free[:, 0], free[:, 1]], free, height, width)
        self.dist = self._distances(self.next)

    @property
    def n_states(self) -> int:
        return self.n_cells * 4 * (self.n_cells + 1) * 3

    def state(
        self, row: int, col: int, direction: int, key: tuple[int, int] | None, door: int
    ) -> int:
        """The state index; ``key`` the key's cell, or None when the agent carries it."""
        k = self.n_cells if key is None else int(self.index[key])
        return ((int(self.index[row, col]) * 4 + direction) * (self.n_cells + 1) + k) * 3 + door

    def _transitions(
        self, kinds: np.ndarray, free: np.ndarray, height: int, width: int
    ) -> np.ndarray:
        """(n_states, 7) the state after each action; ``n_states`` is the goal (the episode's end)."""
        n, goal_sink = self.n_cells, self.n_states
        p, d, k, door = (a.ravel() for a in np.meshgrid(
            np.arange(n), np.arange(4), np.arange(n + 1), np.arange(3), indexing="ij"
        ))  # fmt: skip
        ahead = free[p] + _STEP[d]
        inside = (ahead >= 0).all(1) & (ahead[:, 0] < height) & (ahead[:, 1] < width)
        f = np.where(
            inside, self.index[ahead[:, 0].clip(0, height - 1), ahead[:, 1].clip(0, width - 1)], -1
        )
        wall = f < 0
        fkind = np.where(wall, _TYPE["wall"], kinds[f.clip(0)])
        is_door, is_goal = fkind == _TYPE["door"], fkind == _TYPE["goal"]
        carried = k == n

        def index(p2: np.ndarray, d2: np.ndarray, k2: np.ndarray, door2: np.ndarray) -> np.ndarray:
            return ((p2 * 4 + d2) * (n + 1) + k2) * 3 + door2

        same = index(p, d, k, door)
        out = np.empty((len(p), N_ACTIONS), np.int64)
        out[:, LEFT] = index(p, (d - 1) % 4, k, door)
        out[:, RIGHT] = index(p, (d + 1) % 4, k, door)
        blocked = wall | (k == f) | (is_door & (door != OPEN))
        moved = np.where(blocked, same, index(f.clip(0), d, k, door))
        out[:, FORWARD] = np.where(is_goal & ~blocked, goal_sink, moved)
        out[:, PICKUP] = np.where(~wall & (k == f), index(p, d, np.full_like(k, n), door), same)
        can_drop = carried & ~wall & ~is_door & ~is_goal
        out[:, DROP] = np.where(can_drop, index(p, d, f.clip(0), door), same)
        toggled = np.where(
            door == LOCKED, np.where(carried, OPEN, LOCKED), np.where(door == OPEN, CLOSED, OPEN)
        )
        out[:, TOGGLE] = np.where(is_door, index(p, d, k, toggled), same)
        out[:, DONE] = same
        return out

    @staticmethod
    def _distances(nxt: np.ndarray) -> np.ndarray:
        """Bellman sweeps of ``dist = 1 + min_a dist[next_a]`` from the goal until nothing changes."""
        dist = np.full(len(nxt) + 1, UNREACHABLE, np.int64)
        dist[-1] = 0
        for _ in range(len(nxt) + 1):
            new = np.minimum(dist[:-1], 1 + dist[nxt].min(axis=1))
            if np.array_equal(new, dist[:-1]):
                break
            dist[:-1] = new
        return dist

    def action_set(self, s: int) -> np.ndarray:
        """(7,) bool: the actions on a shortest route from state ``s`` (all when none reaches the goal)."""
        via = 1 + self.dist[self.next[s]]
        if self.dist[s] >= UNREACHABLE:
            return np.ones(N_ACTIONS, bool)
        return via == self.dist[s]


def _value(steps_left: int, steps_taken: int, max_steps: int) -> float:
    """Minigrid's reward for reaching the goal after ``steps_taken + steps_left`` steps (0 past the limit)."""
    total = steps_taken + steps_left
    return 1.0 - 0.9 * total / max_steps if total <= max_steps else 0.0


class DoorKeyPlanner:
    """An optimal scripted policy for a batched Minigrid DoorKey env: ``planner(obs, venv) -> actions``.

    Reads each sub-env's Minigrid grid, agent and carried object and acts by
    :class:`DoorKeyPlan` (one per layout, cached). It looks at the state, not at the
    network's observation. The same interface as RGW's planner, which the
    DAgger learner calls.
    """

    MAX_PLANS = 512
    """plans kept; the cache starts over when full (a new level every episode)"""

    def __init__(self) -> None:
        self._plans: dict[bytes, DoorKeyPlan] = {}
        self._levels: dict[int, tuple[Any, DoorKeyPlan, Any]] = {}  # id(env) -> (its grid, plan, door)
        self._rng = np.random.default_rng(0)

    def __call__(self, obs: np.ndarray, venv: object) -> np.ndarray:
        sets, _, _ = self.labels(venv, regret=False)
        return (self._rng.random(sets.shape) * sets).argmax(axis=1)

    def action_sets(self, venv: object) -> tuple[np.ndarray, np.ndarray]:
        """(n, 7) bool optimal actions per sub-env and (n,) the best return still to earn."""
        sets, values, _ = self.labels(venv, regret=False)
        return sets, values

    def labels(
        self, venv: object, regret: bool = True
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """:meth:`action_sets` and, with ``regret``, (n, 7) float32 the return each action gives up."""
        sets, values, regrets = [], [], []
        for inner in _inner_envs(venv):
            plan, s = self._locate(inner)
            sets.append(plan.action_set(s))
            taken, limit = int(inner.step_count), int(inner.max_steps)
            best = _value(int(plan.dist[s]), taken, limit)
            values.append(best)
            if regret:
                after = [_value(int(plan.dist[t]) + 1, taken, limit) for t in plan.next[s]]
                regrets.append(best - np.asarray(after, np.float32))
        return (
            np.stack(sets),
            np.asarray(values, np.float32),
            np.stack(regrets) if regret else None,
        )

    def _locate(self, inner: Any) -> tuple[DoorKeyPlan, int]:
        """The plan of an env's level and the env's state in it.

        The level's layout is read once per Minigrid grid (a reset makes a new one); each step
        then reads only where the key is and the door's state, from the grid's own objects.
        """
        grid = inner.grid
        cached = self._levels.get(id(inner))
        if cached is None or cached[0] is not grid:
            cached = (grid, self._plan(level_cells(inner)), _find(grid, "door")[0][1])
            self._levels[id(inner)] = cached
        _, plan, door = cached
        carried = getattr(inner.carrying, "type", None) == "key"
        keys = _find(grid, "key")
        if not carried and len(keys) != 1:
            raise ConfigError(
                "the DoorKey planner lost the key: it is neither on the map nor carried"
            )
        place = None if carried else divmod(keys[0][0], grid.width)
        state = LOCKED if door.is_locked else OPEN if door.is_open else CLOSED
        col, row = (int(x) for x in inner.agent_pos)
        return plan, plan.state(row, col, int(inner.agent_dir), place, state)

    def _plan(self, cells: np.ndarray) -> DoorKeyPlan:
        """The cached plan of a layout, made when first met."""
        key = layout_key(cells)
        plan = self._plans.get(key)
        if plan is None:
            if len(self._plans) >= self.MAX_PLANS:
                self._plans.clear()
            plan = self._plans[key] = DoorKeyPlan(cells)
        return plan


def _find(grid: Any, kind: str) -> list[tuple[int, Any]]:
    """(flat index ``row * width + col``, object) of each object of a type on a Minigrid grid."""
    return [(i, o) for i, o in enumerate(grid.grid) if o is not None and o.type == kind]


def _inner_envs(venv: object) -> list[Any]:
    """The Minigrid envs under a :class:`~neurosym.envs.minigrid_env.MinigridVectorEnv`."""
    env = getattr(venv, "unwrapped", venv)
    return [e.inner for e in env.envs]
