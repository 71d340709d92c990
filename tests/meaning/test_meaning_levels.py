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


# --- procedural levels: the same change made to every episode's own level -----------------


@pytest.mark.parametrize(
    ("edit", "changes"),
    [
        ("remove_sword", {("sword", "empty")}),
        ("remove_enemy", {("enemy", "empty")}),
        ("swap_sword_enemy", {("sword", "enemy"), ("enemy", "sword")}),
    ],
)
def test_edited_rgw_random_levels_differ_only_by_the_edit(edit: str, changes: set) -> None:
    from neurosym.envs import rgw_rules as rules
    from neurosym.envs.rgw_random import RandomLevelConfig, generate_levels

    names = {rules.SWORD: "sword", rules.ENEMY: "enemy", rules.EMPTY: "empty"}
    seeds, episodes = np.arange(40), np.zeros(40, dtype=int)
    base, starts, _ = generate_levels(RandomLevelConfig(), seeds, episodes)
    cells, starts2, info = generate_levels(RandomLevelConfig(edit=edit), seeds, episodes)
    assert (starts == starts2).all()
    for b, c in zip(base, cells, strict=True):
        where = np.flatnonzero(b != c)
        assert len(where) == len(changes)
        assert {(names[int(b[i])], names[int(c[i])]) for i in where} == changes
    if edit == "remove_enemy":
        assert not info.guarded.any()  # no enemy guards anything
    if edit == "remove_sword":  # a guarded level cannot be solved without the sword
        _, _, base_info = generate_levels(RandomLevelConfig(), seeds, episodes)
        assert np.isnan(info.optimal_return[base_info.guarded]).all()
        assert np.isfinite(info.optimal_return[~base_info.guarded]).all()


def test_the_env_plays_the_edited_level_of_each_seed() -> None:
    plain, edited = make("rgw-random"), make("rgw-random", edit="remove_sword")
    for seed in (5, 6):
        a, b = plain.reset(seed=seed)[0], edited.reset(seed=seed)[0]
        differs = np.argwhere((a != b).any(axis=0))
        assert len(differs) == 1 and a[1][tuple(differs[0])] == 1 and b[1][tuple(differs[0])] == 0


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"edit": "remove_wall"}, "unknown edit 'remove_wall'; expected one of remove_sword"),
        ({"edit": "swap_sword_enemy", "num_enemies": 2}, "swap_sword_enemy needs num_enemies=1"),
    ],
)
def test_bad_edits_are_refused(kwargs: dict, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        make("rgw-random", **kwargs)


def test_procedural_experiments_and_their_matched_observations() -> None:
    from types import SimpleNamespace

    import pandas as pd

    from neurosym.meaning.intervene import matched_procedural_observations, procedural_experiments

    exps, skipped = procedural_experiments({})
    assert [e.id for e in exps] == ["remove_sword", "remove_enemy", "swap_sword_enemy"]
    assert [str(e.kind) for e in exps] == ["remove(sword)", "remove(enemy)", "swap(sword,enemy)"]
    assert {k for k, _ in skipped} == {"move(enemy)", "move(sword)"}
    exps, skipped = procedural_experiments({"num_enemies": 2})
    assert "swap_sword_enemy" not in [e.id for e in exps] and "swap(sword,enemy)" in dict(skipped)
    # two episodes of one state each: the first observation of seeds 5 and 6
    env = make("rgw-random")
    obs = np.stack([env.reset(seed=s)[0] for s in (5, 6)])
    rec = SimpleNamespace(
        episodes=pd.DataFrame({"episode": [0, 1], "seed": [5, 6], "steps": [1, 1]})
    )
    out = matched_procedural_observations(obs, rec, "remove_sword", "rgw-random", {})
    for i, seed in enumerate((5, 6)):
        expected = make("rgw-random", edit="remove_sword").reset(seed=seed)[0]
        assert (out[i] == expected).all()
