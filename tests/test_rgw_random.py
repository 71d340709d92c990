"""Procedural Relational-Grid-World levels: properties over many seeds, checked by plain search."""

from __future__ import annotations

from collections import deque

import numpy as np
import pytest

from neurosym.envs import rgw_rules as R
from neurosym.envs.rgw_maps import GridMap
from neurosym.envs.rgw_random import RandomLevelConfig, RGWRandomEnv, generate_levels
from neurosym.errors import ConfigError

DELTAS = ((-1, 0), (0, 1), (1, 0), (0, -1))


def moves(cells: np.ndarray, width: int, p: int):
    """Cells one step from p under the default rules (bumps omitted: they lead nowhere new)."""
    height = len(cells) // width
    r, c = divmod(p, width)
    ends = [i for i, v in enumerate(cells) if v == R.TELEPORT]
    for dr, dc in DELTAS:
        nr, nc = r + dr, c + dc
        if 0 <= nr < height and 0 <= nc < width and cells[nr * width + nc] != R.WALL:
            q = nr * width + nc
            if q in ends:
                q = ends[1] if q == ends[0] else ends[0]
            yield q


def shortest(cells: np.ndarray, width: int, start: int, enemies_block: bool) -> float:
    """Steps from start to the terminal, never through a pit (or an enemy, when they block)."""
    seen, todo = {start: 0}, deque([start])
    while todo:
        p = todo.popleft()
        if cells[p] == R.TERMINAL:
            return seen[p]
        for q in moves(cells, width, p):
            if q in seen or cells[q] == R.PIT or (enemies_block and cells[q] == R.ENEMY):
                continue
            seen[q] = seen[p] + 1
            todo.append(q)
    return float("inf")


def solvable(cells: np.ndarray, width: int, start: int) -> bool:
    """Search over (position, holding the sword): sword first, unhurt, then the terminal."""
    seen, todo = {(start, False)}, deque([(start, False)])
    while todo:
        p, holding = todo.popleft()
        for q in moves(cells, width, p):
            h = holding or cells[q] == R.SWORD
            if cells[q] == R.PIT or (cells[q] == R.ENEMY and not holding):
                continue
            if cells[q] == R.TERMINAL:
                if h:
                    return True
                continue
            if (q, h) not in seen:
                seen.add((q, h))
                todo.append((q, h))
    return False


def on_route(cells: np.ndarray, width: int, start: int) -> bool:
    return shortest(cells, width, start, True) > shortest(cells, width, start, False)


@pytest.fixture(scope="module")
def levels() -> tuple[np.ndarray, np.ndarray]:
    cfg = RandomLevelConfig()
    return generate_levels(cfg, np.arange(600), np.arange(600) % 7)


def test_every_level_has_the_configured_objects(levels) -> None:
    cells, starts = levels
    cfg = RandomLevelConfig()
    counts = {code: (cells == code).sum(axis=1) for code in range(R.NUM_CELL_CODES)}
    assert (counts[R.TERMINAL] == 1).all() and (counts[R.SWORD] == 1).all()
    assert (counts[R.TELEPORT] == 2).all() and (counts[R.ENEMY] == cfg.num_enemies).all()
    assert (counts[R.MOUNTAIN] == cfg.num_mountains).all() and (counts[R.PIT] == cfg.num_pits).all()
    assert (cells[np.arange(len(cells)), starts] == R.EMPTY).all()


def test_every_level_is_solvable_and_long_enough(levels) -> None:
    cells, starts = levels
    for i, (c, s) in enumerate(zip(cells, starts, strict=True)):
        assert solvable(c, 10, int(s)), (
            f"level {i} unsolvable:\n{GridMap('x', 10, 10, c, int(s)).text()}"
        )
        assert shortest(c, 10, int(s), False) >= RandomLevelConfig().min_route_length, i


def test_share_of_levels_with_the_enemy_on_every_route(levels) -> None:
    cells, starts = levels
    share = np.mean([on_route(c, 10, int(s)) for c, s in zip(cells, starts, strict=True)])
    assert 0.43 <= share <= 0.57, share


@pytest.mark.parametrize("share", [0.0, 1.0])
def test_enemy_on_route_extremes(share: float) -> None:
    cfg = RandomLevelConfig(enemy_on_route=share, num_enemies=2)
    cells, starts = generate_levels(cfg, np.arange(150), np.zeros(150))
    flags = [on_route(c, 10, int(s)) for c, s in zip(cells, starts, strict=True)]
    assert all(flags) if share == 1.0 else not any(flags)
    assert all(solvable(c, 10, int(s)) for c, s in zip(cells, starts, strict=True))


def test_levels_depend_only_on_their_key() -> None:
    cfg = RandomLevelConfig()
    seeds, eps = np.array([3, 9, 3, 1000]), np.array([0, 5, 1, 2])
    batch_cells, batch_starts = generate_levels(cfg, seeds, eps)
    for i in range(4):
        one_cells, one_starts = generate_levels(cfg, seeds[i : i + 1], eps[i : i + 1])
        assert (one_cells[0] == batch_cells[i]).all() and one_starts[0] == batch_starts[i]
    assert not (batch_cells[0] == batch_cells[2]).all()  # another episode, another level


def test_other_sizes_and_parameters() -> None:
    cfg = RandomLevelConfig(height=7, width=12, num_enemies=3, num_pits=1, wall_segments=4)
    cells, starts = generate_levels(cfg, np.arange(60), np.zeros(60))
    assert cells.shape == (60, 84)
    assert ((cells == R.ENEMY).sum(axis=1) == 3).all()
    assert all(solvable(c, 12, int(s)) for c, s in zip(cells, starts, strict=True))


def test_env_plays_the_keyed_levels() -> None:
    env = RGWRandomEnv()
    cfg = env.level_config
    first = env.reset(seed=11)
    second = env.reset()
    again = env.reset(seed=11)
    cells, starts = generate_levels(cfg, np.array([11, 11]), np.array([0, 1]))
    for (obs, info), c, s in [(first, cells[0], starts[0]), (second, cells[1], starts[1])]:
        assert info["agent"] == divmod(int(s), 10)
        assert (
            obs[:8].argmax(axis=0).reshape(-1)[c != R.EMPTY] == R.ENTITY_OF_CELL[c][c != R.EMPTY]
        ).all()
    assert (again[0] == first[0]).all() and again[1] == first[1]
    assert not (second[0] == first[0]).all()


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"enemy_on_route": 1.5}, "enemy_on_route must be in"),
        ({"num_enemies": 0}, "num_enemies must be an integer >= 1"),
        ({"height": 2}, "height must be an integer >= 3"),
        ({"num_mountains": 60}, "do not fit"),
        ({"enemies": 2}, "unknown rgw-random parameter 'enemies'"),
    ],
)
def test_bad_parameters_are_refused(kwargs: dict, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        RGWRandomEnv(**kwargs)
