"""The four actions shared by Relational-Grid-World and Box-World."""

from __future__ import annotations

from enum import IntEnum


class Action(IntEnum):
    """Discrete(4) actions; the value is the action index."""

    UP = 0
    RIGHT = 1
    DOWN = 2
    LEFT = 3


ACTION_NAMES: tuple[str, ...] = ("up", "right", "down", "left")
"""action index -> atom used in facts (step(E, T, Action, Reward))"""
