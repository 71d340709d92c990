"""Recording scripted routes through Relational-Grid-World Configuration-2.

A random agent seldom meets the sword or the enemy, so these tests drive the
recorder with an agent whose actions follow fixed plans (one per episode) while
a real model supplies the introspection. The routes give the events the rules
are about: sword before enemy, enemy without the sword, back for the sword, a
pit, a timeout. The plans and recordings live in tests/builders.py; other test files reach
them through the conftest fixtures of the same names.
"""

from __future__ import annotations

import pytest
from builders import (
    EXPECTED,
    MAX_STEPS,
    PLANS,
    U,
    explorer_recording,
    scripted_recording,
)

from neurosym.envs import make

KEY_EVENTS = (
    "picked(sword)",
    "teleported",
    "defeated(enemy)",
    "hurt_by(enemy)",
    "reached(terminal)",
    "fell(pit)",
)


def test_plans_give_the_expected_events_and_outcomes() -> None:
    rec = scripted_recording()
    for e, (name, (outcome, events)) in enumerate(EXPECTED.items()):
        row = rec.episodes[rec.episodes.episode == e].iloc[0]
        assert row.outcome == outcome, name
        got = rec.events[(rec.events.episode == e) & rec.events.event.isin(KEY_EVENTS)][
            "event"
        ].tolist()
        assert got == events, name
    timeout = rec.episodes.iloc[-1]
    assert timeout.steps == MAX_STEPS


def test_holding_follows_the_sword() -> None:
    rec = scripted_recording()
    picked = rec.events[rec.events.event == "picked(sword)"].set_index("episode")["t"]
    for e, t_pick in picked.items():
        held = rec.holding[(rec.holding.episode == e) & (rec.holding.item == "sword")]["t"]
        steps = int(rec.episodes.set_index("episode").loc[e, "steps"])
        assert held.tolist() == list(range(t_pick + 1, steps + 1)), e  # states after the pick-up
    # the sword leaves the map once picked up
    pos = rec.positions
    optimal = pos[(pos.episode == 0) & (pos.object == "sword")]["t"]
    assert optimal.max() == picked[0]


@pytest.mark.parametrize("name", list(PLANS))
def test_scripted_routes_replay(name: str) -> None:
    rec = scripted_recording()
    e = list(PLANS).index(name)
    env = make("rgw2", max_steps=MAX_STEPS)
    env.reset(seed=int(rec.episodes.seed[e]))
    actions = rec.steps[rec.steps.episode == e]["action"].tolist()
    plan = PLANS[name] + [U] * (len(actions) - len(PLANS[name]))
    assert actions == [("up", "right", "down", "left")[a] for a in plan[: len(actions)]]
    rewards = [env.step(a)[1] for a in plan[: len(actions)]]
    assert rewards == rec.steps[rec.steps.episode == e]["reward"].tolist()


# --------------------------------------------------------------------------- Box-World


def test_explorer_opens_boxes_and_meets_distractors() -> None:
    rec = explorer_recording()
    events = set(rec.events["event"])
    assert any(e.startswith("opened(lock(") for e in events)
    assert {"got(gem)", "hit(distractor)"} <= events
    assert set(rec.episodes["outcome"]) >= {"gem", "distractor"}
    assert rec.holding["item"].str.fullmatch(r"key\([a-z]+\)").all()
