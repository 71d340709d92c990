"""A figure of heat maps over the grid: one column per head, one row per kind of map.

Both attention pictures (MHDPA: from / onto an object; PrediNet: argument 1 /
argument 2) have this shape, so they share the layout, the colour scaling
(one min..max scale per row, so heads can be compared) and the legend line.

Size: ``PANEL_INCHES`` per panel plus fixed margins, so a figure of ``heads``
columns and ``rows`` rows is ``(heads * 2.4 + 1.0) x (rows * 2.4 + 1.0)``
inches, i.e. ``(240 * heads + 100) x (240 * rows + 100)`` pixels at 100 dpi,
or wider when the title or the note under the panels needs it (one head).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from matplotlib.colors import Normalize
from matplotlib.figure import Figure
from matplotlib.text import Text

from neurosym.viz.grid import draw_heat, label_size, outline_cell
from neurosym.viz.style import data_as_text, legend_text

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
    where it leans, and the colour bar gives the true range. A row with cells
    not recorded (a saved recording keeps only the strongest cell of a map)
    is on the weights' own scale, 0..1: min..max of a few strongest cells
    would be a range of nothing (all 1.00 gave a 0.5..1.5 bar).
    """
    finite = [p.values[np.isfinite(p.values)] for p in row]
    values = np.concatenate(finite) if finite else np.zeros(0)
    if values.size == 0 or any(not np.isfinite(p.values).all() for p in row):
        return Normalize(0.0, max(1.0, float(values.max()) if values.size else 1.0))
    lo, hi = float(values.min()), float(values.max())
    if hi - lo < 1e-12:
        lo, hi = max(0.0, lo - 0.5 * max(abs(lo), 1e-3)), hi + 0.5 * max(abs(hi), 1e-3)
    return Normalize(lo, hi)


def figure_size(rows: int, cols: int) -> tuple[float, float]:
    """Figure size in inches for ``rows`` x ``cols`` panels."""
    return cols * PANEL_INCHES + MARGIN_INCHES, rows * PANEL_INCHES + MARGIN_INCHES


@data_as_text
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
        bar = fig.colorbar(
            image, ax=list(axes[r]), shrink=0.9, pad=0.01, fraction=0.04, panchor=False
        )
        bar.set_label(colourbar_labels[r], fontsize=8)
        bar.ax.tick_params(labelsize=7)
    texts = [fig.suptitle(title, fontsize=10)]
    legend = legend_text(names.ravel())
    texts.append(fig.supxlabel("\n".join(s for s in (legend, note) if s), fontsize=7.5))
    widen_for_text(fig, texts)
    return fig


def widen_for_text(fig: Figure, texts: Sequence[Text], margin_inches: float = 0.3) -> None:
    """Make ``fig`` wide enough for the longest of ``texts`` (titles, legend, notes).

    Panels set a figure's width; one head's panel is narrower than the title
    and the D line under it, which would be cut at both sides.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    renderer = FigureCanvasAgg(fig).get_renderer()
    widest = max(t.get_window_extent(renderer).width for t in texts) / fig.dpi
    if widest + margin_inches > fig.get_figwidth():
        fig.set_figwidth(widest + margin_inches)
