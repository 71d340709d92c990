"""Drawing Box-World states for people: upscaled RGB tiles and plain text.

The tiles keep the observation's colours (what the agent sees) and add a glyph
where a colour alone would be ambiguous to a reader: a keyhole on locks, a
disc for the agent, an outlined diamond for the gem. Drawing is one lookup of
a per-code tile atlas (laid out by :mod:`neurosym.envs.render`), no loop over cells.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from neurosym.envs.boxworld_entities import (
    AGENT,
    AGENT_RGB,
    BACKGROUND_RGB,
    COLOUR_NAMES,
    EMPTY,
    GEM,
    GEM_RGB,
    HELD,
    KEY,
    LOCK,
    NUM_CODES,
    NUM_COLOURS,
    PALETTE,
    WALL,
)
from neurosym.envs.render import ansi_grid, draw_tiles

DEFAULT_TILE = 24
"""pixels per cell of ``rgb_array`` frames"""


@lru_cache(maxsize=8)
def tile_atlas(tile: int = DEFAULT_TILE) -> np.ndarray:
    """(NUM_CODES, tile, tile, 3) uint8: the picture of every entity code."""
    if tile < 4:
        raise ValueError(f"tile size must be at least 4 pixels, got {tile}")
    yy, xx = (np.mgrid[0:tile, 0:tile] + 0.5) / tile - 0.5  # centred coordinates in [-0.5, 0.5)
    disc = yy**2 + xx**2 <= 0.36**2
    diamond = np.abs(yy) + np.abs(xx) <= 0.38
    diamond_edge = diamond & ~(np.abs(yy) + np.abs(xx) <= 0.38 - 1.5 / tile)
    keyhole = (yy + 0.1) ** 2 + xx**2 <= 0.14**2
    keyhole |= (np.abs(xx) <= 0.07) & (yy >= -0.1) & (yy <= 0.25)
    edge = np.zeros((tile, tile), bool)
    edge[-1, :] = edge[:, -1] = True  # a faint grid line between cells

    atlas = np.broadcast_to(PALETTE[:, None, None, :], (NUM_CODES, tile, tile, 3)).copy()
    atlas[EMPTY][edge] = (186, 186, 186)
    atlas[AGENT] = BACKGROUND_RGB
    atlas[AGENT][edge] = (186, 186, 186)
    atlas[AGENT][disc] = AGENT_RGB
    atlas[GEM] = BACKGROUND_RGB
    atlas[GEM][diamond] = GEM_RGB
    atlas[GEM][diamond_edge] = (60, 60, 60)
    for c in range(NUM_COLOURS):
        atlas[LOCK + c][keyhole] = (20, 20, 20)
    atlas.setflags(write=False)
    return atlas


def rgb_frame(grid: np.ndarray, tile: int = DEFAULT_TILE) -> np.ndarray:
    """(H * tile, W * tile, 3) uint8 picture of an (H, W) grid of entity codes."""
    return draw_tiles(grid, tile_atlas(tile), line=None)  # the atlas draws its own grid lines


_LETTERS = "abcdefghijklmnopqrst"
assert len(_LETTERS) == NUM_COLOURS


def _char_table() -> np.ndarray:
    chars = np.empty(NUM_CODES, dtype="<U1")
    chars[EMPTY], chars[WALL], chars[AGENT], chars[GEM] = ".", "#", "@", "*"
    chars[KEY : KEY + NUM_COLOURS] = list(_LETTERS)
    chars[LOCK : LOCK + NUM_COLOURS] = list(_LETTERS.upper())
    chars[HELD : HELD + NUM_COLOURS] = list(_LETTERS)
    return chars


_CHARS = _char_table()
_NO_COLOUR = [None] * NUM_CODES  # 20 colours do not fit the terminal's 16: letters name them


def ansi_text(grid: np.ndarray) -> str:
    """Text picture of an (H, W) grid: ``#`` wall, ``.`` empty, ``@`` agent, ``*`` gem,
    a key in lower case and its lock in upper case (letter per colour, legend below);
    the held key shows in the top-left corner."""
    lines = [ansi_grid(grid, _CHARS.tolist(), _NO_COLOUR)]
    codes = np.unique(grid)
    colours = sorted(
        {
            int(c - base)
            for base in (KEY, LOCK, HELD)
            for c in codes
            if base <= c < base + NUM_COLOURS
        }
    )
    legend = ", ".join(f"{_LETTERS[c]}/{_LETTERS[c].upper()} {COLOUR_NAMES[c]}" for c in colours)
    if legend:
        lines.append(f"keys/locks: {legend}")
    return "\n".join(lines) + "\n"
