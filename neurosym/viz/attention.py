"""MHDPA attention maps: what one object attends to, and what attends to it.

The thesis reads its MHDPA agent through such maps (figures 19 to 22): the
attention of the agent on every other cell (a row of the query x key matrix)
and the attention of every cell on the enemy, the teleport or the sword (a
column). :func:`mhdpa_figure` draws both for each head at one step, on the
grid, with the objects labelled and the chosen object framed.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from neurosym.viz.panels import Panel, heat_map_figure
from neurosym.viz.sources import EnvLike, Source, load_trace, require_source_module
from neurosym.viz.trace import EpisodeTrace

OBJECT_FRAME = "#ff2d2d"
"""colour of the frame around the object a map is about"""

NOT_RECORDED = (
    "grey cells: weight not recorded (the recording keeps only the strongest keys of each query)"
)


def mhdpa_figure(
    source: Source,
    env: EnvLike = None,
    *,
    step: int = 0,
    object: str | None = "agent",
    cell: tuple[int, int] | None = None,
    head: int | None = None,
    episode: int | None = None,
    seed: int = 0,
) -> Figure:
    """Per head, the attention of ``object`` on all cells and of all cells on ``object``.

    ``source`` is a Recording (pick ``episode``), an Agent played on ``env`` from
    ``reset(seed)``, or an EpisodeTrace. ``cell=(row, col)`` picks the object by
    position instead of by name; ``head`` draws one head instead of all.
    """
    require_source_module(source, "mhdpa", "an MHDPA attention plot")
    trace = load_trace(
        source, env, episode=episode, seed=seed, max_steps=step + 1, keep_attention={step}
    )
    return mhdpa_trace_figure(trace, step=step, object=object, cell=cell, head=head)


def mhdpa_trace_figure(
    trace: EpisodeTrace,
    *,
    step: int = 0,
    object: str | None = "agent",
    cell: tuple[int, int] | None = None,
    head: int | None = None,
) -> Figure:
    """:func:`mhdpa_figure` for a trace already built."""
    trace.require("mhdpa", "an MHDPA attention plot")
    trace.check_state(step)
    heads = trace.heads if head is None else (trace.heads[trace.head_index(head)],)
    row, col, name = trace.locate(step, object, cell)
    h, w = trace.shape
    weights = trace.mhdpa[step]  # (heads, N, N) query x key
    q = row * w + col
    where = f"{name} ({row},{col})"
    frame = ((row, col, OBJECT_FRAME),)
    outgoing = [
        Panel(
            weights[trace.head_index(hd), q, :].reshape(h, w),
            f"head {hd}: {where} attends to",
            frame,
        )
        for hd in heads
    ]
    incoming = [
        Panel(
            weights[trace.head_index(hd), :, q].reshape(h, w),
            f"head {hd}: attention on {where}",
            frame,
        )
        for hd in heads
    ]
    top = _strongest(weights, heads, trace, q, step)
    title = f"MHDPA attention of and on {where} at step {step}\n{trace.title_name}"
    note = "\n".join(s for s in (top, "" if trace.complete else NOT_RECORDED) if s)
    return heat_map_figure(
        [outgoing, incoming],
        trace.grids[step],
        title=title,
        colourbar_labels=("weight of the key cell", "weight given by the query cell"),
        note=note,
    )


def _strongest(
    weights: np.ndarray, heads: tuple[int, ...], trace: EpisodeTrace, q: int, step: int
) -> str:
    """``head 0 -> enemy (9,1) 0.41`` for each head: the cell the object attends to most."""
    names = trace.grids[step].ravel()
    w = trace.shape[1]
    parts = []
    for hd in heads:
        row = weights[trace.head_index(hd), q, :]
        if not np.isfinite(row).any():
            continue
        k = int(np.nanargmax(row))
        parts.append(f"head {hd} -> {names[k]} ({k // w},{k % w}) {row[k]:.3g}")
    return "strongest: " + ", ".join(parts) if parts else ""
