"""Next-object labels on hand-made KBs: the object of the first contact at or after each state."""

from __future__ import annotations

from pathlib import Path

from strategy_kbs import write_kb

from neurosym.induce.strategy_data import labels, load_trace

RGW = [
    "object(agent,agent).", "object(sword,sword).", "object(enemy,enemy).",
    "object(terminal,terminal).", "object(teleport_1,teleport).", "object(teleport_2,teleport).",
    "object(pit_1,pit).",
    # state 0: the sword is right of the agent
    "at(0,0,agent,0,0).", "at(0,0,sword,0,1).", "at(0,0,teleport_1,1,1).",
    "at(0,0,teleport_2,3,3).", "at(0,0,enemy,3,2).", "at(0,0,terminal,4,3).",
    "step(0,0,right,0.0).", "event(0,0,picked(sword)).",
    # state 1: down into teleport_1, out at teleport_2
    "at(0,1,agent,0,1).", "at(0,1,teleport_1,1,1).", "at(0,1,teleport_2,3,3).",
    "at(0,1,enemy,3,2).", "at(0,1,terminal,4,3).", "holding(0,1,sword).",
    "step(0,1,down,0.0).", "event(0,1,teleported).",
    # state 2: left into the enemy
    "at(0,2,agent,3,3).", "at(0,2,teleport_1,1,1).", "at(0,2,teleport_2,3,3).",
    "at(0,2,enemy,3,2).", "at(0,2,terminal,4,3).", "holding(0,2,sword).",
    "step(0,2,left,1.0).", "event(0,2,defeated(enemy)).",
    # states 3, 4: a step without contact, then the terminal; state 5 has no label
    "at(0,3,agent,3,2).", "at(0,3,teleport_1,1,1).", "at(0,3,teleport_2,3,3).",
    "at(0,3,terminal,4,3).", "step(0,3,down,-0.1).", "event(0,3,crossed(mountain)).",
    "at(0,4,agent,4,2).", "at(0,4,teleport_1,1,1).", "at(0,4,teleport_2,3,3).",
    "at(0,4,terminal,4,3).", "step(0,4,right,10.0).", "event(0,4,reached(terminal)).",
    "at(0,5,agent,4,3).", "at(0,5,teleport_1,1,1).", "at(0,5,teleport_2,3,3).",
    # episode 1: bumps the border, then falls into a pit; state 0 -> pit_1
    "at(1,0,agent,0,0).", "at(1,0,pit_1,1,0).", "step(1,0,up,0.0).", "event(1,0,bumped(border)).",
    "at(1,1,agent,0,0).", "at(1,1,pit_1,1,0).", "step(1,1,down,-1.0).", "event(1,1,fell(pit)).",
    "at(1,2,agent,1,0).", "at(1,2,pit_1,1,0).",
    # episode 2: never meets anything: no labels
    "at(2,0,agent,0,0).", "step(2,0,up,0.0).", "event(2,0,bumped(border)).", "at(2,1,agent,0,0).",
]  # fmt: skip

BOXWORLD = [
    "object(agent,agent).", "object(key_red,key(red)).", "object(key_blue,key(blue)).",
    "object(lock_red,lock(red)).", "object(gem,gem).",
    "at(0,0,agent,1,1).", "at(0,0,key_red,1,2).", "at(0,0,key_blue,3,3).", "at(0,0,lock_red,3,4).",
    "step(0,0,right,0.0).", "event(0,0,got(key(red))).",
    *[
        f"at(0,{t},agent,{r},{c}). at(0,{t},key_blue,3,3). at(0,{t},lock_red,3,4). "
        f"holding(0,{t},key(red)). step(0,{t},{a},0.0)."
        for t, r, c, a in ((1, 1, 2, "right"), (2, 1, 3, "right"), (3, 1, 4, "down"), (4, 2, 4, "down"))
    ],
    "event(0,4,opened(lock(red))).", "event(0,4,got(key(blue))).",
    "at(0,5,agent,3,4).", "holding(0,5,key(blue)).",
]  # fmt: skip


def test_rgw_labels_follow_contacts(tmp_path: Path) -> None:
    kb = write_kb(tmp_path / "kb.pl", RGW)
    got = [tuple(row) for row in labels(load_trace(kb)).itertuples(index=False)]
    assert got == [
        (0, 0, "sword"), (0, 1, "teleport_1"), (0, 2, "enemy"), (0, 3, "terminal"),
        (0, 4, "terminal"), (1, 0, "pit_1"), (1, 1, "pit_1"),
    ]  # fmt: skip


def test_boxworld_labels_a_loose_key_then_the_lock_not_its_content(tmp_path: Path) -> None:
    kb = write_kb(tmp_path / "kb.pl", BOXWORLD)
    got = [tuple(row) for row in labels(load_trace(kb)).itertuples(index=False)]
    assert got == [(0, 0, "key_red")] + [(0, t, "lock_red") for t in range(1, 5)]
