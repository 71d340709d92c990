"""Procedural Relational-Grid-World levels: properties over many seeds, checked by plain search.

The reference searches below are written from the rule text (the thesis's
rules plus the enemy modes), cell by cell in plain Python, independent of the
array code in rgw_rules and rgw_solver that the generator and the env share.
"""

from __future__ import annotations

from collections import deque
from functools import cache

import numpy as np
import pytest

from neurosym.envs import rgw_rules as R
from neurosym.envs.rgw_maps import GridMap, load_map
from neurosym.envs.rgw_random import RandomLevelConfig, RGWRandomEnv, generate_levels
from neurosym.envs.rgw_solver import Rules, solve_levels
from neurosym.errors import ConfigError

DELTAS = ((-1, 0), (0, 1), (1, 0), (0, -1))
TELEPORTS = (R.TELEPORT, R.TELEPORT_MOUNTAIN)  # Q: a teleport end (a mountain only when classic)
SMALL = RandomLevelConfig(
    height=6, width=6, num_mountains=3, num_pits=1, wall_segments=3, max_wall_length=3
)


def moves(cells, width: int, p: int):
    """Cells one step from p under the default rules (bumps omitted: they lead nowhere new)."""
    height = len(cells) // width
    r, c = divmod(p, width)
    ends = [i for i, v in enumerate(cells) if v in TELEPORTS]
    for dr, dc in DELTAS:
        nr, nc = r + dr, c + dc
        if 0 <= nr < height and 0 <= nc < width and cells[nr * width + nc] != R.WALL:
            q = nr * width + nc
            if q in ends:
                q = ends[1] if q == ends[0] else ends[0]
            yield q


def reach_terminal(cells, width: int, start: int, blocked: set[int]) -> float:
    """Fewest steps to a terminal over cells that are not in ``blocked`` nor pits (inf: none)."""
    seen, todo = {start: 0}, deque([start])
    while todo:
        p = todo.popleft()
        if cells[p] == R.TERMINAL:
            return seen[p]
        for q in moves(cells, width, p):
            if q in seen or q in blocked or cells[q] == R.PIT:
                continue
            seen[q] = seen[p] + 1
            todo.append(q)
    return float("inf")


class Reference:
    """The rules, one plain step at a time: state = (cell, holding, swords left, enemies left)."""

    def __init__(self, cells, width: int, start: int, enemy: str) -> None:
        self.cells, self.width, self.enemy = tuple(int(v) for v in cells), width, enemy
        self.height = len(cells) // width
        self.ends = [i for i, v in enumerate(self.cells) if v in TELEPORTS]
        swords = frozenset(i for i, v in enumerate(self.cells) if v == R.SWORD)
        enemies = frozenset(i for i, v in enumerate(self.cells) if v == R.ENEMY)
        self.start = (start, False, swords, enemies)

    def step(self, state, action):
        """(next state or None when the episode ends, reward, reached the terminal)."""
        p, holding, swords, enemies = state
        r, c = divmod(p, self.width)
        nr, nc = r + DELTAS[action][0], c + DELTAS[action][1]
        if not (0 <= nr < self.height and 0 <= nc < self.width):
            return state, 0.0, False
        q = nr * self.width + nc
        cell = self.cells[q]
        if cell == R.WALL:
            return state, 0.0, False
        if cell in TELEPORTS:
            q = self.ends[1] if q == self.ends[0] else self.ends[0]
            return (q, holding, swords, enemies), 0.0, False
        if q in swords:
            return (q, True, swords - {q}, enemies), 0.0, False
        if q in enemies:
            if holding:
                return (q, holding, swords, enemies - {q}), 1.0, False
            if self.enemy == "block":
                return state, -1.0, False
            if self.enemy == "end":
                return None, -1.0, False
            return (q, holding, swords, enemies), -1.0, False
        if cell == R.MOUNTAIN:
            return (q, holding, swords, enemies), -0.1, False
        if cell == R.PIT:
            return None, -1.0, False
        if cell == R.TERMINAL:
            return None, 10.0, True
        return (q, holding, swords, enemies), 0.0, False

    def best_return(self, steps: int) -> float:
        """Brute force: the best return of any action sequence of at most ``steps`` steps."""

        @cache
        def best(state, k: int) -> float:
            if k == 0:
                return 0.0
            out = -np.inf
            for a in range(4):
                nxt, reward, _ = self.step(state, a)
                out = max(out, reward + (0.0 if nxt is None else best(nxt, k - 1)))
            return out

        return best(self.start, steps)

    def solvable(self) -> bool:
        """Some sequence of steps reaches a terminal (no step limit)."""
        seen, todo = {self.start}, deque([self.start])
        while todo:
            state = todo.popleft()
            for a in range(4):
                nxt, _, won = self.step(state, a)
                if won:
                    return True
                if nxt is not None and nxt not in seen:
                    seen.add(nxt)
                    todo.append(nxt)
        return False


