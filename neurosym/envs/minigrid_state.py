"""What neurosym reads from a Farama Minigrid (or BabyAI) env's own grid, one state at a time.

A :class:`GridState` is one pass over the env's cells (row-major; Minigrid keeps
its grid as a flat list indexed ``y * width + x``, so row = y, col = x): the
cells' (type, colour, state) codes as Minigrid encodes them, the named objects
on the map with their ids, the doors' states, the agent's cell and direction,
what it carries and the mission. From it come the network's observation
(:func:`observation`), the entity grid (:func:`entity_codes`) and, from two
snapshots and the step between them, the step's events (:func:`events`).

Object ids follow Box-World's: ``key_yellow``, ``door_red``, ``door_red_2``
when a colour repeats (numbered in the order first seen: row-major after the
reset, then a box's content when it opens, then anything else that appears),
``goal``; an id stays with the Python object Minigrid moves around, so a key
keeps its id when picked up and dropped elsewhere.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

COLOURS: tuple[str, ...] = ("red", "green", "blue", "purple", "yellow", "grey")
"""Minigrid's colours in its own index order (``COLOR_TO_IDX``)"""

TYPES: tuple[str, ...] = (
    "unseen", "empty", "wall", "floor", "door", "key", "ball", "box", "goal", "lava", "agent",
)  # fmt: skip
"""Minigrid's object types in its own index order (``OBJECT_TO_IDX``)"""

COLOURED = ("key", "ball", "box", "door")
"""types named with their colour (``key(red)``); Minigrid's walls, floors, goals and lava are not"""

NAMED = ("key", "ball", "box", "door", "goal")
"""types that are objects (``object/2``, ``at/5``); walls, floor and lava are terrain"""

DOOR_STATES: tuple[str, ...] = ("open", "closed", "locked")
"""Minigrid's door states in its own index order (``STATE_TO_IDX``)"""

DIRECTIONS: tuple[str, ...] = ("east", "south", "west", "north")
"""``agent_dir`` 0..3: Minigrid's right (+x), down (+y), left, up"""

ACTION_NAMES: tuple[str, ...] = ("left", "right", "forward", "pickup", "drop", "toggle", "done")
"""Minigrid's ``Actions`` 0..6, the atoms of ``step/4``"""

ENTITY_NAMES: tuple[str, ...] = (
    "empty", "agent", "wall", "floor", "goal", "lava",
    *(f"{t}({c})" for t in COLOURED for c in COLOURS),
)  # fmt: skip
"""entity code -> name: the model's entity k is grid cell k and this names what is there"""

OUTCOMES = ("goal", "mission", "lava", "failure", "timeout")
"""how an episode ends: on the goal square, the mission done elsewhere (reward > 0), in lava,
any other termination (no reward: a dynamic obstacle hit, a wrong object), out of steps"""

# observation planes, in order
_OBJECT_PLANES = ("wall", "floor", "door", "key", "ball", "box", "goal", "lava", "agent")
_CARRY_TYPES = ("key", "ball", "box")
COLOUR_PLANE = len(_OBJECT_PLANES)
STATE_PLANE = COLOUR_PLANE + len(COLOURS)
DIRECTION_PLANE = STATE_PLANE + len(DOOR_STATES)
CARRY_PLANE = DIRECTION_PLANE + len(DIRECTIONS)
CARRY_COLOUR_PLANE = CARRY_PLANE + len(_CARRY_TYPES)
NUM_PLANES = CARRY_COLOUR_PLANE + len(COLOURS)
"""31 planes: 9 object types (agent last), 6 colours (keys, balls, boxes, doors), 3 door
states, 4 agent directions (at the agent's cell), then what the agent carries: 3 types and
6 colours, each a plane of ones over the whole grid (as RGW's sword-held plane)"""

_TYPE = {name: i for i, name in enumerate(TYPES)}
_PLANE_OF_TYPE = np.full(len(TYPES), -1, np.int64)
for _k, _name in enumerate(_OBJECT_PLANES[:-1]):
    _PLANE_OF_TYPE[_TYPE[_name]] = _k
_HAS_COLOUR = np.isin(np.arange(len(TYPES)), [_TYPE[t] for t in COLOURED])


