"""Distributions of PrediNet relation values, with the threshold that makes them facts.

``neurosym extract`` keeps a relation row as a ``holds/5`` fact when |D_j|
exceeds relation j's threshold (:mod:`neurosym.facts.thresholds`, computed
from the recorded values of all heads, since W_S is shared). This figure shows
each relation's values per head and pooled, with the threshold at +/- its value
and how many values it keeps, so a threshold spec can be chosen by eye.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from neurosym.errors import ConfigError
from neurosym.facts.tables import DEFAULT_THRESHOLD
from neurosym.record.recording import Recording
from neurosym.viz.live import trace_from_agent
from neurosym.viz.panels import widen_for_text
from neurosym.viz.sources import EnvLike, Source, require_source_module
from neurosym.viz.style import data_as_text, head_colour
from neurosym.viz.trace import EpisodeTrace

HIST_PANEL_INCHES = (2.6, 2.2)
"""(width, height) of one relation's histogram"""

HIST_COLUMNS = 4
"""relations per row of the histogram figure"""

_BINS = 40


def relation_values(
    source: Source, env: EnvLike = None, *, episodes: int = 1, seed: int = 0
) -> tuple[pd.DataFrame, str]:
    """The relation table (episode, t, head, j, value) and a phrase saying where it came from.

    A Recording gives its ``relations`` table; an Agent plays ``episodes``
    episodes from seeds ``seed, seed + 1, ...``; an EpisodeTrace gives its own.
    """
    require_source_module(source, "predinet", "a relation-value plot")
    if isinstance(source, EpisodeTrace):
        return _trace_relations([source]), source.title_name
    if isinstance(source, Recording):
        table = source.relations.loc[:, ["episode", "t", "head", "j", "value"]]
        name = str(source.meta.get("checkpoint", "")) or "recording"
        n = int(source.episodes["episode"].nunique())
        return (
            table,
            f"{_base(name)} on {source.meta.get('env', '?')}, {n} recorded episode{'s' * (n != 1)}",
        )
    if episodes < 1:
        raise ConfigError(f"--episodes must be at least 1, got {episodes}")
    traces = [trace_from_agent(source, env, seed=seed + e) for e in range(episodes)]
    traces = [replace(t, episode=e) for e, t in enumerate(traces)]  # number the episodes 0..n-1
    seeds = f"seed {seed}" if episodes == 1 else f"seeds {seed}..{seed + episodes - 1}"
    env_name = traces[0].env
    return (
        _trace_relations(traces),
        f"{_base(str(source.path))} on {env_name}, {episodes} greedy episode{'s' * (episodes != 1)} ({seeds})",
    )


def _base(path: str) -> str:
    return Path(path).name or path


def _trace_relations(traces: Sequence[EpisodeTrace]) -> pd.DataFrame:
    frames = []
    for tr in traces:
        assert tr.r_vectors is not None
        d = tr.r_vectors[:, :, : tr.relations]  # (S, heads, J)
        s, h, j = d.shape
        t_idx, h_idx, j_idx = np.meshgrid(
            np.arange(s), np.asarray(tr.heads), np.arange(j), indexing="ij"
        )
        frames.append(
            pd.DataFrame(
                {
                    "episode": tr.episode,
                    "t": t_idx.ravel(),
                    "head": h_idx.ravel(),
                    "j": j_idx.ravel(),
                    "value": d.ravel(),
                }
            )
        )
    table = pd.concat(frames, ignore_index=True)
    return table.loc[np.isfinite(table["value"].to_numpy())]


@data_as_text
def relations_figure(
    source: Source,
    env: EnvLike = None,
    *,
    threshold: Any = DEFAULT_THRESHOLD,
    episodes: int = 1,
    seed: int = 0,
) -> Figure:
    """Histogram of each relation's values, per head and together, with its threshold marked.

    Size: (2.6 * columns + 0.4) x (2.2 * rows + 1.0) inches, 4 relations per row.
    """
    from neurosym.facts.thresholds import parse_threshold

    rule = parse_threshold(threshold)
    table, where = relation_values(source, env, episodes=episodes, seed=seed)
    if table.empty:
        raise ConfigError("there are no relation values to plot (the episodes have no steps)")
    per_j = rule.per_relation(table)
    js = sorted(int(j) for j in table["j"].unique())
    heads = sorted(int(h) for h in table["head"].unique())
    n_cols = min(HIST_COLUMNS, len(js))
    n_rows = -(-len(js) // n_cols)
    fig = Figure(
        figsize=(HIST_PANEL_INCHES[0] * n_cols + 0.4, HIST_PANEL_INCHES[1] * n_rows + 1.0),
        layout="constrained",
    )
    axes = fig.subplots(n_rows, n_cols, squeeze=False)
    values = table["value"].to_numpy()
    j_col = table["j"].to_numpy()
    h_col = table["head"].to_numpy()
    for k, ax in enumerate(axes.ravel()):
        if k >= len(js):
            ax.set_axis_off()
            continue
        j = js[k]
        mine = j_col == j
        v = values[mine]
        edges = np.histogram_bin_edges(v, bins=_BINS)
        ax.hist(v, bins=edges, color="#d0d0d0", label="all heads")
        for i, hd in enumerate(heads):
            ax.hist(
                v[h_col[mine] == hd],
                bins=edges,
                histtype="step",
                color=head_colour(i),
                linewidth=1.0,
                label=f"head {hd}",
            )
        thr = float(per_j.get(j, np.nan))
        kept = int(np.sum(np.abs(v) > thr)) if np.isfinite(thr) else 0
        if np.isfinite(thr):
            for x in (-thr, thr):
                ax.axvline(x, color="black", linestyle="--", linewidth=1.0)
        ax.set_title(f"r({j}): threshold ±{thr:.3g}, {kept} of {len(v)} kept", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.set_xlabel(rf"$D_{{{j}}}$ (all heads)", fontsize=7, parse_math=True)
    axes[0, 0].set_ylabel("steps x heads", fontsize=7)
    axes[0, 0].legend(fontsize=6, frameon=False, loc="upper left")
    title = fig.suptitle(
        f"PrediNet relation values with threshold {rule} (dashed: ± threshold)\n{where}",
        fontsize=10,
    )
    widen_for_text(fig, [title])
    return fig