def text(cells, start: int, width: int) -> str:
    return GridMap("x", len(cells) // width, width, np.asarray(cells), int(start)).text()


@pytest.fixture(scope="module")
def levels():
    return generate_levels(RandomLevelConfig(), np.arange(600), np.arange(600) % 7)


def test_every_level_has_the_configured_objects(levels) -> None:
    cells, starts, _ = levels
    cfg = RandomLevelConfig()
    counts = {code: (cells == code).sum(axis=1) for code in range(R.NUM_CELL_CODES)}
    assert (counts[R.TERMINAL] == 1).all() and (counts[R.SWORD] == 1).all()
    assert (counts[R.TELEPORT] == 2).all() and (counts[R.ENEMY] == cfg.num_enemies).all()
    assert (counts[R.MOUNTAIN] == cfg.num_mountains).all() and (counts[R.PIT] == cfg.num_pits).all()
    assert (cells[np.arange(len(cells)), starts] == R.EMPTY).all()


@pytest.mark.expensive  # searches of each of the 600 levels
def test_every_level_is_solvable_and_long_enough(levels) -> None:
    cells, starts, _ = levels
    for i, (c, s) in enumerate(zip(cells, starts, strict=True)):
        assert Reference(c, 10, int(s), "block").solvable(), f"level {i}:\n{text(c, s, 10)}"
        assert reach_terminal(c, 10, int(s), set()) >= RandomLevelConfig().min_route_length, i


@pytest.mark.expensive  # four searches of each of the 600 levels
def test_kinds_match_plain_search_and_the_shares(levels) -> None:
    cells, starts, info = levels
    for i, (c, s) in enumerate(zip(cells, starts, strict=True)):
        enemies = {j for j, v in enumerate(c) if v == R.ENEMY}
        teleports = {j for j, v in enumerate(c) if v == R.TELEPORT}
        hazards = {j for j, v in enumerate(c) if v in (R.MOUNTAIN, R.PIT)}
        guarded = reach_terminal(c, 10, int(s), enemies) == float("inf")
        needs_teleport = reach_terminal(c, 10, int(s), teleports) == float("inf")
        geometric = reach_terminal(np.where(c == R.PIT, R.EMPTY, c), 10, int(s), set())
        hazard = reach_terminal(c, 10, int(s), hazards) > geometric
        got = (info.guarded[i], info.needs_teleport[i], info.hazard_on_route[i])
        assert got == (guarded, needs_teleport, hazard), f"level {i}:\n{text(c, s, 10)}"
    cfg = RandomLevelConfig()
    assert abs(info.guarded.mean() - cfg.guarded_share) < 0.07
    assert abs(info.needs_teleport.mean() - cfg.teleport_share) < 0.07
    assert abs(info.hazard_on_route.mean() - cfg.hazard_share) < 0.07


def test_guarded_levels_need_the_sword(levels) -> None:
    """With the sword taken off the map, no route reaches a guarded terminal (block and end)."""
    cells, starts, info = levels
    assert info.guarded.sum() > 200
    for i in np.flatnonzero(info.guarded)[:120]:
        c = np.where(cells[i] == R.SWORD, R.EMPTY, cells[i])
        for enemy in ("block", "end"):
            assert not Reference(c, 10, int(starts[i]), enemy).solvable(), (
                f"level {i} ({enemy}) solvable without the sword:\n{text(c, starts[i], 10)}"
            )
        assert Reference(c, 10, int(starts[i]), "pass").solvable()  # the thesis's rule lets it by
    decoys = np.flatnonzero(~info.guarded)[:60]
    for i in decoys:
        c = np.where(cells[i] == R.SWORD, R.EMPTY, cells[i])
        assert Reference(c, 10, int(starts[i]), "block").solvable(), i


@pytest.mark.parametrize(
    ("enemy", "max_steps"), [("block", 25), ("end", 25), ("pass", 25), ("block", 9)]
)
def test_optimal_return_matches_brute_force(enemy: str, max_steps: int) -> None:
    rules = Rules(enemy=enemy, max_steps=max_steps)
    cells, starts, info = generate_levels(SMALL, np.arange(40), np.zeros(40), rules)
    for i, (c, s) in enumerate(zip(cells, starts, strict=True)):
        want = Reference(c, 6, int(s), enemy).best_return(max_steps)
        assert round(info.optimal_return[i], 9) == round(want, 9), f"level {i}:\n{text(c, s, 6)}"
    again = solve_levels(cells, starts, 6, 6, rules).optimal_return
    assert (again == info.optimal_return).all()


@pytest.mark.parametrize(("name", "best"), [("rgw1", 11.0), ("rgw2", 10.7)])
def test_optimal_return_of_the_shipped_maps(name: str, best: float) -> None:
    m = load_map(name)
    for enemy in ("pass", "block", "end"):
        got = solve_levels(m.cells[None], [m.start], 10, 10, Rules(enemy=enemy)).optimal_return
        assert round(float(got[0]), 9) == best
        assert round(Reference(m.cells, 10, m.start, enemy).best_return(40), 9) == best
    # Within 20 steps the 21-step route is out of reach: the sword, the enemy, mountains.
    short = solve_levels(m.cells[None], [m.start], 10, 10, Rules(max_steps=20)).optimal_return
    assert round(float(short[0]), 9) == round(
        Reference(m.cells, 10, m.start, "pass").best_return(20), 9
    )


@pytest.mark.parametrize("share", [0.0, 1.0])
def test_share_extremes(share: float) -> None:
    cfg = RandomLevelConfig(
        guarded_share=share, teleport_share=share, hazard_share=share, num_enemies=2
    )
    cells, starts, info = generate_levels(cfg, np.arange(120), np.zeros(120))
    for flags in (info.guarded, info.needs_teleport, info.hazard_on_route):
        assert flags.all() if share == 1.0 else not flags.any()
    assert all(
        Reference(c, 10, int(s), "block").solvable() for c, s in zip(cells, starts, strict=True)
    )


def test_levels_depend_only_on_their_key() -> None:
    cfg = RandomLevelConfig()
    seeds, eps = np.array([3, 9, 3, 1000]), np.array([0, 5, 1, 2])
    batch_cells, batch_starts, batch_info = generate_levels(cfg, seeds, eps)
    for i in range(4):
        one_cells, one_starts, one_info = generate_levels(cfg, seeds[i : i + 1], eps[i : i + 1])
        assert (one_cells[0] == batch_cells[i]).all() and one_starts[0] == batch_starts[i]
        assert one_info.row(0) == batch_info.row(i)
    assert not (batch_cells[0] == batch_cells[2]).all()  # another episode, another level


def test_other_sizes_and_parameters() -> None:
    cfg = RandomLevelConfig(height=7, width=12, num_enemies=3, num_pits=1, wall_segments=4)
    cells, starts, _ = generate_levels(cfg, np.arange(60), np.zeros(60))
    assert cells.shape == (60, 84)
    assert ((cells == R.ENEMY).sum(axis=1) == 3).all()
    assert all(
        Reference(c, 12, int(s), "block").solvable() for c, s in zip(cells, starts, strict=True)
    )


def test_env_plays_the_keyed_levels_and_reports_them() -> None:
    env = RGWRandomEnv()
    assert env.enemy == "block"
    cfg = env.level_config
    first = env.reset(seed=11)
    second = env.reset()
    again = env.reset(seed=11)
    rules = Rules(enemy="block", max_steps=100)
    cells, starts, info = generate_levels(cfg, np.array([11, 11]), np.array([0, 1]), rules)
    for k, ((obs, inf), c, s) in enumerate(
        [(first, cells[0], starts[0]), (second, cells[1], starts[1])]
    ):
        assert inf["agent"] == divmod(int(s), 10)
        assert (
            obs[:8].argmax(axis=0).reshape(-1)[c != R.EMPTY] == R.ENTITY_OF_CELL[c][c != R.EMPTY]
        ).all()
        assert {key: inf[key] for key in info._fields} == info.row(k)
    assert (again[0] == first[0]).all() and again[1] == first[1]
    assert not (second[0] == first[0]).all()
    assert RGWRandomEnv(classic=True).enemy == "pass"


def test_the_kind_shows_in_every_step_info() -> None:
    env = RGWRandomEnv(max_steps=5)
    _, info = env.reset(seed=3)
    kinds = {k: info[k] for k in ("optimal_return", "guarded", "needs_teleport", "hazard_on_route")}
    for _ in range(5):
        info = env.step(0)[4]
        assert {k: info[k] for k in kinds} == kinds


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"guarded_share": 1.5}, "guarded_share must be a number in"),
        ({"num_enemies": 0}, "num_enemies must be an integer >= 1"),
        ({"num_enemies": 4}, "num_enemies must be at most 3"),
        ({"height": 4}, "height must be an integer >= 5"),
        ({"num_mountains": 60}, "do not fit"),
        ({"enemies": 2}, "unknown rgw-random parameter 'enemies'"),
        ({"enemy": "wall"}, "enemy 'wall' is not one of"),
        ({"enemy": "end", "classic": True}, "classic=True"),
    ],
)
def test_bad_parameters_are_refused(kwargs: dict, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        RGWRandomEnv(**kwargs)


def test_an_unknown_parameter_names_the_env_options_too() -> None:
    """The message lists the level parameters and the env's own options, which stay in step."""
    import inspect

    from neurosym.envs.rgw_random import ENV_OPTIONS
    from neurosym.envs.rgw_vector import RGWRandomVectorEnv

    for cls, skip in ((RGWRandomEnv, set()), (RGWRandomVectorEnv, {"num_envs", "seed", "copy"})):
        params = inspect.signature(cls.__init__).parameters
        named = [n for n, p in params.items() if p.kind is p.KEYWORD_ONLY and n not in skip]
        assert tuple(named) == ENV_OPTIONS, cls
    with pytest.raises(ConfigError, match=r"num_mountains.*\(or an option of the env: classic, "):
        RGWRandomEnv(mountains=3)
