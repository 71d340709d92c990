"""Drawing a grid world on a matplotlib Axes: entity colours, heat maps, labels, arrows.

Cell (row, col) is centred on data coordinates (x=col, y=row), row 0 at the
top, as ``imshow`` lays out an (H, W) array; every other module places marks
with :func:`cell_xy`. Cells get the short labels of :mod:`neurosym.viz.style`
so that a heat map still says which object each weight belongs to.
"""

from __future__ import annotations

import numpy as np
from matplotlib import patheffects
from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.collections import LineCollection
from matplotlib.colors import Colormap, Normalize, to_rgb
from matplotlib.image import AxesImage
from matplotlib.patches import FancyArrowPatch, Patch, Polygon, Rectangle
from matplotlib.text import Text

from neurosym.viz.style import entity_colour, entity_label, split_entity, text_colour_on

MISSING_COLOUR = "#d9d9d9"
"""cells whose weight was not recorded"""

_STROKE = [patheffects.withStroke(linewidth=1.6, foreground="white")]


def cell_xy(cell: int, width: int) -> tuple[float, float]:
    """Data coordinates (x, y) of the centre of flat cell index ``cell``."""
    return float(cell % width), float(cell // width)


def label_size(panel_inches: float, width: int) -> float:
    """Font size (points) that fits a label into one cell of a panel ``panel_inches`` wide."""
    return max(3.5, min(10.0, 0.5 * panel_inches * 72 / max(width, 1)))


def _frame(ax: Axes, shape: tuple[int, int]) -> None:
    """Axes limits for an (H, W) grid, no ticks, thin white cell borders."""
    h, w = shape
    ax.set_xlim(-0.5, w - 0.5)
    ax.set_ylim(h - 0.5, -0.5)
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_aspect("equal")
    # one collection per direction: tick machinery per cell is slow
    ax.vlines(np.arange(0.5, w - 1), -0.5, h - 0.5, colors="white", linewidth=0.4).set_in_layout(
        False
    )
    ax.hlines(np.arange(0.5, h - 1), -0.5, w - 0.5, colors="white", linewidth=0.4).set_in_layout(
        False
    )


def _patch(ax: Axes, patch: Patch) -> Patch:
    """A patch inside the axes, left out of the layout computation."""
    ax.add_patch(patch).set_in_layout(False)
    return patch


def _cell_text(ax: Axes, x: float, y: float, text: str, **kwargs: object) -> Text:
    """Text inside a cell; left out of the layout computation (it never leaves the axes)."""
    artist = ax.text(x, y, text, ha="center", va="center", **kwargs)
    artist.set_in_layout(False)
    return artist


def entity_rgb(names: np.ndarray) -> np.ndarray:
    """(H, W, 3) float colours of the entities in an (H, W) array of names."""
    uniq, inverse = np.unique(names.astype(str), return_inverse=True)
    palette = np.array([to_rgb(entity_colour(n)) for n in uniq])  # (U, 3)
    return palette[inverse.reshape(names.shape)]


def draw_entities(ax: Axes, names: np.ndarray, *, fontsize: float) -> AxesImage:
    """The grid in entity colours, each non-empty cell labelled."""
    image = ax.imshow(entity_rgb(names), interpolation="nearest")
    _frame(ax, names.shape)
    for (r, c), name in np.ndenumerate(names):
        label = entity_label(name)
        if label:
            _cell_text(
                ax,
                c,
                r,
                label,
                fontsize=fontsize,
                color=text_colour_on(entity_colour(name)),
                fontweight="bold",
            )
    return image


def draw_heat(
    ax: Axes,
    values: np.ndarray,
    names: np.ndarray,
    *,
    cmap: str | Colormap,
    norm: Normalize,
    fontsize: float,
) -> AxesImage:
    """An (H, W) heat map over the grid, NaN cells grey, labelled with the entities there."""
    cmap = _with_missing(cmap)
    image = ax.imshow(np.ma.masked_invalid(values), cmap=cmap, norm=norm, interpolation="nearest")
    _frame(ax, values.shape)
    label_entities(ax, names, fontsize=fontsize)
    return image


def label_entities(ax: Axes, names: np.ndarray, *, fontsize: float) -> None:
    """Write each non-empty cell's label, legible on any fill; Box-World colours as a swatch."""
    for (r, c), name in np.ndenumerate(names):
        label = entity_label(name)
        if not label:
            continue
        _, colour = split_entity(name)
        if colour is not None:
            _patch(
                ax,
                Rectangle(
                    (c - 0.45, r - 0.45),
                    0.35,
                    0.35,
                    facecolor=entity_colour(name),
                    edgecolor="black",
                    linewidth=0.3,
                ),
            )
        _cell_text(
            ax,
            c,
            r,
            label,
            fontsize=fontsize,
            color="black",
            fontweight="bold",
            path_effects=_STROKE,
        )


def outline_cell(ax: Axes, row: int, col: int, *, colour: str, linewidth: float = 1.8) -> None:
    """A coloured frame around one cell (the object a map is about)."""
    _patch(
        ax,
        Rectangle((col - 0.5, row - 0.5), 1, 1, fill=False, edgecolor=colour, linewidth=linewidth),
    )


def head_arrow(
    ax: Axes,
    start: tuple[float, float],
    end: tuple[float, float],
    *,
    colour: str,
    label: str,
    fontsize: float,
) -> list[Artist]:
    """An arrow from one attended cell to the other, with the head number at its middle.

    When both arguments are the same cell, a square marks it instead. Returns the artists drawn.
    """
    (x0, y0), (x1, y1) = start, end
    text = dict(color=colour, fontsize=fontsize, fontweight="bold", path_effects=_STROKE)
    if (x0, y0) == (x1, y1):
        ring = Rectangle(
            (x0 - 0.38, y0 - 0.38), 0.76, 0.76, fill=False, edgecolor=colour, linewidth=1.5
        )
        return [_patch(ax, ring), _cell_text(ax, x0 + 0.38, y0 - 0.38, label, **text)]
    arrow = FancyArrowPatch(
        (x0, y0),
        (x1, y1),
        arrowstyle="-|>",
        mutation_scale=8,
        color=colour,
        linewidth=1.4,
        shrinkA=2,
        shrinkB=2,
        connectionstyle="arc3,rad=0.15",
    )
    return [_patch(ax, arrow), _cell_text(ax, (x0 + x1) / 2, (y0 + y1) / 2, label, **text)]


def mark_agent(ax: Axes, row: int, col: int, *, fontsize: float) -> list[Artist]:
    """The agent's cell drawn on top of the terrain (the moving part of an animation)."""
    fill = entity_colour("agent")
    cell = Rectangle((col - 0.5, row - 0.5), 1, 1, facecolor=fill, edgecolor="none")
    label = _cell_text(
        ax,
        col,
        row,
        entity_label("agent"),
        fontsize=fontsize,
        color=text_colour_on(fill),
        fontweight="bold",
    )
    return [_patch(ax, cell), label]


_POINTS = {"east": (1, 0), "south": (0, 1), "west": (-1, 0), "north": (0, -1)}
"""(dx, dy) in data coordinates (row 0 at the top) of each Minigrid direction"""


def mark_direction(ax: Axes, row: int, col: int, direction: str) -> list[Artist]:
    """A triangle in the agent's cell pointing where it faces (Minigrid's agent turns)."""
    if direction not in _POINTS:
        return []
    dx, dy = _POINTS[direction]
    tip = (col + 0.42 * dx, row + 0.42 * dy)
    back = (col + 0.12 * dx, row + 0.12 * dy)
    side = (0.2 * -dy, 0.2 * dx)
    corners = [tip, (back[0] + side[0], back[1] + side[1]), (back[0] - side[0], back[1] - side[1])]
    fill = text_colour_on(entity_colour("agent"))
    return [_patch(ax, Polygon(corners, closed=True, facecolor=fill, edgecolor="none"))]


def mark_doors(
    ax: Axes, names: np.ndarray, doors: list[tuple[int, int, str]], *, fontsize: float
) -> list[Artist]:
    """Each Minigrid door's state: an open door is an outline in its colour, a closed one the
    filled cell drawn already, a locked one that cell with a black keyhole."""
    out: list[Artist] = []
    for row, col, state in doors:
        name = str(names[row, col])
        if split_entity(name)[0] != "door":
            continue  # the agent stands in the doorway
        colour = entity_colour(name)
        if state == "open":
            inner = Rectangle(
                (col - 0.5, row - 0.5), 1, 1, facecolor=entity_colour("empty"),
                edgecolor=colour, linewidth=2.5,
            )  # fmt: skip
            out += [_patch(ax, inner)]
            out += [_cell_text(ax, col, row, "D", fontsize=fontsize, color=colour, fontweight="bold")]
        elif state == "locked":
            hole = Rectangle((col + 0.12, row + 0.12), 0.22, 0.26, facecolor="black", edgecolor="none")
            out += [_patch(ax, hole)]
    return out


def draw_route(ax: Axes, path: np.ndarray, *, colour: str = "#1f77b4") -> LineCollection:
    """The agent's route through (row, col) states; jumps (teleports) are dotted."""
    path = path[(path >= 0).all(axis=1)]
    moves = np.abs(np.diff(path, axis=0)).sum(axis=1) if len(path) > 1 else np.zeros(0)  # (S,)
    keep = np.flatnonzero(moves > 0)
    xy = path[:, ::-1].astype(float)  # (S+1, 2) as (x=col, y=row)
    segments = np.stack([xy[keep], xy[keep + 1]], axis=1)  # (M, 2, 2)
    styles = ["solid" if moves[i] == 1 else (0, (1, 1.5)) for i in keep]
    lines = LineCollection(
        segments,
        colors=colour,
        linewidths=2.0,
        alpha=0.75,
        linestyles=styles or "solid",
        capstyle="round",
    )
    ax.add_collection(lines)
    return lines


def _with_missing(cmap: str | Colormap) -> Colormap:
    import matplotlib

    base = matplotlib.colormaps[cmap] if isinstance(cmap, str) else cmap
    return base.with_extremes(bad=MISSING_COLOUR)
