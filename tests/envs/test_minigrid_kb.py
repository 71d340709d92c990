"""Minigrid through the toolkit: a scripted DoorKey recording's facts, the KB round trip
through SWI-Prolog with rules/minigrid.pl, and `neurosym extract` on an untrained agent."""

from __future__ import annotations

import subprocess
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import torch

from neurosym.facts.tables import extract_facts
from neurosym.record.recorder import record
from neurosym.record.recording import Recording

DOORKEY = "MiniGrid-DoorKey-5x5-v0"
LEFT, RIGHT, FORWARD, PICKUP, DROP, TOGGLE, DONE = range(7)
SCRIPT = [FORWARD, PICKUP, LEFT, FORWARD, TOGGLE, FORWARD, FORWARD, RIGHT, FORWARD]
"""episode 0 (seed 1): bump into the key, pick it up, bump into the door, unlock it, the goal"""
MAX_STEPS = 12
RULES = Path(__file__).resolve().parents[2] / "rules" / "minigrid.pl"
MISSION = "use the key to open the door and then get to the goal"


@dataclass
class ScriptedAgent:
    """Row i of the batch follows plans[i] (an empty plan turns left until the time limit);
    the wrapped small agent's model introspects every state."""

    inner: Any
    plans: list[list[int]]
    step: int = field(default=0)
    env_name: str = DOORKEY
    env_kwargs: dict = field(default_factory=lambda: {"max_steps": MAX_STEPS})
    path: str = "scripted.pt"

    @property
    def config(self) -> Any:
        return self.inner.config

    def act(
        self, obs: np.ndarray, greedy: bool = True, introspect: bool = False, generator: Any = None
    ) -> Any:
        _, intro = self.inner.act(obs, greedy=True, introspect=introspect)
        k = self.step
        self.step += 1
        live = [p for p in self.plans if (k < len(p) if p else k < MAX_STEPS)]
        assert len(live) == len(obs)
        return np.array([p[k] if p else LEFT for p in live], dtype=np.int64), intro


@pytest.fixture(scope="module")
def scripted(small_agent) -> Recording:
    """Episode 0 (seed 1) along SCRIPT, episode 1 (seed 2) turning left until the time limit."""
    agent = ScriptedAgent(small_agent(DOORKEY), [SCRIPT, []])
    return record(agent, DOORKEY, episodes=2, seed=1, batch=2)


def test_scripted_recording_tables(scripted: Recording) -> None:
    rec = scripted
    assert rec.episodes[["episode", "steps", "outcome", "seed"]].values.tolist() == [
        [0, 9, "goal", 1],
        [1, MAX_STEPS, "timeout", 2],
    ]
    ev = rec.events
    assert ev[ev.episode == 0][["t", "event"]].values.tolist() == [
        [0, "bumped(key(yellow))"],
        [1, "picked(key(yellow))"],
        [3, "bumped(door(yellow))"],
        [4, "unlocked(door(yellow))"],
        [4, "opened(door(yellow))"],
        [8, "reached(goal)"],
        [8, "achieved(mission)"],
    ]
    assert rec.steps[rec.steps.episode == 0]["action"].tolist() == [
        "forward", "pickup", "left", "forward", "toggle", "forward", "forward", "right", "forward",
    ]  # fmt: skip
    facing = rec.facing[rec.facing.episode == 0]["direction"].tolist()
    assert facing == ["south"] * 3 + ["east"] * 5 + ["south"] * 2  # states 0..9
    doors = rec.doors[rec.doors.episode == 0]
    assert doors["state"].tolist() == ["locked"] * 5 + ["open"] * 5
    assert set(doors["id"]) == {"door_yellow"}
    assert rec.missions.values.tolist() == [[0, MISSION], [1, MISSION]]
    held = rec.holding[rec.holding.episode == 0]
    assert held["t"].tolist() == list(range(2, 10)) and set(held["item"]) == {"key(yellow)"}


@pytest.fixture(scope="module")
def kb_path(tmp_path_factory: pytest.TempPathFactory, scripted: Recording) -> Path:
    path = tmp_path_factory.mktemp("minigrid") / "kb.pl"
    extract_facts(scripted).to_prolog(path)
    return path


