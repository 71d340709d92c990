"""The DoorKey planner (neurosym/envs/minigrid_solver.py) that ``--algo imitate`` copies on Minigrid.

Its distances are checked against a breadth-first search over copies of Minigrid's own env
(its real rules, not the planner's model of them); the scripted level is the one
tests/envs/test_minigrid.py walks: DoorKey-5x5 seed 1, agent at (2, 1) facing south, the
key below it, the locked door east of it, the goal at (3, 3).
"""

from __future__ import annotations

import copy

import numpy as np
import pytest

from neurosym.envs import make_batched
from neurosym.envs.minigrid_solver import DoorKeyPlanner as Planner
from neurosym.errors import ConfigError

DOORKEY = "MiniGrid-DoorKey-5x5-v0"
LEFT, RIGHT, FORWARD, PICKUP, DROP, TOGGLE, DONE = range(7)


def _state(inner) -> tuple:
    keys = [i for i, o in enumerate(inner.grid.grid) if o is not None and o.type == "key"]
    door = next(o for o in inner.grid.grid if o is not None and o.type == "door")
    return (tuple(inner.agent_pos), inner.agent_dir, tuple(keys), door.is_locked, door.is_open)


def _bfs_steps(inner) -> int:
    """Fewest steps to the goal by breadth-first search over deep copies of the real env."""
    frontier, seen = [inner], {_state(inner)}
    for depth in range(1, 60):
        nxt = []
        for env in frontier:
            for action in range(7):
                child = copy.deepcopy(env)
                _, reward, terminated, _, _ = child.step(action)
                if reward > 0:
                    return depth
                if not terminated and _state(child) not in seen:
                    seen.add(_state(child))
                    nxt.append(child)
        frontier = nxt
    raise AssertionError("no route found")


def test_planner_distances_match_a_search_over_minigrid_itself() -> None:
    venv = make_batched(DOORKEY, 1, seed=1)
    venv.reset(seed=1)
    planner = Planner()
    sets, values, regret = planner.labels(venv)
    # seed 1: facing the key (south), so picking it up is the one first step of a shortest route
    assert sets[0].tolist() == [False, False, False, True, False, False, False]
    plan, s = planner._locate(venv.envs[0].inner)
    assert (
        plan.dist[s] == _bfs_steps(venv.envs[0].inner) == 7
    )  # pickup, left (east), toggle, forward, forward, right, forward
    assert values[0] == pytest.approx(1 - 0.9 * 7 / venv.envs[0].inner.max_steps)
    assert regret[0, PICKUP] == 0 and (regret[0, [LEFT, RIGHT, DROP, TOGGLE, DONE]] > 0).all()


@pytest.mark.parametrize("env_id", [DOORKEY, "MiniGrid-DoorKey-8x8-v0"])
def test_following_the_planner_reaches_the_goal_in_its_distance(env_id: str) -> None:
    venv = make_batched(env_id, 8, seed=100)
    venv.reset(seed=100)
    planner = Planner()
    first = [int(p.dist[s]) for p, s in map(planner._locate, (e.inner for e in venv.envs))]
    lengths, outcomes, steps = [None] * 8, [None] * 8, 0
    while any(o is None for o in outcomes):
        _, _, terminated, truncated, info = venv.step(planner(None, venv))
        steps += 1
        for i in np.flatnonzero(terminated | truncated):
            if outcomes[i] is None:
                outcomes[i], lengths[i] = venv.episode_outcome(info, i), steps
    assert outcomes == ["goal"] * 8
    assert lengths == first


def test_the_planner_labels_states_off_its_own_route() -> None:
    """DAgger visits states the planner never would: the key dropped elsewhere, the door shut."""
    venv = make_batched(DOORKEY, 1, seed=1)
    venv.reset(seed=1)
    planner = Planner()
    # take the key, unlock and open the door, close it again, turn back and drop the key north
    for action in (PICKUP, LEFT, TOGGLE, TOGGLE, LEFT, DROP):
        venv.step(np.array([action]))
    inner = venv.envs[0].inner
    door = next(o for o in inner.grid.grid if o is not None and o.type == "door")
    assert (door.is_locked, door.is_open, inner.carrying) == (False, False, None)
    plan, s = planner._locate(inner)
    assert plan.dist[s] == _bfs_steps(inner)
    steps = 0
    while True:
        _, _, terminated, _, info = venv.step(planner(None, venv))
        steps += 1
        if terminated[0]:
            break
    assert (venv.episode_outcome(info, 0), steps) == ("goal", plan.dist[s])


def test_a_level_without_a_door_is_refused() -> None:
    venv = make_batched("MiniGrid-Empty-5x5-v0", 1, seed=0)
    venv.reset(seed=0)
    with pytest.raises(
        ConfigError,
        match=r"^the DoorKey planner needs one door, one goal and at most one key on the map; "
        r"this level has 0 doors, 1 goals, 0 keys \(use --algo ppo or a3c\)$",
    ):
        Planner().labels(venv)
