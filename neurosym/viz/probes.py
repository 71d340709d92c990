"""Probe selectivity as a heat map: heads x predicates, accuracy minus control.

Reads the table ``neurosym probe`` writes (``probes.parquet``). One panel for
the trained network and, when the table has it, one for the untrained network
of the same shape, on the same colour scale, so what training added shows as
the difference between the two. Predicates are ordered by their best
selectivity over the heads; ``top`` keeps the most selective ones.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from neurosym.errors import ConfigError
from neurosym.viz.style import data_as_text


def load_probe_table(path: str | os.PathLike[str]) -> pd.DataFrame:
    """The probe table from a ``neurosym probe`` output folder or its ``probes.parquet``."""
    p = Path(path)
    if p.is_dir():
        p = p / "probes.parquet"
    try:
        return pd.read_parquet(p)
    except (OSError, ValueError) as exc:
        raise ConfigError(f"cannot read the probe table {p}: {exc}") from None


@data_as_text
def probes_figure(table: pd.DataFrame, relation: str = "all", top: int = 25) -> Figure:
    """Heads x predicates selectivity of relation ``relation`` (``all``, ``0``, ... or ``best``).

    ``best``: per head and predicate, the most selective of its relations.
    """
    if table.empty:
        raise ConfigError("the probe table is empty: no predicate could be probed")
    if relation == "best":
        t = table.sort_values("selectivity", ascending=False).drop_duplicates(["head", "predicate"])
    else:
        t = table[table["relation"].astype(str) == relation]
        if t.empty:
            have = ", ".join(sorted(set(table["relation"].astype(str))))
            raise ConfigError(f"no probes of relation {relation!r}; the table has {have} (or best)")
    panels = [("selectivity", "trained")]
    if "untrained_selectivity" in t and t["untrained_selectivity"].notna().all():
        panels.append(("untrained_selectivity", "untrained, same shape"))
    order = (
        t.groupby("predicate")["selectivity"]
        .max()
        .sort_values(ascending=False)
        .index[:top]
        .tolist()
    )
    heads = sorted(t["head"].unique().tolist())
    grids = [
        t.pivot_table(index="head", columns="predicate", values=col, aggfunc="max")
        .reindex(index=heads, columns=order)
        .to_numpy(dtype=np.float64)
        for col, _ in panels
    ]
    limit = max(0.05, float(np.nanmax(np.abs(np.stack(grids)))))
    width = 1.2 + 0.32 * len(order)
    fig = Figure(figsize=(width, 0.9 + 1.9 * len(panels) + 0.11 * max(map(len, order))))
    axes = fig.subplots(len(panels), 1, squeeze=False)[:, 0]
    for ax, grid, (_, title) in zip(axes, grids, panels, strict=True):
        im = ax.imshow(grid, cmap="RdBu_r", vmin=-limit, vmax=limit, aspect="auto")
        ax.set_yticks(range(len(heads)), [f"head {h}" for h in heads], fontsize=8)
        ax.set_xticks(range(len(order)), order, rotation=70, ha="right", fontsize=7)
        ax.set_title(f"selectivity (accuracy - control), relation {relation}: {title}", fontsize=9)
        for (i, j), v in np.ndenumerate(grid):
            if np.isfinite(v) and abs(v) >= 0.1:
                ax.text(j, i, f"{v:.2f}", ha="center", va="center", fontsize=6)
        fig.colorbar(im, ax=ax, fraction=0.02, pad=0.01)
    fig.tight_layout()
    return fig
