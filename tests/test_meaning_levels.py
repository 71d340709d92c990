"""Changed levels change exactly the cells they say, and nothing else."""

from __future__ import annotations

import numpy as np
import pytest

from neurosym.envs import make
from neurosym.envs.rgw_maps import load_map, parse_map
from neurosym.errors import ConfigError
from neurosym.meaning import levels
from neurosym.meaning.intervene import level_experiments, matched_observations


def grid(text: str) -> np.ndarray:
    return np.array([list(line) for line in text.splitlines()])


def differing(before: str, after: str) -> set[tuple[int, int, str, str]]:
    a, b = grid(before), grid(after)
    rows, cols = np.nonzero(a != b)
    return {(int(r), int(c), str(a[r, c]), str(b[r, c])) for r, c in zip(rows, cols, strict=True)}


RGW2 = load_map("rgw2")


def test_remove_empties_one_cell() -> None:
    level = levels.remove(RGW2, "sword")
    assert differing(RGW2.text(), level.text) == {(0, 6, "S", ".")}
    assert [(c.row, c.col, c.before, c.after) for c in level.changes] == [(0, 6, "sword", "empty")]


def test_move_and_swap_change_two_cells() -> None:
    moved = levels.move(RGW2, "enemy", 7, 1)
    assert differing(RGW2.text(), moved.text) == {(9, 1, "E", "."), (7, 1, ".", "E")}
    swapped = levels.swap(RGW2, "sword", "enemy")
    assert differing(RGW2.text(), swapped.text) == {(0, 6, "S", "E"), (9, 1, "E", "S")}
    parse_map(swapped.text)  # still a playable map


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: levels.move(RGW2, "enemy", 0, 0), "not a free cell"),  # the agent's start
        (lambda: levels.move(RGW2, "enemy", 6, 0), "not a free cell"),  # a wall
        (lambda: levels.remove(RGW2, "teleport"), "cannot change 'teleport'"),
        (lambda: levels.remove(RGW2, "pit"), "has 2 pit cells"),
    ],
)
def test_bad_changes_are_refused(call, message: str) -> None:  # noqa: ANN001
    with pytest.raises(ConfigError, match=message):
        call()


def test_distances_follow_the_env_rules() -> None:
    d = levels.distances(RGW2).reshape(10, 10)
    assert d[0, 0] == 0 and d[0, 6] == 6
    assert d[6, 0] == -1  # a wall
    assert d[8, 8] == 12  # through the teleport at (3, 9), entered from (3, 8) at 11
    assert d[9, 1] == 20 and d[9, 0] == 21  # the enemy, then the terminal behind it


def test_every_level_experiment_changes_only_what_its_detail_lists() -> None:
    route = np.zeros(100, dtype=bool)
    route[[0, 1, 2, 3, 4, 5, 6, 16, 26, 36, 37, 38, 88, 98, 97, 96, 95, 94, 93, 92, 91, 90]] = True
    exps, skipped = level_experiments(RGW2, route)
    assert [e.id for e in exps] == [
        "remove_sword", "remove_enemy", "move_enemy", "move_sword", "swap_sword_enemy"
    ]  # fmt: skip
    assert skipped == []
    for e in exps:
        detail = e.detail if e.detail.functor == "cells" else e.detail.args[0]
        listed = {(c.args[0], c.args[1]) for c in detail.args[0]}
        assert {(r, c) for r, c, _, _ in differing(RGW2.text(), e.map_text)} == listed, e.id
    move_enemy = next(e for e in exps if e.id == "move_enemy")
    r, c = move_enemy.kind.args[1:]
    assert not route[r * 10 + c]  # off the route


def test_matched_observations_redraw_only_the_changed_cells() -> None:
    env = make("rgw2")
    obs0, _ = env.reset(seed=0)
    obs1, *_ = env.step(1)  # one step right: the agent at (0, 1)
    obs = np.stack([obs0, obs1])
    level = levels.swap(RGW2, "sword", "enemy")
    out = matched_observations(obs, RGW2.text(), level.text, "rgw2", {})
    changed = (out != obs).any(axis=1)  # (S, H, W)
    assert {tuple(x) for x in np.argwhere(changed[0])} == {(0, 6), (9, 1)}
    assert (out[:, 1, 0, 6] == 0).all() and (out[:, 2, 0, 6] == 1).all()  # enemy plane at (0, 6)
    assert (out[:, 0] == obs[:, 0]).all()  # the agent did not move
