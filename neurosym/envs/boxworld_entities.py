"""Box-World's vocabulary: colours, entity codes, their names and their RGB values.

One table serves the rules (codes in the state grid), the observation (RGB per
code), the entity grid the recorder names attention targets with, and the
Prolog text of events and held items. Colour names are plain lower-case atoms
so that ``key(red)`` is valid Prolog without quoting.

Codes::

    0 empty   1 wall   2 agent   3 gem
    KEY  + c  key(C)    a loose key, or the content of a box (left of its lock)
    LOCK + c  lock(C)   a box's lock
    HELD + c  held(C)   the held key, drawn in the top-left border cell
"""

from __future__ import annotations

import numpy as np

from neurosym.terms import Term

# Twenty colours that stay apart from each other and from the agent (dark
# grey), the gem (white), the background (light grey) and the wall (black).
COLOURS: tuple[tuple[str, tuple[int, int, int]], ...] = (
    ("red", (230, 25, 75)),
    ("green", (60, 180, 75)),
    ("yellow", (255, 225, 25)),
    ("blue", (0, 130, 200)),
    ("orange", (245, 130, 48)),
    ("purple", (145, 30, 180)),
    ("cyan", (70, 240, 240)),
    ("magenta", (240, 50, 230)),
    ("lime", (210, 245, 60)),
    ("pink", (250, 190, 212)),
    ("teal", (0, 128, 128)),
    ("lavender", (220, 190, 255)),
    ("brown", (170, 110, 40)),
    ("maroon", (128, 0, 0)),
    ("mint", (170, 255, 195)),
    ("olive", (128, 128, 0)),
    ("apricot", (255, 215, 180)),
    ("navy", (0, 0, 128)),
    ("indigo", (75, 0, 130)),
    ("sky", (135, 206, 250)),
)
COLOUR_NAMES: tuple[str, ...] = tuple(name for name, _ in COLOURS)
NUM_COLOURS = len(COLOURS)
COLOUR_INDEX: dict[str, int] = {name: i for i, name in enumerate(COLOUR_NAMES)}

EMPTY, WALL, AGENT, GEM = 0, 1, 2, 3
KEY = 4
LOCK = KEY + NUM_COLOURS
HELD = LOCK + NUM_COLOURS
NUM_CODES = HELD + NUM_COLOURS

BACKGROUND_RGB = (204, 204, 204)
WALL_RGB = (0, 0, 0)
AGENT_RGB = (96, 96, 96)
GEM_RGB = (255, 255, 255)

ENTITY_NAMES: tuple[str, ...] = (
    "empty",
    "wall",
    "agent",
    "gem",
    *(str(Term("key", (c,))) for c in COLOUR_NAMES),
    *(str(Term("lock", (c,))) for c in COLOUR_NAMES),
    *(str(Term("held", (c,))) for c in COLOUR_NAMES),
)
assert len(ENTITY_NAMES) == NUM_CODES


def _palette() -> np.ndarray:
    colours = np.array([rgb for _, rgb in COLOURS], dtype=np.uint8)
    fixed = np.array([BACKGROUND_RGB, WALL_RGB, AGENT_RGB, GEM_RGB], dtype=np.uint8)
    return np.concatenate([fixed, colours, colours, colours])


PALETTE: np.ndarray = _palette()
"""(NUM_CODES, 3) uint8: the RGB value of each code in the observation."""
PALETTE.setflags(write=False)

TYPE_PLANES: tuple[str, ...] = ("wall", "agent", "gem", "key", "lock", "held")
"""The object-type planes of the one-hot observation, then one plane per colour."""
NUM_PLANES = len(TYPE_PLANES) + NUM_COLOURS


def _onehot_table() -> np.ndarray:
    table = np.zeros((NUM_CODES, NUM_PLANES), np.uint8)
    table[WALL, 0] = table[AGENT, 1] = table[GEM, 2] = 1
    for c in range(NUM_COLOURS):
        for plane, base in ((3, KEY), (4, LOCK), (5, HELD)):
            table[base + c, plane] = 1
            table[base + c, len(TYPE_PLANES) + c] = 1
    return table


ONEHOT: np.ndarray = _onehot_table()
"""(NUM_CODES, NUM_PLANES) uint8: the planes set for each code (empty sets none). A key and its
lock share their colour plane and differ in their type plane, so "same colour" is one
channel for the network instead of a match of three RGB values."""
ONEHOT.setflags(write=False)

# Prolog text used in info dicts, built once (decoding runs every step).
KEY_TEXT: tuple[str, ...] = ENTITY_NAMES[KEY:LOCK]
LOCK_TEXT: tuple[str, ...] = ENTITY_NAMES[LOCK:HELD]
GOT_KEY_TEXT: tuple[str, ...] = tuple(str(Term("got", (Term("key", (c,)),))) for c in COLOUR_NAMES)
OPENED_TEXT: tuple[str, ...] = tuple(
    str(Term("opened", (Term("lock", (c,)),))) for c in COLOUR_NAMES
)
GOT_GEM_TEXT = str(Term("got", ("gem",)))
HIT_DISTRACTOR_TEXT = str(Term("hit", ("distractor",)))

OUTCOMES: tuple[str | None, ...] = (None, "gem", "distractor", "timeout")
"""Outcome codes in batched info: 0 none, 1 gem, 2 distractor, 3 timeout."""
OUTCOME_NONE, OUTCOME_GEM, OUTCOME_DISTRACTOR, OUTCOME_TIMEOUT = range(4)

GOT_GEM = NUM_COLOURS
"""Value of the batched ``event_got`` field when the content handed over is the gem."""


def object_id(entity: str) -> str:
    """The base id of an object of type ``entity``: ``key(red)`` -> ``key_red``, ``gem`` -> ``gem``."""
    return entity.replace("(", "_").replace(")", "")
