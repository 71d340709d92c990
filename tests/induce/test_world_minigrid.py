"""World rules learned from Minigrid and BabyAI KBs of random-action episodes (tiny untrained network):
the actions, the faced cell, door states and what the agent carries, colours as variables."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

from neurosym.envs.minigrid_state import COLOURS
from neurosym.facts.tables import extract_facts
from neurosym.induce import induce_world
from neurosym.induce.background import FAMILIES
from neurosym.record.recorder import record

pytestmark = pytest.mark.expensive  # world rules searched over 30-100 recorded episodes

CASES = {  # env -> (env options, episodes)
    # 30 random episodes of 100 steps on seed 0 unlock the door 7 times, close it twice and
    # reach the goal twice
    "MiniGrid-DoorKey-5x5-v0": ({"max_steps": 100}, 30),
    # eight keys, balls and boxes of several colours in one room: picks, drops, boxes opened
    "BabyAI-PickupLoc-v0": ({"max_steps": 64}, 100),
}


@pytest.fixture(scope="module", params=sorted(CASES))
def kb(
    request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory, small_agent
) -> Path:
    env = request.param
    options, episodes = CASES[env]
    rec = record(small_agent(env), env, episodes, seed=0, actions="random", env_kwargs=options)
    return extract_facts(rec).to_prolog(tmp_path_factory.mktemp("minigrid") / "train.pl")


@pytest.fixture(scope="module")
def learned(kb: Path) -> tuple[object, Path]:
    return induce_world(kb), kb


def _clause(head: str, *body: str) -> str:
    return f"predicts(E, T, {head}) :-\n    " + ",\n    ".join(body) + "."


EXPECTED = {
    "MiniGrid-DoorKey-5x5-v0": {
        "bumped(wall)": [_clause("bumped(wall)", "action(E, T, forward)", "ahead(E, T, wall)")],
        "picked(key(C))": [
            _clause("picked(key(C))", "ahead(E, T, key(C))", "action(E, T, pickup)")
        ],
        "dropped(key(C))": [
            _clause(
                "dropped(key(C))",
                "carrying(E, T, key(C))",
                "action(E, T, drop)",
                "ahead(E, T, empty)",
            )
        ],
        # DoorKey's one key has the door's colour: the door the agent faces needs no colour
        "unlocked(door(C))": [
            _clause(
                "unlocked(door(C))",
                "action(E, T, toggle)",
                "carrying(E, T, key(C))",
                "ahead_door(E, T, locked)",
            )
        ],
        "closed(door(C))": [
            _clause(
                "closed(door(C))",
                "ahead(E, T, door(C))",
                "ahead_door(E, T, open)",
                "action(E, T, toggle)",
            )
        ],
        "reached(goal)": [_clause("reached(goal)", "ahead(E, T, goal)", "action(E, T, forward)")],
    },
    "BabyAI-PickupLoc-v0": {
        **{
            f"picked({t}(C))": [
                _clause(
                    f"picked({t}(C))",
                    f"ahead(E, T, {t}(C))",
                    "action(E, T, pickup)",
                    "carrying(E, T, nothing)",
                )
            ]
            for t in ("key", "ball", "box")
        },
        "dropped(ball(C))": [
            _clause(
                "dropped(ball(C))",
                "carrying(E, T, ball(C))",
                "action(E, T, drop)",
                "ahead(E, T, empty)",
            )
        ],
        "opened(box(C))": [
            _clause("opened(box(C))", "ahead(E, T, box(C))", "action(E, T, toggle)")
        ],
    },
}


def test_the_minigrid_rules_are_learned(learned: tuple) -> None:
    rules, _ = learned
    assert rules.family == "minigrid"
    assert set(rules.scores) == set(FAMILIES["minigrid"].vocabulary)
    for event, clauses in EXPECTED[rules.env].items():
        score = rules.scores[event]
        assert score.status == "determined", (event, score.reason)
        assert [c.text() for c in score.clauses] == clauses
        assert (score.train_precision, score.train_recall) == (1.0, 1.0)
    assert rules.scores["fell(lava)"].reason == "no positive example in the KB"


def test_colours_are_variables_over_several_colours(learned: tuple) -> None:
    rules, kb = learned
    if rules.env != "BabyAI-PickupLoc-v0":
        pytest.skip("DoorKey has one colour")
    picked = set(re.findall(r"picked\((?:key|ball|box)\((\w+)\)\)", kb.read_text()))
    assert len(picked) >= 3  # several colours picked up, one clause per kind of object
    assert len(rules.scores["picked(ball(C))"].clauses) == 1
    words = set(re.findall(r"\w+", "\n".join(c.text() for c in rules.clauses)))
    assert not words & set(COLOURS)


def _facts(swipl: Path, files: list[Path], goal: str) -> set[str]:
    query = f"forall({goal}, (writeq(E-T-X), nl))"
    out = subprocess.run(
        [str(swipl), "-q", "-g", query, "-t", "halt", *map(str, files)],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert out.returncode == 0 and out.stderr == "", out.stderr
    return set(out.stdout.split())


def test_world_pl_predicts_exactly_the_determined_events_in_plain_swipl(
    learned: tuple, tmp_path: Path, swipl: Path
) -> None:
    rules, kb = learned
    world = rules.write(tmp_path / "world.pl")
    text = world.read_text()
    assert "holding/3, facing/3, door_state/4, terrain/4" in " ".join(text.split("*/")[0].split())
    assert "ahead_door(E, T, State) :-" in text
    determined = [s.event for s in rules.scores.values() if s.status == "determined"]
    pattern = re.compile("|".join(re.escape(e).replace("C", "[a-z]+") for e in determined))
    events = {f for f in _facts(swipl, [kb], "event(E, T, X)") if pattern.fullmatch(f.split("-", 2)[2])}
    assert events and _facts(swipl, [kb, world], "predicts(E, T, X)") == events
