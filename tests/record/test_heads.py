"""Heads worth reading: head_summary on a hand-made attends table and on a recording."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import pandas as pd
import pytest

from neurosym.record.heads import head_summary


def attends(rows: list[tuple]) -> SimpleNamespace:
    """A recording stand-in: rows of (episode, t, head, (entity, row, col) arg 1, ... arg 2)."""
    out = []
    for e, t, h, a1, a2 in rows:
        for arg, (entity, r, c) in ((1, a1), (2, a2)):
            out.append((e, t, h, arg, entity, r, c, 0.5))
    cols = ["episode", "t", "head", "arg", "entity", "row", "col", "weight"]
    return SimpleNamespace(attends=pd.DataFrame(out, columns=cols))


SWORD, ENEMY, AGENT = ("sword", 0, 6), ("enemy", 9, 1), ("agent", 0, 0)
TERM, WALL, EMPTY, MOUNT = ("terminal", 9, 0), ("wall", 6, 0), ("empty", 5, 5), ("mountain", 0, 5)
PIT_1, PIT_2 = ("pit", 7, 8), ("pit", 8, 9)


def test_shares_and_pairs_of_a_fixture() -> None:
    rec = attends(
        [
            # head 0: sword-enemy twice, agent-terminal once, agent-agent, agent-wall, empty-mountain
            (0, 0, 0, SWORD, ENEMY),
            (0, 1, 0, SWORD, ENEMY),
            (0, 2, 0, AGENT, TERM),
            (0, 3, 0, AGENT, AGENT),
            (1, 0, 0, AGENT, WALL),
            (1, 1, 0, EMPTY, MOUNT),
            # head 1: two pits are two different objects of one type; one pit twice is not
            (0, 0, 1, PIT_1, PIT_2),
            (0, 1, 1, PIT_1, PIT_1),
            (0, 2, 1, ENEMY, SWORD),
            (0, 3, 1, TERM, AGENT),
            (1, 0, 1, AGENT, EMPTY),
            (1, 1, 1, WALL, WALL),
        ]
    )
    df = head_summary(rec)
    assert df["head"].tolist() == [0, 1] and df["states"].tolist() == [6, 6]
    h0, h1 = df.to_dict("records")
    assert h0["two_objects"] == pytest.approx(3 / 6)
    assert (h0["pair_1"], h0["share_1"]) == ("sword-enemy", pytest.approx(2 / 6))
    assert (h0["pair_2"], h0["share_2"]) == ("agent-terminal", pytest.approx(1 / 6))
    assert h0["pair_3"] is None and h0["share_3"] is None
    assert h1["two_objects"] == pytest.approx(3 / 6)
    # equal counts: by name
    assert [h1["pair_1"], h1["pair_2"], h1["pair_3"]] == [
        "enemy-sword",
        "pit-pit",
        "terminal-agent",
    ]


def test_next_object_follows_the_agents_next_event() -> None:
    rows = [
        (0, 0, 0, SWORD, ENEMY),  # next: sword (picked at step 1) -> on it
        (0, 1, 0, SWORD, ENEMY),  # step 1's own event is still ahead of state 1 -> on it
        (0, 2, 0, AGENT, TERM),  # next: terminal -> on it
        (0, 3, 0, AGENT, AGENT),  # next: terminal -> not on it
        (1, 0, 0, AGENT, WALL),  # episode 1 meets only terrain: left out
        (0, 0, 1, PIT_1, PIT_2),
        (0, 1, 1, PIT_1, PIT_1),
        (0, 2, 1, ENEMY, SWORD),  # next: terminal -> not on it
        (0, 3, 1, TERM, AGENT),  # argument 1 on the next object counts too
        (1, 0, 1, AGENT, EMPTY),
    ]
    rec = attends(rows)
    rec.events = pd.DataFrame(
        [(0, 1, "picked(sword)"), (0, 3, "reached(terminal)"), (1, 0, "crossed(mountain)")],
        columns=["episode", "t", "event"],
    )
    h0, h1 = head_summary(rec).to_dict("records")
    assert h0["next_object"] == pytest.approx(3 / 4)
    assert h1["next_object"] == pytest.approx(1 / 4)
    # a recording without events (or that never meets an object): None, not 0
    assert head_summary(attends(rows))["next_object"].tolist() == [None, None]


def test_event_objects_of_both_families() -> None:
    from neurosym.record.heads import event_object

    assert [event_object(e) for e in ("picked(sword)", "defeated(enemy)", "teleported")] == [
        "sword",
        "enemy",
        "teleport",
    ]
    assert [event_object(e) for e in ("got(key(red))", "opened(lock(red))", "got(gem)")] == [
        "key(red)",
        "lock(red)",
        "gem",
    ]
    assert event_object("crossed(mountain)") is None and event_object("done") is None


def test_an_mhdpa_recording_has_no_argument_pairs() -> None:
    rec = SimpleNamespace(attends=pd.DataFrame(columns=["episode", "t", "head", "arg"]))
    df = head_summary(rec)
    assert df.empty and list(df.columns)[:3] == ["head", "states", "two_objects"]


def test_on_a_recording_and_in_the_extract_report(
    scripted_recording,
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:

    from neurosym.facts.tables import extract_facts
    from neurosym.record.extraction import write_outputs
    from neurosym.reports.terminal import print_report

    rec = scripted_recording()
    df = head_summary(rec)
    states = rec.attends.groupby("head")[["episode", "t"]].apply(lambda g: len(g.drop_duplicates()))
    assert df.set_index("head")["states"].to_dict() == states.to_dict()
    for row in df.to_dict("records"):
        shares = [row[f"share_{k}"] or 0.0 for k in (1, 2, 3)]
        assert sum(shares) <= row["two_objects"] + 1e-12 and shares == sorted(shares, reverse=True)
    facts = extract_facts(rec, threshold="quantile:0.9")
    written = write_outputs(tmp_path / "out", rec, facts, ("pl",))
    print_report(rec, facts, written, kb=written.get("kb.pl"))
    text = capsys.readouterr().out
    assert "two objects" in text and "next object" in text and "top pairs (share of states)" in text
    assert "on or beside two objects" in text and "top pair (share of states)" in text


def test_beside_reads_a_terrain_argument_as_the_object_next_to_it() -> None:
    # one state's map: agent (2, 2), sword (2, 5), enemy (5, 5), a pit (4, 3)
    positions = pd.DataFrame(
        [(0, 0, "agent", "agent", 2, 2), (0, 0, "sword_1", "sword", 2, 5)]
        + [(0, 0, "enemy_1", "enemy", 5, 5), (0, 0, "pit_1", "pit", 4, 3)],
        columns=["episode", "t", "object", "type", "row", "col"],
    )
    rows = [
        (0, 0, 0, ("empty", 2, 3), ("sword", 2, 5)),  # beside the agent, on the sword
        (0, 0, 1, ("empty", 1, 2), ("empty", 2, 4)),  # beside the agent, beside the sword
        (0, 0, 2, ("empty", 2, 4), ("sword", 2, 5)),  # the sword twice: one object, not two
        (0, 0, 3, ("agent", 2, 2), ("empty", 8, 8)),  # nothing beside (8, 8): not read as one
        (0, 0, 4, ("wall", 4, 4), ("agent", 2, 2)),  # beside the pit and the enemy: ties by name
    ]
    rec = attends(rows)
    rec.positions = positions
    df = head_summary(rec).set_index("head")
    assert df["two_objects"].tolist() == [0.0] * 5  # the strict figure counts none of them
    assert df["beside_objects"].tolist() == [1.0, 1.0, 0.0, 0.0, 1.0]
    # (4, 4) touches the pit (4, 3) and the enemy (5, 5), both one cell away: 'enemy' sorts first
    assert df["beside_pair"].tolist() == ["agent-sword", "agent-sword", None, None, "enemy-agent"]
    assert df.loc[0, "beside_share"] == pytest.approx(1.0) and df.loc[2, "beside_share"] is None
    # a recording without positions: None, not 0
    assert head_summary(attends(rows))["beside_objects"].tolist() == [None] * 5