def _entity_table() -> np.ndarray:
    """(type index, colour index) -> entity code."""
    table = np.zeros((len(TYPES), len(COLOURS)), np.int64)
    index = {name: i for i, name in enumerate(ENTITY_NAMES)}
    for t in ("wall", "floor", "goal", "lava"):
        table[_TYPE[t], :] = index[t]
    for t in COLOURED:
        for c, colour in enumerate(COLOURS):
            table[_TYPE[t], c] = index[f"{t}({colour})"]
    table[_TYPE["agent"], :] = index["agent"]
    return table


_ENTITY = _entity_table()


def name_of(obj: Any) -> str:
    """An object's entity name: ``key(red)``, ``goal``, ``wall``."""
    return f"{obj.type}({obj.color})" if obj.type in COLOURED else str(obj.type)


@dataclass
class GridState:
    """One state of a Minigrid env, read from its grid (see the module docstring)."""

    cells: np.ndarray
    """(H, W, 3) int64: Minigrid's (type, colour, state) of each cell, the agent not drawn"""
    objects: tuple[tuple[str, str, int, int], ...]
    """(id, type, row, col) of the agent (first) and every named object on the map"""
    doors: tuple[tuple[str, str], ...]
    """(id, state) of every door on the map"""
    agent: tuple[int, int]
    direction: int
    carrying: tuple[str, ...]
    """``("key(red)",)`` or ``()``"""
    carried_id: str | None
    mission: str

    @property
    def ids(self) -> set[str]:
        return {o[0] for o in self.objects}


class Namer:
    """Ids of one episode's objects, kept with the Python objects Minigrid moves around."""

    def __init__(self) -> None:
        self._ids: dict[int, tuple[Any, str]] = {}  # id(obj) -> (obj kept alive, its id)
        self._used: dict[str, int] = {}

    def __call__(self, obj: Any) -> str:
        known = self._ids.get(id(obj))
        if known is not None and known[0] is obj:
            return known[1]
        base = f"{obj.type}_{obj.color}" if obj.type in COLOURED else str(obj.type)
        count = self._used.get(base, 0) + 1
        self._used[base] = count
        name = base if count == 1 else f"{base}_{count}"
        self._ids[id(obj)] = (obj, name)
        return name


