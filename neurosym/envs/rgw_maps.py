"""Relational-Grid-World text maps: the legend, the two shipped maps, and validation.

A map is a rectangle of one-character cells, one row per line; lines starting
with ``#`` and blank lines are ignored. Legend:

====== ==========================================================================
``A``  agent start (the cell itself is empty)
``.``  empty
``W``  wall
``M``  mountain (-0.1 on entering)
``P``  pit (-1, ends the episode)
``S``  sword
``E``  enemy
``T``  terminal (+10, ends the episode)
``O``  teleport end (exactly two per map, or none)
``Q``  teleport end that ``classic=True`` also treats as a mountain: the original
       release lists (3, 9) of Configuration-2 both as a teleport and a mountain
====== ==========================================================================

A map that cannot be played raises :class:`~neurosym.errors.MapError` naming the
row and column (0-based) of the first problem.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np

from neurosym.envs import rgw_rules as rules
from neurosym.errors import MapError

SYMBOLS: dict[str, int] = {
    ".": rules.EMPTY,
    "A": rules.EMPTY,
    "W": rules.WALL,
    "M": rules.MOUNTAIN,
    "P": rules.PIT,
    "S": rules.SWORD,
    "E": rules.ENEMY,
    "T": rules.TERMINAL,
    "O": rules.TELEPORT,
    "Q": rules.TELEPORT_MOUNTAIN,
}
"""map character -> internal cell code"""

SHIPPED = ("rgw1", "rgw2")
"""names of the maps in neurosym/envs/maps/"""

# Room for the removable objects' bits in the uint64 'removed' mask.
MAX_REMOVABLE = 64

MAX_MAP_BYTES = 1 << 20
"""largest map file read (a 1000 x 1000 map is under 1 MiB)"""


@dataclass(frozen=True, eq=False)
class GridMap:
    """A parsed, validated map: cell codes row-major and the agent's start cell."""

    name: str
    """shipped name, file name or "<string>" """
    height: int
    width: int
    cells: np.ndarray
    """(H * W,) uint8 internal cell codes (see rgw_rules), the agent's cell empty"""
    start: int
    """row-major index of the agent's start cell"""

    def text(self) -> str:
        """The map back as text (what :func:`parse_map` reads)."""
        chars = np.array([_CHAR_OF[c] for c in range(len(_CHAR_OF))])[self.cells]
        chars[self.start] = "A"
        return "\n".join("".join(row) for row in chars.reshape(self.height, self.width)) + "\n"


_CHAR_OF = [""] * (max(SYMBOLS.values()) + 1)
for _ch, _code in SYMBOLS.items():
    if _ch != "A":
        _CHAR_OF[_code] = _ch


def parse_map(text: str, name: str = "<string>") -> GridMap:
    """Parse and validate map text; raise MapError naming row and column of a problem."""
    rows = [line.rstrip("\r\n").rstrip() for line in text.splitlines()]
    rows = [r for r in rows if r and not r.lstrip().startswith("#")]
    if not rows:
        raise MapError(f"map {name}: no rows (expected lines of {''.join(SYMBOLS)})")
    width = len(rows[0])
    for r, row in enumerate(rows):
        if len(row) != width:
            raise MapError(f"map {name}: row {r} has {len(row)} cells, expected {width} like row 0")
        for c, ch in enumerate(row):
            if ch not in SYMBOLS:
                raise MapError(
                    f"map {name}: unknown symbol {ch!r} at row {r}, column {c}; "
                    f"expected one of {''.join(SYMBOLS)}"
                )
    height = len(rows)
    flat = "".join(rows)
    agents = [i for i, ch in enumerate(flat) if ch == "A"]
    if not agents:
        raise MapError(f"map {name}: no agent start 'A' in rows 0-{height - 1}; add exactly one")
    if len(agents) > 1:
        r, c = divmod(agents[1], width)
        raise MapError(f"map {name}: second agent start 'A' at row {r}, column {c}; expected one")
    if "T" not in flat:
        raise MapError(f"map {name}: no terminal 'T' in rows 0-{height - 1}; add at least one")
    teleports = [i for i, ch in enumerate(flat) if ch in "OQ"]
    if len(teleports) == 1:
        r, c = divmod(teleports[0], width)
        raise MapError(
            f"map {name}: one teleport end at row {r}, column {c}; teleports come in pairs"
        )
    if len(teleports) > 2:
        r, c = divmod(teleports[2], width)
        raise MapError(
            f"map {name}: third teleport end at row {r}, column {c}; at most one pair per map"
        )
    removable = [i for i, ch in enumerate(flat) if ch in "SE"]
    if len(removable) > MAX_REMOVABLE:
        r, c = divmod(removable[MAX_REMOVABLE], width)
        raise MapError(
            f"map {name}: more than {MAX_REMOVABLE} swords and enemies (row {r}, column {c})"
        )
    cells = np.array([SYMBOLS[ch] for ch in flat], dtype=np.uint8)
    return GridMap(name=name, height=height, width=width, cells=cells, start=agents[0])


def shipped_map_text(name: str) -> str:
    """Text of a map shipped in neurosym/envs/maps/ (``rgw1`` or ``rgw2``)."""
    return resources.files("neurosym.envs").joinpath("maps", f"{name}.txt").read_text()


def load_map(source: str | os.PathLike[str]) -> GridMap:
    """A map from a shipped name, a file path, or map text (anything with a newline)."""
    if isinstance(source, str) and source in SHIPPED:
        return parse_map(shipped_map_text(source), name=source)
    if isinstance(source, str) and ("\n" in source or "\r" in source):
        return parse_map(source)
    path = Path(source)
    if not path.is_file():
        raise MapError(
            f"map {str(source)!r}: not a shipped map ({', '.join(SHIPPED)}), "
            "not a file, and not map text (which has one line per row)"
        )
    return parse_map(read_map_file(path), name=path.name)


def read_map_file(path: Path) -> str:
    """The text of a map file, or a MapError naming it: unreadable, too large, not UTF-8."""
    try:
        size = path.stat().st_size
        if size > MAX_MAP_BYTES:
            raise MapError(
                f"map {str(path)!r}: {size:,} bytes, more than a map's {MAX_MAP_BYTES:,}; "
                "a map is lines of the legend's characters"
            )
        with path.open("rb") as fh:
            data = fh.read(MAX_MAP_BYTES + 1)
    except OSError as exc:
        raise MapError(f"map {str(path)!r}: cannot read it ({exc.strerror or exc})") from None
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise MapError(
            f"map {str(path)!r}: not UTF-8 text (byte 0x{data[exc.start]:02x} at offset "
            f"{exc.start}); a map is lines of {''.join(SYMBOLS)}"
        ) from None
