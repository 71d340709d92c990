"""World rules learned from KBs of random-action episodes of the real envs (tiny untrained network)."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest
from builders import WORLD_CASES as CASES

from neurosym.errors import ConfigError
from neurosym.facts.tables import extract_facts
from neurosym.induce import induce_world
from neurosym.induce.background import VOCABULARY
from neurosym.record.recorder import record
from neurosym.record.recording import Recording


@pytest.fixture(scope="module", params=sorted(CASES))
def kbs(
    request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory, write_world_kb
) -> tuple[str, Path, Path]:
    folder = tmp_path_factory.mktemp(request.param)
    env = request.param
    return env, write_world_kb(folder / "train.pl", env, 0), write_world_kb(folder / "held.pl", env, 50_000)


@pytest.fixture(scope="module")
def learned(kbs: tuple[str, Path, Path]) -> tuple[str, object, Path]:
    env, train, held = kbs
    return env, induce_world(train, holdout=held), held


EXPECTED = {
    "rgw-random": {
        "bumped(border)": ["predicts(E, T, bumped(border)) :-\n    ahead(E, T, border)."],
        "bumped(wall)": ["predicts(E, T, bumped(wall)) :-\n    ahead(E, T, wall)."],
        "teleported": ["predicts(E, T, teleported) :-\n    ahead(E, T, teleport)."],
        "crossed(mountain)": ["predicts(E, T, crossed(mountain)) :-\n    ahead(E, T, mountain)."],
        "picked(sword)": ["predicts(E, T, picked(sword)) :-\n    ahead(E, T, sword)."],
        "fell(pit)": ["predicts(E, T, fell(pit)) :-\n    ahead(E, T, pit)."],
    },
    "bw2": {
        "opened(lock(C))": [
            "predicts(E, T, opened(lock(C))) :-\n    ahead(E, T, lock(C)),\n    holding(E, T, key(C))."
        ],
    },
}


def test_known_rules_are_learned(learned: tuple) -> None:
    env, rules, _ = learned
    for event, clauses in EXPECTED[env].items():
        score = rules.scores[event]
        assert score.status == "determined", (event, score.reason)
        assert [c.text() for c in score.clauses] == clauses


def test_every_determined_event_is_solved_perfectly_held_out(learned: tuple) -> None:
    env, rules, _ = learned
    assert set(rules.scores) == set(VOCABULARY[rules.family])
    determined = [s for s in rules.scores.values() if s.status == "determined"]
    assert len(determined) >= len(EXPECTED[env])
    for s in determined:
        assert (s.train_precision, s.train_recall) == (1.0, 1.0), s.event
        assert s.solved, (s.event, s.holdout_precision, s.holdout_recall)


def test_events_without_examples_are_undetermined_comments(learned: tuple, tmp_path: Path) -> None:
    env, rules, _ = learned
    if env != "rgw-random":
        pytest.skip("the enemy modes' own events")
    for event in ("bumped(enemy)", "killed_by(enemy)"):  # enemy=pass never blocks or kills
        assert rules.scores[event].status == "undetermined"
        assert rules.scores[event].reason == "no positive example in the KB"
    text = rules.write(tmp_path / "world.pl").read_text()
    assert "% undetermined: killed_by(enemy): no positive example in the KB" in text
    assert "predicts(E, T, killed_by" not in text


def _facts(swipl: Path, files: list[Path], goal: str) -> set[str]:
    query = f"forall({goal}, (writeq(E-T-X), nl))"
    out = subprocess.run(
        [str(swipl), "-q", "-g", query, "-t", "halt", *map(str, files)],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert out.returncode == 0 and out.stderr == "", out.stderr
    return set(out.stdout.split())


def test_world_pl_predicts_exactly_the_held_out_events_in_plain_swipl(
    learned: tuple, tmp_path: Path, swipl: Path
) -> None:
    _, rules, held = learned
    world = rules.write(tmp_path / "world.pl")
    head = world.read_text().splitlines()[0]
    assert head.startswith("/** <module> World rules learned")
    determined = [s.event for s in rules.scores.values() if s.status == "determined"]
    pattern = re.compile("|".join(re.escape(e).replace("C", "[a-z]+") for e in determined))
    events = {
        f for f in _facts(swipl, [held], "event(E, T, X)") if pattern.fullmatch(f.split("-", 2)[2])
    }
    predicted = _facts(swipl, [held, world], "predicts(E, T, X)")
    assert events and predicted == events
    # either load order works
    assert _facts(swipl, [world, held], "predicts(E, T, X)") == predicted


def test_a_kb_without_steps_or_events_is_one_line_error(small_agent, tmp_path: Path) -> None:
    empty = extract_facts(Recording()).to_prolog(tmp_path / "empty.pl")
    with pytest.raises(ConfigError, match=r"has no step/4 facts"):
        induce_world(empty)
    rec = record(small_agent("rgw2"), "rgw2", 1, env_kwargs={"max_steps": 1})
    rec.events = rec.events.iloc[:0]
    quiet = extract_facts(rec).to_prolog(tmp_path / "quiet.pl")
    with pytest.raises(ConfigError, match=r"has no event/3 facts"):
        induce_world(quiet)
    with pytest.raises(ConfigError, match=r"does not exist"):
        induce_world(tmp_path / "missing.pl")


def test_a_held_out_kb_of_another_env_family_is_refused(small_agent, kbs: tuple, tmp_path: Path) -> None:
    env, train, _ = kbs
    other = "bw2" if env == "rgw-random" else "rgw-random"
    rec = record(small_agent(other), other, 8, actions="random", env_kwargs={"max_steps": 300})
    path = extract_facts(rec).to_prolog(tmp_path / "other.pl")
    with pytest.raises(ConfigError, match=r"held-out KB .* is a (boxworld|rgw) KB; the rules"):
        induce_world(train, holdout=path)