def snapshot(env: Any, namer: Namer) -> GridState:
    """Read the unwrapped Minigrid env ``env``'s state; ``namer`` gives its objects their ids."""
    grid = env.grid
    width, height = grid.width, grid.height
    cells = np.zeros((height * width, 3), np.int64)
    cells[:, 0] = _TYPE["empty"]
    objects: list[tuple[str, str, int, int]] = []
    doors: list[tuple[str, str]] = []
    for k, obj in enumerate(grid.grid):
        if obj is None:
            continue
        code = obj.encode()
        cells[k] = code
        if obj.type in NAMED:
            ident = namer(obj)
            objects.append((ident, name_of(obj), k // width, k % width))
            if obj.type == "door":
                doors.append((ident, DOOR_STATES[int(code[2])]))
    x, y = (int(v) for v in env.agent_pos)
    carried = env.carrying
    return GridState(
        cells=cells.reshape(height, width, 3),
        objects=(("agent", "agent", y, x), *objects),
        doors=tuple(doors),
        agent=(y, x),
        direction=int(env.agent_dir),
        carrying=(name_of(carried),) if carried is not None else (),
        carried_id=namer(carried) if carried is not None else None,
        mission=str(env.mission),
    )


def observation(snap: GridState, out: np.ndarray | None = None) -> np.ndarray:
    """(NUM_PLANES, H, W) uint8 0/1 planes of a snapshot (written into ``out`` when given).

    The agent's cell shows only the agent and its direction (what it stands on,
    an open door or the goal, is hidden under it, as in RGW).
    """
    cells = snap.cells
    types, colours, states = cells[..., 0], cells[..., 1], cells[..., 2]
    H, W = types.shape
    obs = np.zeros((NUM_PLANES, H, W), np.uint8) if out is None else out
    obs[:] = 0
    plane = _PLANE_OF_TYPE[types]
    rows, cols = np.nonzero(plane >= 0)
    obs[plane[rows, cols], rows, cols] = 1
    coloured = _HAS_COLOUR[types]
    rows, cols = np.nonzero(coloured)
    obs[COLOUR_PLANE + colours[rows, cols], rows, cols] = 1
    rows, cols = np.nonzero(types == _TYPE["door"])
    obs[STATE_PLANE + states[rows, cols], rows, cols] = 1
    r, c = snap.agent
    obs[:, r, c] = 0
    obs[len(_OBJECT_PLANES) - 1, r, c] = 1
    obs[DIRECTION_PLANE + snap.direction, r, c] = 1
    if snap.carrying:
        kind, _, colour = snap.carrying[0].partition("(")
        if kind in _CARRY_TYPES:
            obs[CARRY_PLANE + _CARRY_TYPES.index(kind)] = 1
        obs[CARRY_COLOUR_PLANE + COLOURS.index(colour.rstrip(")"))] = 1
    return obs


def entity_codes(snap: GridState) -> np.ndarray:
    """(H, W) int64 entity codes (names in :data:`ENTITY_NAMES`); the agent's cell is ``agent``."""
    codes = _ENTITY[snap.cells[..., 0], snap.cells[..., 1]]
    codes[snap.agent] = ENTITY_NAMES.index("agent")
    return codes


def events(
    before: GridState, after: GridState, action: int, reward: float, terminated: bool
) -> tuple[str, ...]:
    """The events of the step from ``before`` to ``after``, in this order.

    ``bumped(What)`` (forward did not move the agent: What is the entity ahead),
    ``picked(X)``, ``dropped(X)``, ``unlocked(door(C))`` then ``opened(door(C))``
    (a locked door opens at once when unlocked), ``opened(door(C))``,
    ``closed(door(C))``, ``opened(box(C))`` (a box toggled: it gives way to its
    content), ``reached(goal)``, ``fell(lava)``, ``achieved(mission)`` (the
    episode ended with a reward: the env's mission is done).
    """
    out: list[str] = []
    if ACTION_NAMES[action] == "forward" and after.agent == before.agent:
        dr, dc = _AHEAD[before.direction]
        r, c = before.agent[0] + dr, before.agent[1] + dc
        if 0 <= r < before.cells.shape[0] and 0 <= c < before.cells.shape[1]:
            code = int(_ENTITY[before.cells[r, c, 0], before.cells[r, c, 1]])
            if ENTITY_NAMES[code] != "empty":
                out.append(f"bumped({ENTITY_NAMES[code]})")
    if before.carried_id != after.carried_id:
        if before.carrying:
            out.append(f"dropped({before.carrying[0]})")
        if after.carrying:
            out.append(f"picked({after.carrying[0]})")
    was = dict(before.doors)
    types = {o[0]: o[1] for o in before.objects}
    for ident, state in after.doors:
        old = was.get(ident)
        if old == state or old is None:
            continue
        door = types[ident]
        if old == "locked":
            out.append(f"unlocked({door})")
        out.append(f"{'opened' if state == 'open' else 'closed'}({door})")
    gone = before.ids - after.ids - ({after.carried_id} if after.carried_id else set())
    out += [f"opened({types[i]})" for i in sorted(gone) if types[i].startswith("box(")]
    if terminated:
        under = TYPES[int(after.cells[after.agent][0])]
        if under == "goal":
            out.append("reached(goal)")
        elif under == "lava":
            out.append("fell(lava)")
        if reward > 0:
            out.append("achieved(mission)")
    return tuple(out)


_AHEAD = ((0, 1), (1, 0), (0, -1), (-1, 0))
"""(drow, dcol) of each direction"""


def outcome(after: GridState, reward: float, terminated: bool, truncated: bool) -> str | None:
    """The episode's outcome (:data:`OUTCOMES`) on the step that ends it, else None."""
    if terminated:
        under = TYPES[int(after.cells[after.agent][0])]
        if under == "goal":
            return "goal"
        if under == "lava":
            return "lava"
        return "mission" if reward > 0 else "failure"
    return "timeout" if truncated else None
