"""Strategies on Minigrid: the label is the object of the agent's next contact event (the object
ahead on a pickup, toggle or forward), the door features, and a learned file that plays."""

from __future__ import annotations

from pathlib import Path

import pytest
from minigrid_scripted import DOORKEY, doorkey_recording
from test_strategy_features import check_features_agree

from neurosym.facts.tables import extract_facts
from neurosym.induce.strategy_data import candidates, labels, load_trace
from neurosym.induce.strategy_features import world_features
from neurosym.play import score_strategy


@pytest.fixture(scope="module")
def kb(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The scripted DoorKey episode (seed 1) as a KB: bump into the key, pick it up, turn, bump
    into the door, unlock it, forward twice, turn, the goal."""
    out = tmp_path_factory.mktemp("minigrid") / "kb.pl"
    return extract_facts(doorkey_recording()).to_prolog(out)


def test_labels_are_the_object_of_the_next_contact_event(kb: Path) -> None:
    """picked(key(yellow)) in state 1, unlocked/opened(door(yellow)) in state 4, reached(goal)
    in state 8: each earlier state's next object is that event's object, the one ahead."""
    got = labels(load_trace(kb))
    assert list(zip(got["T"], got["Goal"], strict=True)) == [
        (0, "key_yellow"), (1, "key_yellow"),
        (2, "door_yellow"), (3, "door_yellow"), (4, "door_yellow"),
        (5, "goal"), (6, "goal"), (7, "goal"), (8, "goal"),
    ]  # fmt: skip


def test_door_features(kb: Path) -> None:
    """door_locked until the toggle in state 4, open after; the door of the held key once the
    key is held (state 2 on); the key of the locked door while it is on the map."""
    trace = load_trace(kb)
    pairs = candidates(trace)
    feats, x = world_features(trace, pairs[["E", "T", "O", "R", "C"]])
    col = {f.name: i for i, f in enumerate(feats)}
    door = (pairs["O"] == "door_yellow").to_numpy()
    key = (pairs["O"] == "key_yellow").to_numpy()
    ts = pairs["T"].to_numpy()
    assert [int(v) for v in x[door, col["door_locked"]]] == [int(t <= 4) for t in ts[door]]
    assert [int(v) for v in x[door, col["door_open"]]] == [int(t > 4) for t in ts[door]]
    assert [int(v) for v in x[door, col["door_of_held_key"]]] == [int(t >= 2) for t in ts[door]]
    assert list(ts[key]) == [0, 1] and list(x[key, col["key_of_locked_door"]]) == [1.0, 1.0]


def test_a_learned_minigrid_strategy_plays_its_level(neurosym_main, kb: Path, tmp_path: Path) -> None:
    """Learned from the one episode (all of it: no held-out share), the strategy chooses every
    state's next object, its features' Prolog agrees with their Python, and played through route.pl it solves the level in fewer steps than
    the script's 9 (the script bumps twice)."""
    out = tmp_path / "strategy.pl"
    ran = neurosym_main("induce", "strategy", "--kb", kb, "--holdout", kb, "--out", out)
    assert ran.returncode == 0, ran.stderr
    assert "% Scores: fidelity 1.0000 on 9 held-out states" in out.read_text()
    assert check_features_agree(kb, out, "world") >= 20  # the door features among them, in SWI
    report = score_strategy(out, DOORKEY, 1, seed=1, fallback="none").as_dict()
    assert report["outcomes"] == {"goal": 1} and report["fallback_steps"] == 0
    assert report["mean_length"] == 7
