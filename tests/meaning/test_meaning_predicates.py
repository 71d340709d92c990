"""State predicates and behaviour measures from the trace of scripted rgw2 routes."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

from neurosym.meaning.intervene import behaviour, relates_table
from neurosym.meaning.predicates import acted_states, state_labels


@pytest.fixture(scope="session")
def recording(scripted_recording):  # noqa: ANN201
    """``recording(...)``, built from the shared builders."""
    @cache
    def recording():  # noqa: ANN201

        return scripted_recording(
            "predinet"
        )  # 0 optimal, 1 no_sword, 2 pit, 3 back_for_sword, 4 timeout
    return recording


def at(labels, name: str, episode: int) -> np.ndarray:  # noqa: ANN001
    rows = labels.states["episode"].to_numpy() == episode
    return labels.column(name)[rows]


def test_one_row_per_acted_state(recording) -> None:
    rec = recording()
    states = acted_states(rec.episodes)
    assert len(states) == int(rec.episodes["steps"].sum())
    assert states[states.episode == 0]["t"].tolist() == list(range(int(rec.episodes.steps[0])))


def test_holding_visited_and_next_target_follow_the_events(recording) -> None:
    labels = state_labels(recording(), "rgw")
    # optimal route: picked(sword) at t=5, teleported at 11, enemy beaten at 19, terminal at 20
    holding = at(labels, "holding(sword)", 0)
    assert not holding[:6].any() and holding[6:].all()
    assert np.array_equal(at(labels, "visited(sword)", 0), holding)
    nxt = at(labels, "next_target(sword)", 0)
    assert nxt[:6].all() and not nxt[6:].any()
    assert at(labels, "next_target(teleport)", 0)[6:12].all()
    assert at(labels, "next_target(enemy)", 0)[12:20].all()
    assert at(labels, "next_target(terminal)", 0)[20:].tolist() == [True]
    events = recording().events
    assert events[(events.episode == 0) & (events.event == "defeated(enemy)")]["t"].tolist() == [19]
    # timeout: nothing is ever reached
    assert not at(labels, "visited(sword)", 4).any()
    assert not at(labels, "next_target(sword)", 4).any()


def test_geometry_of_agent_and_objects(recording) -> None:
    labels = state_labels(recording(), "rgw")
    # optimal route starts with 6 steps right along row 0 towards the sword at (0, 6)
    left = at(labels, "left_of(agent,sword)", 0)
    assert left[:6].all()  # columns 0..5 < 6
    adjacent = at(labels, "adjacent(agent,sword)", 0)
    assert adjacent.tolist()[:6] == [False] * 5 + [True]
    assert not at(labels, "left_of(agent,sword)", 0)[6:].any()  # the sword is gone: false
    assert at(labels, "above(agent,enemy)", 0)[:6].all()


def test_behaviour_measures(recording) -> None:
    m = behaviour(recording(), "rgw")
    # optimal and back_for_sword beat the enemy with the sword; no_sword meets it unarmed,
    # back_for_sword too (before going back); pit and timeout never meet it
    assert m["enemy_met"] == 3 / 5
    assert m["enemy_unarmed"] == 2 / 5
    assert m["enemy_defeated"] == 2 / 5
    assert m["sword_before_enemy"] == 1 / 5
    assert m["sword_picked"] == 3 / 5  # optimal, pit, back_for_sword
    assert m["success"] == 3 / 5


def test_relates_shares_are_shares_of_states(recording) -> None:
    table = relates_table(recording(), "predinet")
    assert ((table["share"] > 0) & (table["share"] <= 1)).all()
    assert (table["a"] < table["b"]).all()
