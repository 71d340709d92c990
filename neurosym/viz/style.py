"""Colours and short labels for the entities of Relational-Grid-World, Box-World and Minigrid.

A grid cell is too small for a full name, so every entity gets a label of one
or two characters and the figure carries a legend line spelling them out.
Box-World's keys, locks and held keys take the colour in their name
(``key(red)``); a colour matplotlib does not know gets a fixed palette entry
chosen from a digest of its name, so the same name always looks the same.
"""

from __future__ import annotations

import functools
import hashlib
import re
from collections.abc import Callable, Iterable
from typing import ParamSpec, TypeVar

import matplotlib
from matplotlib import colors as mcolors

_P = ParamSpec("_P")
_R = TypeVar("_R")


def data_as_text(draw: Callable[_P, _R]) -> Callable[_P, _R]:
    """Run a figure builder with matplotlib's mathtext off, so that names from files (a
    checkpoint, an entity, a predicate) are drawn as written: ``$\\alpha$`` in a file name
    would be a Greek letter and ``$\\frac$`` a parse error. Labels of our own that are
    mathtext ask for it (``parse_math=True``)."""

    @functools.wraps(draw)
    def run(*args: _P.args, **kwargs: _P.kwargs) -> _R:
        with matplotlib.rc_context({"text.parse_math": False}):
            return draw(*args, **kwargs)

    return run


HEAD_COLOURS = (
    "#e6194b",
    "#3cb44b",
    "#4363d8",
    "#f58231",
    "#911eb4",
    "#42d4f4",
    "#f032e6",
    "#9a6324",
)
"""one colour per head (arrows, histogram lines); repeats past eight heads"""

ENTITY_COLOURS: dict[str, str] = {
    "agent": "#1f77b4",
    "sword": "#e6b800",
    "enemy": "#d62728",
    "terminal": "#2ca02c",
    "teleport": "#9467bd",
    "wall": "#7f7f7f",
    "mountain": "#b08d57",
    "pit": "#1a1a1a",
    "empty": "#f4f4f4",
    "gem": "#ffffff",
    "goal": "#2ca02c",  # Minigrid
    "lava": "#ff7f0e",
    "floor": "#e6e6e6",
}

ENTITY_LABELS: dict[str, str] = {
    "agent": "A",
    "sword": "S",
    "enemy": "E",
    "terminal": "T",
    "teleport": "O",
    "wall": "W",
    "mountain": "M",
    "pit": "P",
    "empty": "",
    "gem": "G",
    "key": "k",
    "lock": "L",
    "held": "h",
    "door": "D",  # Minigrid: door(C), ball(C), box(C) take their colour as keys do
    "ball": "b",
    "box": "x",
    "goal": "G",
    "lava": "~",
    "floor": "f",
}

_COLOURED = re.compile(r"^(key|lock|held|door|ball|box)\((.+)\)$")
_FALLBACK_PALETTE = (
    "#e6194b",
    "#3cb44b",
    "#ffe119",
    "#4363d8",
    "#f58231",
    "#911eb4",
    "#42d4f4",
    "#f032e6",
    "#bfef45",
    "#fabed4",
    "#469990",
    "#dcbeff",
    "#9a6324",
    "#fffac8",
    "#800000",
    "#aaffc3",
    "#808000",
    "#ffd8b1",
)


def head_colour(head_index: int) -> str:
    """Colour of the head at position ``head_index`` (0-based) in the model."""
    return HEAD_COLOURS[head_index % len(HEAD_COLOURS)]


def split_entity(name: str) -> tuple[str, str | None]:
    """``key(red)`` -> ``("key", "red")``; ``wall`` -> ``("wall", None)``."""
    match = _COLOURED.match(name)
    if match:
        return match.group(1), match.group(2).strip("'")
    return name, None


def colour_of(colour_name: str) -> str:
    """A matplotlib colour for a Box-World colour name, stable across runs."""
    if mcolors.is_color_like(colour_name):
        return mcolors.to_hex(colour_name)
    digest = hashlib.sha256(colour_name.encode()).digest()
    return _FALLBACK_PALETTE[digest[0] % len(_FALLBACK_PALETTE)]


def entity_colour(name: str) -> str:
    """Fill colour of a cell holding ``name``."""
    kind, colour = split_entity(name)
    if colour is not None:
        return colour_of(colour)
    return ENTITY_COLOURS.get(kind, "#cccccc")


def entity_label(name: str) -> str:
    """The one- or two-character label drawn in a cell holding ``name`` ('' for empty)."""
    kind, _ = split_entity(name)
    if kind in ENTITY_LABELS:
        return ENTITY_LABELS[kind]
    return kind[:2]


def text_colour_on(fill: str) -> str:
    """Black or white, whichever reads better on ``fill``."""
    r, g, b = mcolors.to_rgb(fill)
    return "black" if 0.299 * r + 0.587 * g + 0.114 * b > 0.5 else "white"


def legend_text(names: Iterable[str]) -> str:
    """One line spelling out the labels of the entities present, e.g. ``A agent · S sword``."""
    seen: dict[str, str] = {}
    for name in sorted(set(names), key=_legend_order):
        kind, _ = split_entity(name)
        label = entity_label(name)
        if label and label not in seen:
            seen[label] = f"{kind}(C)" if kind in ("key", "lock", "held") else kind
    return "   ".join(f"{label} {kind}" for label, kind in seen.items())


def _legend_order(name: str) -> tuple[int, str]:
    kind, _ = split_entity(name)
    order = list(ENTITY_LABELS)
    return (order.index(kind) if kind in order else len(order), name)
