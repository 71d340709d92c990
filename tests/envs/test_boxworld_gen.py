"""Box-World level generation: solvable, distractors are dead ends, objects never block each
other, checked by search over thousands of seeds; determinism and the solver itself."""

from __future__ import annotations

import numpy as np
import pytest

from neurosym.envs.boxworld import BOXWORLD_CONFIGS, Box, BoxWorldEnv, Level
from neurosym.envs.boxworld_entities import AGENT, GEM, HELD, KEY, LOCK, NUM_COLOURS
from neurosym.envs.boxworld_gen import (
    GRID,
    MAX_OBJECTS,
    BoxWorldConfig,
    generate_levels,
    seed_keys,
)
from neurosym.envs.boxworld_solver import level_grid, search, walk

CONFIGS = {
    **BOXWORLD_CONFIGS,
    "default": {},
    "long-branches": {"solution_length": 4, "num_distractors": 3, "distractor_length": 2},
}


def levels_for(config: BoxWorldConfig, count: int, episode: int = 0):
    keys = seed_keys(12345, 1)[0] + np.arange(count, dtype=np.uint64)
    return generate_levels(config, keys, np.full(count, episode, np.uint64))


@pytest.mark.expensive  # a search of each of 5,000 levels per config
@pytest.mark.parametrize("name", list(CONFIGS))
def test_every_level_is_solvable_and_distractors_are_dead_ends(name):
    config = BoxWorldConfig(**{k: v for k, v in CONFIGS[name].items() if k != "max_steps"})
    count = 5000
    levels = levels_for(config, count)
    for i in range(count):
        grid, distractor, agent = level_grid(levels, i)
        found = search(grid, distractor, agent)
        assert found.solvable, f"level {i} of {name}: the gem cannot be reached"
        assert found.min_boxes == config.solution_length, f"level {i}: {found.min_boxes} boxes"
        assert not found.untouchable_from_start, (
            f"level {i}: blocked {found.untouchable_from_start}"
        )
        # every branch's first box can really be opened (a distractor, not decoration) ...
        assert len(found.distractors_openable) == config.num_distractors, f"level {i}"
        # ... and nothing after opening one leads to the gem, even if the episode went on
        onwards = search(grid, distractor, agent, stop_at_distractor=False)
        assert not onwards.gem_after_distractor, f"level {i} of {name}: a distractor leads on"


