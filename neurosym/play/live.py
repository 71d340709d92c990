"""The facts of a live state, under the KB schema of docs/design.md.

What ``neurosym extract`` writes for a recorded state, :mod:`neurosym.play`
writes for the state being played: for episode E and state T

* per episode (after reset): ``object(Id, Type)`` for the map's objects,
  ``terrain(E, Type, Row, Col)`` for every non-empty cell of the entity grid
  that holds no object and is not the agent, ``grid(E, Rows, Cols)``;
* per state: ``at(E, T, Id, Row, Col)`` for the agent and every object still
  on the map, ``holding(E, T, Item)``; Minigrid's ``facing(E, T, Dir)`` and
  ``door_state(E, T, Id, State)`` (:func:`minigrid_rows`);
* per step: ``step(E, T, Action, Reward)`` and ``event(E, T, Event)`` for
  the transition from T to T + 1.

The recorder (:mod:`neurosym.record.recorder`) builds a recording's world tables
with these same functions. The rows come from the env's decoded info (``decode_info``, the same dicts
the recorder reads) and its entity grid, as plain Python values: ids and
names as text, entity and event texts as :class:`~neurosym.terms.Term` once
parsed (:func:`encode` turns them into what the Prolog side rebuilds).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from neurosym.terms import Term, parse_term

NOT_TERRAIN = ("empty", "agent")
"""entity names that are never terrain"""


@lru_cache(maxsize=4096)
def encode(text: str) -> Any:
    """Prolog text of a ground term -> the janus value neurosym_play rebuilds it from."""
    return _encode(parse_term(text))


def _encode(value: Any) -> Any:
    if isinstance(value, Term):
        if not value.args:
            return value.functor
        return ("$t", value.functor, [_encode(a) for a in value.args])
    if isinstance(value, tuple):
        return [_encode(v) for v in value]
    return value


@dataclass(frozen=True)
class EpisodeFacts:
    """object/2 rows (id, type text), terrain/4 rows (type, row, col) and the grid's size."""

    objects: tuple[tuple[str, str], ...]
    terrain: tuple[tuple[str, int, int], ...]
    rows: int
    cols: int


def episode_facts(info: dict[str, Any], grid: np.ndarray, names: Sequence[str]) -> EpisodeFacts:
    """The per-episode facts from the state after reset: its decoded info and entity grid (H, W)."""
    objects = tuple((str(i), str(t)) for i, t, _, _ in info["objects"])
    taken = {(int(r), int(c)) for _, _, r, c in info["objects"]}
    taken.add(tuple(int(v) for v in info["agent"]))
    rows, cols = grid.shape
    terrain = []
    for r, c in zip(*np.nonzero(~np.isin(grid, _codes(names, NOT_TERRAIN))), strict=True):
        if (int(r), int(c)) not in taken:
            terrain.append((str(names[int(grid[r, c])]), int(r), int(c)))
    return EpisodeFacts(objects, tuple(terrain), int(rows), int(cols))


def _codes(names: Sequence[str], wanted: Sequence[str]) -> list[int]:
    return [i for i, n in enumerate(names) if n in wanted]


def state_objects(info: dict[str, Any]) -> tuple[tuple[Any, ...], ...]:
    """(id, type, row, col) of the agent and every object on the map in a decoded info, the
    agent first (the envs list it first; be sure), values as the env gave them."""
    objects = tuple(info["objects"])
    if not objects or objects[0][0] != "agent":
        objects = (("agent", "agent", *info["agent"]), *objects)
    return objects


def state_rows(info: dict[str, Any]) -> tuple[list[tuple[str, int, int]], list[str]]:
    """at/5 rows (id, row, col), agent first, and holding/3 items of a decoded info."""
    ats = [(str(i), int(r), int(c)) for i, _, r, c in state_objects(info)]
    return ats, [str(h) for h in info["holding"]]


def minigrid_rows(info: dict[str, Any]) -> tuple[str, list[tuple[str, str]]] | None:
    """facing/3's direction and door_state/4's (id, state) rows of a decoded info; None for an
    env without a direction (RGW, Box-World)."""
    if "direction" not in info:
        return None
    return str(info["direction"]), [(str(i), str(s)) for i, s in info["doors"]]
