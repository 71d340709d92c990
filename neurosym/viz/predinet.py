"""PrediNet pictures: where each head looks at one step, and its R vectors over an episode.

* :func:`predinet_figure` -- per head, the two attention maps a1 and a2 over the
  grid at one step, the attended objects named and framed, D^h in the note.
* :func:`r_vectors_figure` -- R^h of every head over an episode as a heat map:
  the J relation values (diverging colours, one scale for all heads, since W_S
  is shared) above the four position values of E1 and E2 (0..1).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from matplotlib.colors import Normalize
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from neurosym.errors import ConfigError
from neurosym.viz.panels import Panel, heat_map_figure
from neurosym.viz.sources import EnvLike, Source, load_trace, require_source_module
from neurosym.viz.style import data_as_text, head_colour
from neurosym.viz.trace import EpisodeTrace

NOT_RECORDED = (
    "grey cells: weight not recorded (the recording keeps only each head's strongest cell)"
)

R_WIDTH_INCHES = 8.0
"""width of the R-vector heat map"""

R_HEAD_INCHES = 1.6
"""height of one head's block in the R-vector heat map"""


# ---------------------------------------------------------------------------
# attention maps at one step


def predinet_figure(
    source: Source,
    env: EnvLike = None,
    *,
    step: int = 0,
    head: int | None = None,
    episode: int | None = None,
    seed: int = 0,
) -> Figure:
    """Per head, the attention maps a1 and a2 over the grid at ``step``, attended objects named."""
    require_source_module(source, "predinet", "a PrediNet attention plot")
    trace = load_trace(source, env, episode=episode, seed=seed, max_steps=step + 1)
    return predinet_trace_figure(trace, step=step, head=head)


def predinet_trace_figure(trace: EpisodeTrace, *, step: int = 0, head: int | None = None) -> Figure:
    """:func:`predinet_figure` for a trace already built."""
    trace.require("predinet", "a PrediNet attention plot")
    trace.check_state(step)
    assert (
        trace.attention1 is not None
        and trace.attention2 is not None
        and trace.r_vectors is not None
    )
    heads = trace.heads if head is None else (trace.heads[trace.head_index(head)],)
    h, w = trace.shape
    names = trace.grids[step]
    rows: list[list[Panel]] = [[], []]
    notes = []
    for hd in heads:
        i = trace.head_index(hd)
        colour = head_colour(i)
        attended = []
        for arg, maps in ((1, trace.attention1), (2, trace.attention2)):
            weights = maps[step, i]  # (N,)
            cell = int(np.nanargmax(weights)) if np.isfinite(weights).any() else -1
            if cell < 0:
                rows[arg - 1].append(
                    Panel(weights.reshape(h, w), f"head {hd} · E{arg}: not recorded")
                )
                attended.append("?")
                continue
            r, c = divmod(cell, w)
            name = str(names[r, c])
            attended.append(name)
            title = f"head {hd} · E{arg} = {name} ({r},{c}) {weights[cell]:.2f}"
            rows[arg - 1].append(Panel(weights.reshape(h, w), title, ((r, c, colour),)))
        d = trace.r_vectors[step, i, : trace.relations]
        values = " ".join(f"{v:+.2f}" for v in d)
        notes.append(f"head {hd}: D({attended[0]}, {attended[1]}) = [{values}]")
    if not trace.complete:
        notes.append(NOT_RECORDED)
    title = f"PrediNet attention a1 (top) and a2 (bottom) at step {step}\n{trace.title_name}"
    return heat_map_figure(
        rows,
        names,
        title=title,
        colourbar_labels=("a1: weight of the cell", "a2: weight of the cell"),
        note="\n".join(_pairs(notes)),
    )


def _pairs(lines: list[str]) -> list[str]:
    """Two short lines per printed line, so four heads take two lines of the note."""
    out = []
    for i in range(0, len(lines), 2):
        out.append("      ".join(lines[i : i + 2]))
    return out


# ---------------------------------------------------------------------------
# R vectors over an episode


def r_vectors_figure(
    source: Source,
    env: EnvLike = None,
    *,
    head: int | None = None,
    episode: int | None = None,
    seed: int = 0,
    max_steps: int | None = None,
) -> Figure:
    """R^h of every head (or one) at every step of an episode as a heat map."""
    require_source_module(source, "predinet", "an R-vector plot")
    trace = load_trace(source, env, episode=episode, seed=seed, max_steps=max_steps)
    return r_vectors_trace_figure(trace, head=head)