@pytest.mark.parametrize("name", list(CONFIGS))
def test_layout_and_colours(name):
    config = BoxWorldConfig(**{k: v for k, v in CONFIGS[name].items() if k != "max_steps"})
    count = 3000
    lv = levels_for(config, count)
    codes, cells = lv.codes.astype(np.int64), lv.cells.astype(np.int64)
    rows, cols = cells // GRID, cells % GRID
    assert (cells >= 0).all() and cells.shape[1] == config.num_slots
    # one gem, one lock per box, keys = loose key + boxed keys
    assert ((codes == GEM).sum(1) == 1).all()
    assert (((codes >= LOCK) & (codes < HELD)).sum(1) == config.num_boxes).all()
    assert (((codes >= KEY) & (codes < LOCK)).sum(1) == config.num_boxes).all()
    # object cells inside the interior, the ring next to the border kept free
    assert rows.min() >= 2 and rows.max() <= 11 and cols.min() >= 2 and cols.max() <= 11
    # distinct cells; two objects' cells touch (8-neighbourhood) only within one box
    assert all(len(set(c)) == len(c) for c in cells.tolist())
    lock = (codes >= LOCK) & (codes < HELD)
    owner = np.where(lock, cells - 1, cells)  # a box is named by its content's cell
    dr = np.abs(rows[:, :, None] - rows[:, None, :])
    dc = np.abs(cols[:, :, None] - cols[:, None, :])
    touching = (dr <= 1) & (dc <= 1) & (owner[:, :, None] != owner[:, None, :])
    assert not touching.any(), f"objects touch in level {np.flatnonzero(touching.any((1, 2)))[:5]}"
    # the agent stands on an empty interior cell
    agent = lv.agent.astype(np.int64)
    assert (
        (agent // GRID >= 1) & (agent // GRID <= 12) & (agent % GRID >= 1) & (agent % GRID <= 12)
    ).all()
    assert not (cells == agent[:, None]).any()
    # distractor keys never have a colour of the solution's keys
    for i in range(50):
        grid, distractor, a = level_grid(lv, i)
        sol = search(grid, distractor, a)
        route_keys = {int(grid[c] - KEY) for c in sol.route if KEY <= grid[c] < LOCK}
        route_keys |= {
            int(grid[c - 1] - KEY)
            for c in sol.route
            if LOCK <= grid[c] < HELD and grid[c - 1] != GEM
        }
        dis_keys = {int(grid[c - 1] - KEY) for c in np.flatnonzero(distractor)}
        assert not route_keys & dis_keys, f"level {i}: shared colours {route_keys & dis_keys}"
    # every colour and every placement row/column turns up across levels
    colours = np.unique(codes[lock] - LOCK)
    assert len(colours) == NUM_COLOURS
    assert set(np.unique(rows[lock])) == set(range(2, 12))
    assert set(np.unique(cols[lock])) == set(range(3, 12))


def test_levels_do_not_depend_on_the_batch_they_are_drawn_in():
    config = BoxWorldConfig(**CONFIGS["long-branches"])
    keys = seed_keys(7, 64)
    episodes = np.arange(64, dtype=np.uint64) % 5
    together = generate_levels(config, keys, episodes)
    for i in range(0, 64, 7):
        alone = generate_levels(config, keys[i : i + 1], episodes[i : i + 1])
        for field in ("agent", "cells", "codes", "distractor"):
            assert np.array_equal(getattr(alone, field)[0], getattr(together, field)[i]), (i, field)
    again = generate_levels(config, keys, episodes)
    assert np.array_equal(again.cells, together.cells) and np.array_equal(
        again.agent, together.agent
    )


def test_episodes_of_one_stream_differ():
    config = BoxWorldConfig(**CONFIGS["default"])
    keys = np.repeat(seed_keys(3, 1), 200)
    lv = generate_levels(config, keys, np.arange(200, dtype=np.uint64))
    assert len({(a, c.tobytes()) for a, c in zip(lv.agent.tolist(), lv.cells, strict=True)}) == 200


def test_the_fullest_configuration_still_generates():
    config = BoxWorldConfig(solution_length=10, num_distractors=4)
    assert config.num_objects == MAX_OBJECTS
    lv = levels_for(config, 20)
    for i in range(20):
        grid, distractor, agent = level_grid(lv, i)
        assert search(grid, distractor, agent).min_boxes == 10


def test_solver_routes_win_in_the_environment():
    for seed in range(30):
        env = BoxWorldEnv(**CONFIGS["long-branches"])
        env.reset(seed=seed)
        grid = env.entity_grid().ravel()
        agent = int(np.flatnonzero(grid == AGENT)[0])
        distractor = env.unwrapped._state.distractor[0]
        route = search(grid, distractor, agent).route
        total, info = 0.0, None
        for action in walk(grid, agent, route):
            _, reward, terminated, _, info = env.step(action)
            total += reward
        assert terminated and info["outcome"] == "gem" and total == 4 + 10, (seed, total)


def test_solver_sees_blocked_and_unsolvable_levels():
    # the gem's box needs a key that is nowhere
    no_key = Level(agent=(2, 2), boxes=(Box(6, 6, "red", "gem"),)).to_arrays()
    assert not search(*level_grid(no_key, 0)).solvable
    # a loose key walled in by boxes cannot be reached from the start
    walled = Level(
        agent=(9, 9),
        keys=((1, 1, "red"),),  # the border above and left, box contents right and below
        boxes=(Box(1, 3, "blue", "green"), Box(2, 2, "blue", "green"), Box(6, 6, "red", "gem")),
    ).to_arrays()
    found = search(*level_grid(walled, 0))
    assert not found.solvable and found.untouchable_from_start == {1 * GRID + 1}
    # a distractor whose key opens the way on would not be a dead end
    leaky = Level(
        agent=(2, 2),
        keys=((2, 4, "red"),),
        boxes=(Box(5, 5, "red", "blue", distractor=True), Box(8, 8, "blue", "gem")),
    ).to_arrays()
    assert not search(*level_grid(leaky, 0)).solvable
    assert search(*level_grid(leaky, 0), stop_at_distractor=False).gem_after_distractor


@pytest.mark.parametrize("name", ["bw2", "bw3"])
def test_route_targets_lead_every_level_to_the_gem(name):
    """Walking to the second target each step (plain BFS through empty cells) wins every level,
    and the agent only ever walks into the object it was told: a key, then the lock that key
    opens, and so on. The first target is the held key's cell exactly when the second is a lock
    of the held key's colour."""
    from neurosym.envs import make_batched
    from neurosym.envs.boxworld_gen import HELD_CELL
    from neurosym.envs.boxworld_solver import RouteTargets

    n = 24
    venv = make_batched(name, n, seed=77)
    venv.reset(seed=77)
    env = venv.unwrapped
    route = RouteTargets()
    outcomes: list[str | None] = [None] * n
    contacts = 0
    for _ in range(400):
        targets = route.attention_targets(venv)
        grids, _, agents, held = env.solver_states()
        assert targets.dtype == np.int16 and targets.shape == (n, 2)
        live = [i for i in range(n) if outcomes[i] is None]
        for i in live:
            cell = int(targets[i, 1])
            code = int(grids[i, cell])
            assert KEY <= code < HELD or code == GEM
            opens = LOCK <= code < HELD and code - LOCK == held[i]
            assert targets[i, 0] == (HELD_CELL if opens else -1)
            assert not (LOCK <= code < HELD) or opens  # a lock is named only with its key held
        actions = np.array(
            [walk(grids[i], int(agents[i]), [int(targets[i, 1])])[0] if targets[i, 1] >= 0 else 0
             for i in range(n)]  # fmt: skip
        )
        _, _, terminated, truncated, info = venv.step(actions)
        moved = env.solver_states()[2]
        for i in live:
            if terminated[i] or truncated[i]:
                outcomes[i] = env.episode_outcome(info, i)
            elif moved[i] != agents[i] and grids[i, moved[i]] != 0:  # walked into an object
                assert moved[i] == targets[i, 1]
                contacts += 1
        if all(o is not None for o in outcomes):
            break
    assert outcomes == ["gem"] * n
    assert contacts >= n  # objects walked into before the gem
