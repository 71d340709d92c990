"""A figure of heat maps over the grid: one column per head, one row per kind of map.

Both attention pictures (MHDPA: from / onto an object; PrediNet: argument 1 /
argument 2) have this shape, so they share the layout, the colour scaling
(one min..max scale per row, so heads can be compared) and the legend line.

Size: ``PANEL_INCHES`` per panel plus fixed margins, so a figure of ``heads``
columns and ``rows`` rows is ``(heads * 2.4 + 1.0) x (rows * 2.4 + 1.0)``
inches, i.e. ``(240 * heads + 100) x (240 * rows + 100)`` pixels at 100 dpi.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from matplotlib.colors import Normalize
from matplotlib.figure import Figure

from neurosym.viz.grid import draw_heat, label_size, outline_cell
from neurosym.viz.style import legend_text

PANEL_INCHES = 2.4
"""width and height of one grid panel"""

MARGIN_INCHES = 1.0
"""room for the title, colour bars and the legend line"""

HEAT_CMAP = "viridis"
"""colour map of attention weights"""


@dataclass(frozen=True)
class Panel:
    """One heat map: values over the grid, a title, and the cells to frame."""

    values: np.ndarray
    """(H, W) weights; NaN = not recorded"""
    title: str
    outlines: tuple[tuple[int, int, str], ...] = ()
    """(row, col, colour) of cells to frame"""


def row_norm(row: Sequence[Panel]) -> Normalize:
    """One colour scale for a row, from its smallest to its largest weight.

    Attention of an untrained or uncertain head is close to uniform (1/N
    everywhere); a scale from 0 would paint it one flat colour, min..max shows
    where it leans, and the colour bar gives the true range.
    """
    finite = [p.values[np.isfinite(p.values)] for p in row]
    values = np.concatenate(finite) if finite else np.zeros(0)
    if values.size == 0:
        return Normalize(0.0, 1.0)
    lo, hi = float(values.min()), float(values.max())
    if hi - lo < 1e-12:
        lo, hi = max(0.0, lo - 0.5 * max(abs(lo), 1e-3)), hi + 0.5 * max(abs(hi), 1e-3)
    return Normalize(lo, hi)


def figure_size(rows: int, cols: int) -> tuple[float, float]:
    """Figure size in inches for ``rows`` x ``cols`` panels."""
    return cols * PANEL_INCHES + MARGIN_INCHES, rows * PANEL_INCHES + MARGIN_INCHES


def heat_map_figure(
    panels: Sequence[Sequence[Panel]],
    names: np.ndarray,
    *,
    title: str,
    colourbar_labels: Sequence[str],
    note: str = "",
) -> Figure:
    """Lay out rows of panels over the grid ``names`` with one colour bar per row."""
    n_rows, n_cols = len(panels), len(panels[0])
    fig = Figure(figsize=figure_size(n_rows, n_cols), layout="constrained")
    fig.get_layout_engine().set(w_pad=0.03, h_pad=0.03, wspace=0.02, hspace=0.04)
    axes = fig.subplots(n_rows, n_cols, squeeze=False)
    fontsize = label_size(PANEL_INCHES * 0.85, names.shape[1])
    for r, row in enumerate(panels):
        norm = row_norm(row)
        image = None
        for c, panel in enumerate(row):
            ax = axes[r, c]
            image = draw_heat(ax, panel.values, names, cmap=HEAT_CMAP, norm=norm, fontsize=fontsize)
            for row_i, col_i, colour in panel.outlines:
                outline_cell(ax, row_i, col_i, colour=colour)
            ax.set_title(panel.title, fontsize=8)
        bar = fig.colorbar(image, ax=list(axes[r]), shrink=0.9, pad=0.01, fraction=0.04)
        bar.set_label(colourbar_labels[r], fontsize=8)
        bar.ax.tick_params(labelsize=7)
    fig.suptitle(title, fontsize=10)
    legend = legend_text(names.ravel())
    fig.supxlabel("\n".join(s for s in (legend, note) if s), fontsize=7.5)
    return fig