@data_as_text
def r_vectors_trace_figure(trace: EpisodeTrace, *, head: int | None = None) -> Figure:
    """:func:`r_vectors_figure` for a trace already built.

    Size: 8.0 x (1.0 + 1.6 * heads shown) inches.
    """
    trace.require("predinet", "an R-vector plot")
    if trace.steps == 0:
        raise ConfigError(f"episode {trace.episode} has no steps: nothing to draw")
    assert trace.r_vectors is not None
    heads = trace.heads if head is None else (trace.heads[trace.head_index(head)],)
    j = trace.relations
    r = trace.r_vectors  # (S, heads, J + 4)
    fig = Figure(figsize=(R_WIDTH_INCHES, 1.0 + R_HEAD_INCHES * len(heads)), layout="constrained")
    fig.get_layout_engine().set(h_pad=0.02, hspace=0.0)
    ratios = [v for _ in heads for v in (max(j, 1), 4)]
    axes = fig.subplots(2 * len(heads), 1, sharex=True, gridspec_kw={"height_ratios": ratios})
    rel = r[:, [trace.head_index(hd) for hd in heads], :j]
    top = float(np.nanmax(np.abs(rel))) if np.isfinite(rel).any() else 1.0
    d_norm = Normalize(-top, top) if top > 0 else Normalize(-1, 1)
    p_norm = Normalize(0.0, 1.0)
    extent = (-0.5, trace.steps - 0.5, None, None)
    d_image = p_image = None
    for k, hd in enumerate(heads):
        i = trace.head_index(hd)
        ax_d, ax_p = axes[2 * k], axes[2 * k + 1]
        d_image = ax_d.imshow(
            r[:, i, :j].T,
            aspect="auto",
            cmap="RdBu_r",
            norm=d_norm,
            interpolation="nearest",
            extent=(extent[0], extent[1], j - 0.5, -0.5),
        )
        ax_d.set_yticks(range(j), [f"r({x})" for x in range(j)], fontsize=6)
        ax_d.set_ylabel(f"head {hd}", fontsize=8, color=head_colour(i), fontweight="bold")
        p_image = ax_p.imshow(
            r[:, i, j:].T,
            aspect="auto",
            cmap="cividis",
            norm=p_norm,
            interpolation="nearest",
            extent=(extent[0], extent[1], 3.5, -0.5),
        )
        ax_p.set_yticks(range(4), ["E1 row", "E1 col", "E2 row", "E2 col"], fontsize=6)
        for ax in (ax_d, ax_p):
            ax.tick_params(axis="x", labelsize=7, length=2)
            ax.tick_params(axis="y", length=0)
    _mark_events(axes, trace)
    axes[-1].set_xlabel("step t", fontsize=8)
    axes[-1].xaxis.set_major_locator(MaxNLocator(integer=True))
    # both bars beside all panels (side by side): bars over interleaved panels would overlap
    d_bar = fig.colorbar(d_image, ax=list(axes), shrink=0.7, pad=0.01, fraction=0.03)
    d_bar.set_label(r"relations r(j): $D^h_j = (E_1 - E_2)\,W_S$", fontsize=8, parse_math=True)
    p_bar = fig.colorbar(p_image, ax=list(axes), shrink=0.7, pad=0.01, fraction=0.03)
    p_bar.set_label("position in [0, 1]", fontsize=8)
    for bar in (d_bar, p_bar):
        bar.ax.tick_params(labelsize=7)
    outcome = f", outcome {trace.outcome}" if trace.outcome else ""
    fig.suptitle(
        f"PrediNet R vectors over {trace.steps} steps{outcome}\n{trace.title_name}", fontsize=10
    )
    return fig


def _mark_events(axes: Sequence[Any], trace: EpisodeTrace) -> None:
    """Dashed lines between state t and t+1 for each event, named above the first panel."""
    if trace.events.empty:
        return
    grouped = trace.events.groupby("t")["event"].apply(lambda e: ", ".join(map(str, e)))
    for t, text in grouped.items():
        x = float(t) + 0.5
        for ax in axes:
            ax.axvline(x, color="black", linewidth=0.6, linestyle="--", alpha=0.6)
        label = axes[0].annotate(
            text,
            (x, 1),
            xycoords=("data", "axes fraction"),
            xytext=(1, 1),
            textcoords="offset points",
            fontsize=6,
            rotation=30,
            ha="left",
            va="bottom",
        )
        label.set_in_layout(False)
