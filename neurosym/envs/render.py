"""Drawing grid worlds with numpy: pixel-art tiles for ``rgb_array``, coloured text for ``ansi``.

Nothing is read from image files. A tile is a small bitmap written as strings
(one character per pixel, each character mapped to a colour) and scaled up;
a frame is one fancy-indexing gather of tiles by cell code. Box-World can use
:func:`draw_tiles` with solid tiles (:func:`solid_tiles`) and :func:`ansi_grid`.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache

import numpy as np

from neurosym.envs.rgw_rules import ENTITY_NAMES

RGB = tuple[int, int, int]


def glyph_tile(rows: Sequence[str], palette: dict[str, RGB], scale: int = 3) -> np.ndarray:
    """A (h * scale, w * scale, 3) uint8 tile from a bitmap of palette characters."""
    lut = np.zeros((128, 3), dtype=np.uint8)
    for ch, colour in palette.items():
        lut[ord(ch)] = colour
    codes = np.array([[ord(ch) for ch in row] for row in rows], dtype=np.intp)
    tile = lut[codes]  # (h, w, 3)
    return np.repeat(np.repeat(tile, scale, axis=0), scale, axis=1)


def solid_tiles(colours: Sequence[RGB], size: int = 24) -> np.ndarray:
    """(K, size, size, 3) uint8 tiles of one colour each."""
    arr = np.asarray(colours, dtype=np.uint8)[:, None, None, :]
    return np.broadcast_to(arr, (len(colours), size, size, 3)).copy()


def draw_tiles(codes: np.ndarray, tiles: np.ndarray, line: RGB | None = (90, 90, 90)) -> np.ndarray:
    """(H * t, W * t, 3) uint8 frame: ``tiles[codes]`` laid out on a grid, with thin lines."""
    H, W = codes.shape
    t = tiles.shape[1]
    frame = tiles[codes].transpose(0, 2, 1, 3, 4).reshape(H * t, W * t, 3)  # (H, t, W, t, 3)
    if line is not None:
        frame = frame.copy()
        frame[::t, :, :] = line
        frame[:, ::t, :] = line
    return frame


def ansi_grid(codes: np.ndarray, chars: Sequence[str], colours: Sequence[int | None]) -> str:
    """Text of a grid, one character per cell, coloured with ANSI foreground codes."""
    cells = [
        ch if col is None else f"\x1b[{col}m{ch}\x1b[0m"
        for ch, col in zip(chars, colours, strict=True)
    ]
    return "\n".join("".join(cells[c] for c in row) for row in np.asarray(codes).tolist())


# -- Relational-Grid-World tiles ------------------------------------------------

_FLOOR: RGB = (236, 234, 222)
_RGW_GLYPHS: dict[str, tuple[tuple[str, ...], dict[str, RGB]]] = {
    "agent": (
        (
            "..####..",
            ".######.",
            "##.##.##",
            "########",
            "########",
            "#.####.#",
            ".##..##.",
            "..####..",
        ),
        {".": _FLOOR, "#": (40, 90, 200)},
    ),
    "sword": (
        (
            "......##",
            ".....###",
            "....###.",
            "+..###..",
            ".+###...",
            "..++....",
            ".+..+...",
            "+.......",
        ),
        {".": _FLOOR, "#": (140, 145, 160), "+": (130, 80, 30)},
    ),
    "enemy": (
        (
            ".#....#.",
            "..####..",
            ".######.",
            "##.##.##",
            "########",
            ".#.##.#.",
            ".######.",
            "#.#..#.#",
        ),
        {".": _FLOOR, "#": (200, 40, 40)},
    ),
    "terminal": (
        (
            ".+......",
            ".+####..",
            ".+######",
            ".+####..",
            ".+......",
            ".+......",
            ".+......",
            "+++.....",
        ),
        {".": _FLOOR, "#": (40, 170, 60), "+": (90, 70, 50)},
    ),
    "teleport": (
        (
            "..####..",
            ".#....#.",
            "#..##..#",
            "#.#..#.#",
            "#.#..#.#",
            "#..##..#",
            ".#....#.",
            "..####..",
        ),
        {".": _FLOOR, "#": (140, 60, 200)},
    ),
    "wall": (
        (
            "########",
            "...#....",
            "...#....",
            "########",
            ".......#",
            ".......#",
            "########",
            "...#....",
        ),
        {".": (150, 75, 50), "#": (190, 180, 170)},
    ),
    "mountain": (
        (
            "........",
            "...++...",
            "..+##+..",
            "..####..",
            ".######.",
            ".######.",
            "########",
            "........",
        ),
        {".": _FLOOR, "#": (125, 100, 75), "+": (250, 250, 250)},
    ),
    "pit": (
        (
            "........",
            "..####..",
            ".######.",
            "########",
            "########",
            ".######.",
            "..####..",
            "........",
        ),
        {".": _FLOOR, "#": (25, 25, 25)},
    ),
    "empty": (("........",) * 8, {".": _FLOOR}),
    # The agent holding the sword: the agent with a gold frame.
    "agent+sword": (
        (
            "++++++++",
            "+######+",
            "##.##.##",
            "########",
            "########",
            "#.####.#",
            "+##..##+",
            "++++++++",
        ),
        {".": _FLOOR, "#": (40, 90, 200), "+": (230, 180, 20)},
    ),
}
RGW_TILE_ORDER = (*ENTITY_NAMES, "agent+sword")
"""tile index = entity code (agent .. empty), then 9 = agent holding the sword"""

RGW_CHARS = ("A", "S", "E", "T", "O", "W", "M", "P", ".", "A")
RGW_COLOURS: tuple[int | None, ...] = (94, 37, 91, 92, 95, 90, 33, 90, None, 93)


@lru_cache(maxsize=8)
def rgw_tiles(scale: int = 3) -> np.ndarray:
    """(10, 8 * scale, 8 * scale, 3) uint8 tiles in RGW_TILE_ORDER."""
    tiles = np.stack([glyph_tile(*_RGW_GLYPHS[name], scale=scale) for name in RGW_TILE_ORDER])
    tiles.setflags(write=False)
    return tiles


def rgw_frame(entities: np.ndarray, holding: bool, scale: int = 3) -> np.ndarray:
    """RGB frame of one RGW state from its (H, W) entity grid."""
    codes = np.asarray(entities)
    if holding:
        codes = np.where(codes == 0, len(RGW_TILE_ORDER) - 1, codes)
    return draw_tiles(codes, rgw_tiles(scale))


def rgw_text(entities: np.ndarray, holding: bool, colour: bool = True) -> str:
    """Text of one RGW state (map legend letters), with a status line."""
    colours = RGW_COLOURS if colour else (None,) * len(RGW_CHARS)
    grid = ansi_grid(entities, RGW_CHARS, colours)
    return f"{grid}\nholding: {'sword' if holding else 'nothing'}\n"
