"""A scripted Minigrid DoorKey episode, recorded: the key picked up, the door unlocked, the goal
(for the tests that draw a Minigrid level: plots and the report page)."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np
from builders import small_agent

from neurosym.record.recorder import record
from neurosym.record.recording import Recording

DOORKEY = "MiniGrid-DoorKey-5x5-v0"
LEFT, RIGHT, FORWARD, PICKUP, DROP, TOGGLE = range(6)
SCRIPT = [FORWARD, PICKUP, LEFT, FORWARD, TOGGLE, FORWARD, FORWARD, RIGHT, FORWARD]
"""seed 1: bump into the key, pick it up, turn east, bump into the door, unlock it, the goal"""
DOOR = (2, 2)
"""the door's cell (row, col); the agent faces it, locked, in state 4 and open in state 5"""


@dataclass
class Scripted:
    """Plays SCRIPT whatever it sees; the wrapped small agent introspects every state."""

    inner: Any
    step: int = 0
    env_name: str = DOORKEY
    env_kwargs: dict | None = None
    path: str = "scripted.pt"

    @property
    def config(self) -> Any:
        return self.inner.config

    def act(self, obs: np.ndarray, greedy: bool = True, introspect: bool = False,
            generator: Any = None) -> Any:  # fmt: skip
        _, intro = self.inner.act(obs, greedy=True, introspect=introspect)
        self.step += 1
        return np.full(len(obs), SCRIPT[self.step - 1], dtype=np.int64), intro


def scripted_agent() -> Scripted:
    return Scripted(small_agent(DOORKEY))


@cache
def doorkey_recording() -> Recording:
    """The scripted episode (seed 1) as the recorder keeps it."""
    return record(scripted_agent(), DOORKEY, episodes=1, seed=1, batch=1)
