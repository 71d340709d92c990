"""The Prolog agent on Minigrid: route.pl turns and steps the agent to the strategy's object and
does the interaction; the live facing/3 and door_state/4 facts are the recorder's."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from minigrid_scripted import DOORKEY, SCRIPT, doorkey_recording

from neurosym.facts.tables import extract_facts
from neurosym.play import PrologAgent, score_strategy
from neurosym.play.cli_play import compare_file

ROOT = Path(__file__).resolve().parents[2]
HANDWRITTEN = ROOT / "neurosym" / "play" / "strategies" / "minigrid_handwritten.pl"


def _play(agent: PrologAgent, venv: Any, seed: int) -> tuple[list[tuple], str | None]:
    """(decider, goal, action) of every step of one episode, and its outcome."""
    obs, _ = venv.reset(seed=[seed])
    steps = []
    for _ in range(50):
        actions = agent.act(obs, venv)
        steps.append(agent.last)
        obs, _, terminated, truncated, info = venv.step(actions)
        if terminated[0] or truncated[0]:
            return steps, venv.episode_outcome(info, 0)
    return steps, None


def test_the_hand_written_strategy_solves_a_doorkey_level() -> None:
    """DoorKey-5x5 seed 1 (the scripted level: the key ahead, the door to the east): pick the
    key up, turn left to face the door, unlock it, through, turn right, onto the goal. Seven
    actions, every one the strategy's: the script's nine without its two bumps."""
    with PrologAgent(HANDWRITTEN) as agent:
        venv = agent.make_venv(DOORKEY, 1, seed=1)
        steps, outcome = _play(agent, venv, 1)
    assert outcome == "goal"
    assert steps == [
        ("strategy", "key_yellow", "pickup"),
        ("strategy", "door_yellow", "left"),
        ("strategy", "door_yellow", "toggle"),
        ("strategy", "goal", "forward"),
        ("strategy", "goal", "forward"),
        ("strategy", "goal", "right"),
        ("strategy", "goal", "forward"),
    ]


def test_the_trivial_strategy_has_no_route_through_the_locked_door() -> None:
    """Always the goal: behind the locked door route.pl finds no path (no_route), so route.pl's
    default goal takes the key and opens the door (3 steps), then the goal is the strategy's
    (4 steps); the shipped names resolve to the Minigrid files."""
    trivial = compare_file("trivial", DOORKEY)
    assert trivial.name == "minigrid_trivial.pl"
    assert compare_file("handwritten", "BabyAI-GoToRedBall-v0").name == "minigrid_handwritten.pl"
    report = score_strategy(trivial, DOORKEY, 1, seed=1).as_dict()
    assert report["outcomes"] == {"goal": 1} and report["fallbacks"] == {"no_route": 3}
    assert report["deciders"]["strategy"] == 4 and report["deciders"]["default_goal"] == 3


def test_live_facing_and_door_state_equal_the_extracted_ones(tmp_path: Path) -> None:
    """The scripted episode replayed through the agent's env: every state's facing/3 and
    door_state/4 in the agent's KB are the rows the KB of its recording holds (the door locked,
    then open; the agent's direction through its turns)."""
    tables = extract_facts(doorkey_recording()).tables
    policy = tmp_path / "s.pl"
    policy.write_text("goal(_, _, goal).\n")
    live: dict[str, list] = {"facing": [], "door_state": []}
    with PrologAgent(policy) as agent:
        venv = agent.make_venv(DOORKEY, 1, seed=1)
        obs, _ = venv.reset(seed=[1])
        for t, action in enumerate(SCRIPT):
            agent.act(obs, venv)  # asserts the state's facts; the script is played
            facts = agent.state_facts(0, t)
            live["facing"] += [(0, t, *row) for row in facts["facing"]]
            live["door_state"] += [(0, t, *row) for row in facts["door_state"]]
            obs, *_ = venv.step(np.array([action]))
    for name in live:
        df = tables[name]
        df = df[df["t"] < len(SCRIPT)]  # the last state, after the goal, is never decided
        expected = sorted(tuple(str(v) if isinstance(v, str) else int(v) for v in row)
                          for row in df.itertuples(index=False))  # fmt: skip
        assert sorted(live[name]) == expected, name