def test_kb_round_trip_through_swi_prolog(kb_path: Path) -> None:
    from neurosym.prolog.knowledge_base import KnowledgeBase

    with KnowledgeBase(kb_path, rules=[str(RULES)]) as kb:

        def rows(goal: str, *names: str) -> list[Any]:
            text = ", ".join(f"format(atom(T{n}), '~q', [{n}])" for n in names)
            return [tuple(str(r[f"T{n}"]) for n in names) for r in kb.query(f"{goal}, {text}")]

        assert rows("event(0, T, X)", "T", "X") == [
            ("0", "bumped(key(yellow))"),
            ("1", "picked(key(yellow))"),
            ("3", "bumped(door(yellow))"),
            ("4", "unlocked(door(yellow))"),
            ("4", "opened(door(yellow))"),
            ("8", "reached(goal)"),
            ("8", "achieved(mission)"),
        ]
        assert rows("object(I, Ty)", "I", "Ty") == [
            ("agent", "agent"),
            ("door_yellow", "door(yellow)"),
            ("goal", "goal"),
            ("key_yellow", "key(yellow)"),
        ]
        assert rows("at(0, 9, I, R, C)", "I", "R", "C") == [
            ("agent", "3", "3"),
            ("door_yellow", "2", "2"),
            ("goal", "3", "3"),
        ]
        assert rows("facing(0, 4, D), door_state(0, 4, I, S)", "D", "I", "S") == [
            ("east", "door_yellow", "locked")
        ]
        assert rows("door_state(0, 5, I, S)", "I", "S") == [("door_yellow", "open")]
        assert rows("mission(E, M)", "E", "M") == [("0", f"'{MISSION}'"), ("1", f"'{MISSION}'")]
        assert rows("episode(E, S, _, O)", "E", "S", "O") == [
            ("0", "9", "goal"),
            ("1", "12", "timeout"),
        ]
        # rules/minigrid.pl over the written facts
        assert rows("key_before_door(E)", "E") == [("0",)]
        assert rows("key_before_door(E, C)", "E", "C") == [("0", "yellow")]
        assert rows("unlocked_with_key(E, T, D)", "E", "T", "D") == [("0", "4", "door(yellow)")]
        assert rows("opens(K, D)", "K", "D") == [("key(yellow)", "door(yellow)")]
        assert rows("mission_done(E)", "E") == [("0",)]
        assert rows("mission_shown(E)", "E") == []  # DoorKey's mission is no BabyAI instruction


def test_kb_loads_in_plain_swipl(kb_path: Path, swipl: Path) -> None:
    goal = (
        "consult(KB), consult(Rules), findall(E, key_before_door(E), Es), "
        "findall(M, mission(_, M), Ms), length(Ms, N), print(Es-N), nl"
    )
    proc = subprocess.run(
        [str(swipl), "--on-error=status", "-g", f"KB = '{kb_path}', Rules = '{RULES}', {goal}",
         "-t", "halt"],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "[0]-2"
    assert "Warning" not in proc.stderr


def test_extract_cli_on_an_untrained_agent(tmp_path: Path, neurosym_main, swipl: Path) -> None:
    from neurosym.agent.checkpoint import save_checkpoint
    from neurosym.agent.config import ModelConfig
    from neurosym.agent.networks.model import ActorCritic
    from neurosym.envs.minigrid_state import NUM_PLANES

    config = ModelConfig.for_family(
        "minigrid", "predinet", (NUM_PLANES, 5, 5), heads=2, relations=3, key_size=8,
        conv_channels=(4, 8), hidden_sizes=(16,),
    )  # fmt: skip
    torch.manual_seed(0)
    ckpt = tmp_path / "untrained.pt"
    save_checkpoint(ckpt, model=ActorCritic(config), config=config, env_name=DOORKEY,
                    env_kwargs={"max_steps": 20})  # fmt: skip
    out = tmp_path / "out"
    proc = neurosym_main("extract", "--checkpoint", ckpt, "--env", DOORKEY, "--episodes", "2",
                         "--out", out)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "rules/minigrid.pl" in proc.stdout and "key before door" in proc.stdout
    goal = (
        f"consult('{out / 'kb.pl'}'), kb_meta(env, Env), aggregate_all(count, facing(_, _, _), F), "
        "aggregate_all(count, step(_, _, _, _), S), print(Env-F-S), nl"
    )
    run = subprocess.run([str(swipl), "--on-error=status", "-g", goal, "-t", "halt"],
                         capture_output=True, text=True, timeout=120)  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == f"'{DOORKEY}'-42-40"  # 2 episodes of 20 steps: 21 states each


def test_a_minigrid_agent_on_another_family_or_size_is_one_line(
    tmp_path: Path, neurosym_main
) -> None:
    from neurosym.agent.checkpoint import save_checkpoint
    from neurosym.agent.config import ModelConfig
    from neurosym.agent.networks.model import ActorCritic
    from neurosym.envs.minigrid_state import NUM_PLANES

    config = ModelConfig.for_family(
        "minigrid", "mhdpa", (NUM_PLANES, 5, 5), heads=1, key_size=4, value_size=4,
        conv_channels=(4,), hidden_sizes=(8,),
    )  # fmt: skip
    ckpt = tmp_path / "mg.pt"
    save_checkpoint(ckpt, model=ActorCritic(config), config=config, env_name=DOORKEY)
    trained = f"{ckpt} was trained on {DOORKEY}"
    for env, message in (
        ("rgw2", f"{trained} (minigrid family, observations ({NUM_PLANES}, 5, 5)); rgw2 is a rgw "
                 "environment: pick one of the MiniGrid-* and BabyAI-* ids (`neurosym envs` "
                 "lists them)"),
        ("MiniGrid-DoorKey-6x6-v0", f"{trained} with observations ({NUM_PLANES}, 5, 5); "
                                    f"MiniGrid-DoorKey-6x6-v0 gives ({NUM_PLANES}, 6, 6): pick an "
                                    "environment of the same shape"),
    ):  # fmt: skip
        proc = neurosym_main("extract", "--checkpoint", ckpt, "--env", env, "--out", tmp_path / "x")
        assert proc.returncode != 0
        assert proc.stderr.strip().splitlines() == [f"neurosym extract: error: {message}"]
