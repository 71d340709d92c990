"""Recording scripted routes through Relational-Grid-World Configuration-2.

A random agent seldom meets the sword or the enemy, so these tests drive the
recorder with an agent whose actions follow fixed plans (one per episode) while
a real model supplies the introspection. The routes give the events the rules
are about: sword before enemy, enemy without the sword, back for the sword, a
pit, a timeout. Other test files import :func:`scripted_recording`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cache
from typing import Any

import numpy as np
import pytest

from neurosym.envs import make
from neurosym.record.recorder import record
from neurosym.record.recording import Recording

U, R, D, L = 0, 1, 2, 3
TO_TELEPORT_WITHOUT_SWORD = [D] * 3 + [R] * 9  # (0,0) -> (3,8) -> teleport (3,9) -> (8,8)
SWORD_THEN_TELEPORT = [R] * 6 + [D] * 3 + [R] * 3  # sword at (0,6), then the teleport
PLANS: dict[str, list[int]] = {
    # sword, teleport, enemy beaten, terminal: the optimal route of Configuration-2
    "optimal": SWORD_THEN_TELEPORT + [D] + [L] * 8,
    # teleport, hurt by the enemy, terminal
    "no_sword": TO_TELEPORT_WITHOUT_SWORD + [D] + [L] * 8,
    # sword, teleport, pit
    "pit": SWORD_THEN_TELEPORT + [U],
    # teleport, hurt, back through the teleport for the sword, teleport, enemy beaten, terminal
    "back_for_sword": TO_TELEPORT_WITHOUT_SWORD
    + [D]
    + [L] * 7
    + [R] * 7
    + [U]
    + [L] * 3
    + [U] * 3
    + [D] * 3
    + [R] * 3
    + [D]
    + [L] * 8,
    # bumps into the top border until the time limit
    "timeout": [],
}
EXPECTED = {  # plan -> (outcome, key events in order)
    "optimal": (
        "terminal",
        ["picked(sword)", "teleported", "defeated(enemy)", "reached(terminal)"],
    ),
    "no_sword": ("terminal", ["teleported", "hurt_by(enemy)", "reached(terminal)"]),
    "pit": ("pit", ["picked(sword)", "teleported", "fell(pit)"]),
    "back_for_sword": (
        "terminal",
        [
            "teleported",
            "hurt_by(enemy)",
            "teleported",
            "picked(sword)",
            "teleported",
            "defeated(enemy)",
            "reached(terminal)",
        ],
    ),
    "timeout": ("timeout", []),
}
MAX_STEPS = 60


@dataclass
class ScriptedAgent:
    """Acts by plan (row i of the batch follows plans[i]); the wrapped agent's model introspects."""

    inner: Any
    plans: list[list[int]]
    step: int = field(default=0)

    @property
    def config(self) -> Any:
        return self.inner.config

    env_name = "rgw2"
    env_kwargs = {"max_steps": MAX_STEPS}  # noqa: RUF012
    path = "scripted.pt"

    def act(
        self, obs: np.ndarray, greedy: bool = True, introspect: bool = False, generator: Any = None
    ) -> Any:
        """The recorder passes only the sub-envs still playing: a plan's episode ends with its
        last action (the timeout plan's at MAX_STEPS), so the live plans at step k are known."""
        _, intro = self.inner.act(obs, greedy=True, introspect=introspect)
        k = self.step
        self.step += 1
        live = [p for p in self.plans if (k < len(p) if p else k < MAX_STEPS)]
        assert len(live) == len(obs), (
            f"step {k}: {len(obs)} observations, {len(live)} live episodes"
        )
        actions = np.array([p[k] if k < len(p) else U for p in live], dtype=np.int64)
        return actions, intro


@cache
def scripted_recording(module: str = "predinet") -> Recording:
    """One wave, episode i = plan i (in PLANS order), seed 0."""
    from test_recorder import small_agent

    agent = ScriptedAgent(small_agent("rgw2", module), list(PLANS.values()))
    return record(agent, "rgw2", episodes=len(PLANS), seed=0, batch=len(PLANS))


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


@dataclass
class ExplorerAgent:
    """Box-World: walks to the nearest object it can use (the env tests' scripted explorer).

    It reads the batched env's entity grid (set by :func:`explorer_recording`), so
    keys, boxes, distractors and gems all happen; a real model introspects.
    """

    inner: Any
    env_name: str
    venv: Any = None
    env_kwargs: dict = field(default_factory=lambda: {"max_steps": 80})
    path: str = "explorer.pt"

    @property
    def config(self) -> Any:
        return self.inner.config

    def act(
        self, obs: np.ndarray, greedy: bool = True, introspect: bool = False, generator: Any = None
    ) -> Any:
        from neurosym.envs.boxworld_entities import AGENT, HELD
        from neurosym.envs.boxworld_solver import nearest_interaction

        _, intro = self.inner.act(obs, greedy=True, introspect=introspect)
        grids = self.venv.entity_grid().reshape(self.venv.num_envs, -1)[~self.venv.idle]
        assert len(grids) == len(obs)
        actions = np.zeros(len(obs), dtype=np.int64)
        for i, grid in enumerate(grids):
            agent = int(np.flatnonzero(grid == AGENT)[0])
            held = int(grid[0]) - HELD if grid[0] >= HELD else -1
            step = nearest_interaction(grid, agent, held)
            actions[i] = U if step is None else step
        return actions, intro


class _Tracking:
    """A batched env that remembers which sub-envs ended their episode since the last reset
    (the recorder then stops passing their observations to the agent)."""

    def __init__(self, venv: Any) -> None:
        self.venv = venv
        self.idle = np.zeros(venv.num_envs, dtype=bool)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.venv, name)

    def reset(self, **kwargs: Any) -> Any:
        self.idle[:] = False
        return self.venv.reset(**kwargs)

    def step(self, actions: np.ndarray) -> Any:
        out = self.venv.step(actions)
        self.idle |= out[2] | out[3]
        return out


@cache
def explorer_recording(env: str = "bw2", episodes: int = 8) -> Recording:
    """Episodes of the explorer on ``env`` from seed 0, all in one wave."""
    from test_recorder import small_agent

    import neurosym.envs as envs

    agent = ExplorerAgent(small_agent(env), env)
    real = envs.make_batched

    def capture(*args: Any, **kwargs: Any) -> Any:
        agent.venv = _Tracking(real(*args, **kwargs))
        return agent.venv

    envs.make_batched = capture
    try:
        return record(agent, env, episodes=episodes, seed=0, batch=episodes)
    finally:
        envs.make_batched = real


def test_explorer_opens_boxes_and_meets_distractors() -> None:
    rec = explorer_recording()
    events = set(rec.events["event"])
    assert any(e.startswith("opened(lock(") for e in events)
    assert {"got(gem)", "hit(distractor)"} <= events
    assert set(rec.episodes["outcome"]) >= {"gem", "distractor"}
    assert rec.holding["item"].str.fullmatch(r"key\([a-z]+\)").all()
