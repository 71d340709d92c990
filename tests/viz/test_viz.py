"""neurosym.viz on hand-built recordings: traces, figures of known pixel size, reproducible bytes, errors."""

from __future__ import annotations

import io
import re

import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure
from PIL import Image

from neurosym.errors import ConfigError
from neurosym.facts.thresholds import parse_threshold
from neurosym.record.recording import Recording
from neurosym.viz import episode as ep_mod
from neurosym.viz.attention import mhdpa_figure
from neurosym.viz.output import figure_bytes, gif_bytes, save_figure
from neurosym.viz.predinet import predinet_figure, r_vectors_figure
from neurosym.viz.recorded import trace_from_recording
from neurosym.viz.relations import relations_figure

LAYOUT = (
    "A....MSMMM",
    "......MMMM",
    ".......MMM",
    "........MO",
    "...W.....M",
    "...W......",
    "WWWWWWWW..",
    "........P.",
    "WW......OP",
    "TE........",
)
TYPES = {
    "A": "agent",
    "S": "sword",
    "E": "enemy",
    "T": "terminal",
    "O": "teleport",
    "W": "wall",
    "M": "mountain",
    "P": "pit",
}
# states 0..5: three steps right, then down onto the teleport end (3,9)... jump to (8,8), then left
ROUTE = [(2, 6), (2, 7), (2, 8), (2, 9), (8, 8), (8, 7)]
ACTIONS = ["right", "right", "right", "down", "left"]
HEADS, J = 2, 3
# PrediNet: (t, head) -> (a1 cell, a2 cell); weights fixed per arg
ARGS = {
    (t, h): ((0, 6), (9, 1)) if h == 0 else ((8, 8), ROUTE[t])
    for t in range(5)
    for h in range(HEADS)
}


def base_grid() -> np.ndarray:
    grid = np.full((10, 10), "empty", dtype=object)
    for r, line in enumerate(LAYOUT):
        for c, ch in enumerate(line):
            if ch in TYPES and ch != "A":
                grid[r, c] = TYPES[ch]
    return grid


def synthetic_recording(module: str) -> Recording:
    """One episode of 5 steps on an RGW-2-like map, tables shaped as the recorder makes them."""
    grid = base_grid()
    objects = [
        (f"{grid[r, c]}{k}", grid[r, c], r, c)
        for k, (r, c) in enumerate(zip(*np.nonzero(grid != "empty"), strict=True))
    ]
    positions = [(0, t, "agent", "agent", r, c) for t, (r, c) in enumerate(ROUTE)]
    positions += [(0, t, oid, ty, r, c) for t in range(6) for oid, ty, r, c in objects]
    tables: dict[str, pd.DataFrame] = {
        "episodes": pd.DataFrame(
            [(0, 5, -0.2, "timeout", 11)], columns=["episode", "steps", "return", "outcome", "seed"]
        ),
        "steps": pd.DataFrame(
            {"episode": 0, "t": range(5), "action": ACTIONS, "reward": [0.0, -0.1, -0.1, 0.0, 0.0]}
        ),
        "positions": pd.DataFrame(
            positions, columns=["episode", "t", "object", "type", "row", "col"]
        ),
        "events": pd.DataFrame([(0, 3, "teleported")], columns=["episode", "t", "event"]),
    }
    if module == "predinet":
        att, rel, rv = [], [], []
        for (t, h), cells in ARGS.items():
            for arg, (r, c) in zip((1, 2), cells, strict=True):
                att.append((0, t, h, arg, "x", r, c, 0.5 + 0.1 * arg))
            for j in range(J):
                value = (t + 1) * (h + 1) * (j - 1) / 10  # j=0 negative, j=1 zero, j=2 positive
                rel.append((0, t, h, j, "x", "y", value))
                rv.append((0, t, h, j, value))
            for k, v in enumerate(
                (cells[0][0] / 9, cells[0][1] / 9, cells[1][0] / 9, cells[1][1] / 9)
            ):
                rv.append((0, t, h, J + k, v))
        tables["attends"] = pd.DataFrame(
            att, columns=["episode", "t", "head", "arg", "entity", "row", "col", "weight"]
        )
        tables["relations"] = pd.DataFrame(
            rel, columns=["episode", "t", "head", "j", "a", "b", "value"]
        )
        tables["r_vectors"] = pd.DataFrame(rv, columns=["episode", "t", "head", "j", "value"])
    else:
        rows = []
        for t in range(5):
            for h in range(HEADS):
                for q in np.flatnonzero(grid.ravel() != "empty").tolist() + [
                    ROUTE[t][0] * 10 + ROUTE[t][1]
                ]:
                    key = (
                        91 if h == 0 else 6
                    )  # head 0 looks at the enemy (9,1), head 1 at the sword (0,6)
                    rows.append(
                        (0, t, h, "q", "k", 0.25 + 0.05 * h, q // 10, q % 10, key // 10, key % 10)
                    )
        tables["attention"] = pd.DataFrame(
            rows,
            columns=[
                "episode",
                "t",
                "head",
                "query",
                "key",
                "weight",
                "query_row",
                "query_col",
                "key_row",
                "key_col",
            ],
        )
    meta = {"checkpoint": f"runs/rgw2-{module}.pt", "env": "rgw2", "module": module, "heads": HEADS,
            "relations": J if module == "predinet" else 0, "seed": 11}  # fmt: skip
    return Recording(**tables, meta=meta)


@pytest.fixture(scope="module")
def pn() -> Recording:
    return synthetic_recording("predinet")


@pytest.fixture(scope="module")
def mh() -> Recording:
    return synthetic_recording("mhdpa")


def png_size(data: bytes) -> tuple[int, int]:
    with Image.open(io.BytesIO(data)) as im:
        return im.size


# ---------------------------------------------------------------- traces


def test_trace_rebuilds_grids_route_and_sparse_maps(pn: Recording) -> None:
    tr = trace_from_recording(pn)
    assert tr.steps == 5 and tr.shape == (10, 10) and tr.heads == (0, 1) and tr.relations == J
    assert tr.agent_path.tolist() == [list(p) for p in ROUTE]
    assert (
        tr.grids[0, 0, 6] == "sword"
        and tr.grids[4, 8, 8] == "agent"
        and tr.grids[0, 0, 0] == "empty"
    )
    assert tr.grids[5, 8, 8] == "teleport"  # the agent left the teleport end
    assert not tr.complete
    # a1 holds exactly the recorded cell and weight, NaN elsewhere
    a1 = tr.attention1[2, 1]
    assert np.flatnonzero(np.isfinite(a1)).tolist() == [88] and a1[88] == pytest.approx(0.6)
    assert tr.r_vectors.shape == (5, 2, J + 4)
    assert tr.r_vectors[4, 1, :J].tolist() == pytest.approx([-1.0, 0.0, 1.0])
    assert tr.event_text(3) == "teleported"


def test_without_its_env_a_recording_is_drawn_from_its_positions_alone(pn: Recording) -> None:
    from dataclasses import replace

    orphan = replace(pn, meta={**pn.meta, "env": "rgw-from-another-version"})
    tr = trace_from_recording(orphan)
    assert tr.shape == (10, 10) and tr.env == "rgw-from-another-version"
    assert (
        tr.grids[0, 0, 6] == "sword" and tr.grids[0, 6, 0] == "wall"
    )  # listed in this recording's positions
    assert tr.agent_path.tolist() == [list(p) for p in ROUTE]


def test_mhdpa_trace_builds_maps_on_demand_and_the_agents_focus(mh: Recording) -> None:
    tr = trace_from_recording(mh)
    att = tr.mhdpa[2]  # (heads, N, N)
    assert att.shape == (2, 100, 100)
    agent = 2 * 10 + 8
    assert np.nanargmax(att[0, agent]) == 91 and np.nanargmax(att[1, agent]) == 6
    assert np.isnan(att[0, 0]).all()  # the empty cell (0,0) was never a query
    assert tr.mhdpa_focus.tolist() == [[91, 6]] * 5


def test_objects_are_found_by_entity_cell_or_id(mh: Recording) -> None:
    tr = trace_from_recording(mh)
    ids = mh.positions.loc[
        (mh.positions["t"] == 0) & (mh.positions["type"] == "teleport"), "object"
    ].tolist()
    assert tr.locate(0, "sword") == (0, 6, "sword")
    assert tr.locate(4, "agent") == (8, 8, "agent")
    assert tr.locate(0, cell=(8, 8)) == (8, 8, "teleport")
    assert tr.locate(0, ids[1]) == (8, 8, f"{ids[1]} = teleport")
    with pytest.raises(
        ConfigError, match=rf"pick one with --cell \(3,9 8,8\) or an id \({ids[0]}, {ids[1]}\)"
    ):
        tr.locate(0, "teleport")


def test_unknown_episode_is_refused(pn: Recording) -> None:
    with pytest.raises(
        ConfigError, match=r"--episode 3 is not in the recording: it has episodes 0"
    ):
        trace_from_recording(pn, 3)


# ---------------------------------------------------------------- figures


def test_mhdpa_figure_size_is_fixed_by_the_heads(mh: Recording) -> None:
    fig = mhdpa_figure(mh, step=1, object="sword")
    assert png_size(figure_bytes(fig, "png", 50)) == (
        290,
        290,
    )  # (2 heads * 2.4 + 1.0) inches at 50 dpi
    assert "sword (0,6)" in fig.get_suptitle() and "rgw2-mhdpa.pt" in fig.get_suptitle()
    one = mhdpa_figure(mh, step=1, cell=(3, 9), head=1)
    width, height = png_size(figure_bytes(one, "png", 50))
    assert height == 290 and width >= 170  # one head: as wide as its title needs
    assert_texts_inside(one)
    assert "teleport (3,9)" in one.get_suptitle()


def assert_texts_inside(fig: Figure) -> None:
    """The title and the note under the panels are inside the figure, not cut at its sides."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    renderer = FigureCanvasAgg(fig).get_renderer()
    fig.draw(renderer)
    width = fig.get_figwidth() * fig.dpi
    for text in (fig._suptitle, fig._supxlabel):
        if text is None:
            continue
        box = text.get_window_extent(renderer)
        assert box.x0 >= 0 and box.x1 <= width, (text.get_text(), box, width)


def test_one_head_figures_are_wide_enough_for_their_text(pn: Recording, mh: Recording) -> None:
    assert_texts_inside(predinet_figure(pn, step=0, head=0))
    assert_texts_inside(mhdpa_figure(mh, step=1, object="sword", head=0))
    assert_texts_inside(ep_mod.episode_figure(pn, head=0, frames=1))


def test_recorded_attention_is_on_the_weights_scale(pn: Recording) -> None:
    """A recording keeps only the strongest cells: the colour scale is 0..1, not min..max of them."""
    fig = predinet_figure(pn, step=0)
    bars = [ax for ax in fig.axes if ax.get_label() == "<colorbar>"]
    assert len(bars) == 2
    for bar in bars:
        assert bar.get_ylim() == (0.0, 1.0)


def test_predinet_figure_names_the_attended_objects(pn: Recording) -> None:
    fig = predinet_figure(pn, step=0)
    titles = [ax.get_title() for ax in fig.axes if ax.get_title()]
    assert "head 0 · E1 = sword (0,6) 0.60" in titles
    assert "head 0 · E2 = enemy (9,1) 0.70" in titles
    assert "head 1 · E2 = agent (2,6) 0.70" in titles
    assert "head 0: D(sword, enemy) = [-0.10 +0.00 +0.10]" in fig.get_supxlabel()
    assert png_size(figure_bytes(fig, "png", 50)) == (290, 290)


def test_r_vectors_and_relations_figures(pn: Recording) -> None:
    fig = r_vectors_figure(pn)
    assert png_size(figure_bytes(fig, "png", 50)) == (
        400,
        210,
    )  # 8.0 x (1.0 + 1.6 * 2 heads) inches
    fig = relations_figure(pn, threshold="quantile:0.5")
    per_j = parse_threshold("quantile:0.5").per_relation(pn.relations)
    titles = [ax.get_title() for ax in fig.axes if ax.get_title()]
    for j in range(J):
        values = pn.relations.loc[pn.relations["j"] == j, "value"].abs()
        kept = int((values > per_j[j]).sum())
        assert f"r({j}): threshold ±{per_j[j]:.3g}, {kept} of 10 kept" in titles
    assert png_size(figure_bytes(fig, "png", 50)) == (
        410,
        160,
    )  # (2.6 * 3 relations + 0.4) x (2.2 + 1.0)


def test_episode_strip_and_frames(pn: Recording) -> None:
    tr = trace_from_recording(pn)
    assert ep_mod.choose_states(tr, None, 3) == [0, 2, 5]
    assert ep_mod.choose_states(tr, (1, 3), None) == [1, 2, 3]
    assert ep_mod.head_pairs(tr, 0, tr.heads) == [(0, 6, 91), (1, 88, 26)]
    assert ep_mod.head_pairs(tr, 5, tr.heads) == []  # the final state was never acted in
    fig = ep_mod.episode_figure(pn, frames=4)
    assert png_size(figure_bytes(fig, "png", 50)) == (415, 165)  # (2.0 * 4 + 0.3) x (2.4 + 0.9)
    frames = ep_mod.episode_frames(tr, every=2)
    assert len(frames) == 3 and frames[0].shape == (368, 320, 3)
    assert not np.array_equal(frames[0], frames[1])  # the agent moved


def test_route_dots_the_teleport_jump(pn: Recording) -> None:
    from matplotlib.figure import Figure

    from neurosym.viz.grid import draw_route

    ax = Figure().add_subplot()
    lines = draw_route(ax, trace_from_recording(pn).agent_path)
    segments = lines.get_segments()
    assert len(segments) == 5
    styles = lines.get_linestyles()
    assert styles[0][1] is None and styles[4][1] is None  # plain steps are solid
    assert styles[3][1] is not None  # (2,9) -> (8,8) is a jump


# ---------------------------------------------------------------- bytes


@pytest.mark.expensive
def test_outputs_are_byte_identical_and_carry_no_timestamps(
    pn: Recording, mh: Recording, tmp_path
) -> None:
    for make in (lambda: predinet_figure(pn, step=1), lambda: mhdpa_figure(mh, step=0)):
        a, b = make(), make()
        for fmt in ("png", "svg"):
            assert figure_bytes(a, fmt, 40) == figure_bytes(b, fmt, 40)
    svg = figure_bytes(predinet_figure(pn, step=1), "svg", 40).decode()
    assert "<dc:date>" not in svg and "Matplotlib" not in svg
    png = figure_bytes(predinet_figure(pn, step=1), "png", 40)
    assert b"tEXt" not in png and b"tIME" not in png
    tr = trace_from_recording(pn)
    assert gif_bytes(ep_mod.episode_frames(tr), 4) == gif_bytes(ep_mod.episode_frames(tr), 4)
    out = save_figure(r_vectors_figure(pn), tmp_path / "r.svg")
    assert out.read_bytes().startswith(b"<?xml") and [p.name for p in tmp_path.iterdir()] == [
        "r.svg"
    ]


# ---------------------------------------------------------------- errors


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (
            lambda pn, mh: mhdpa_figure(pn),
            r"an MHDPA attention plot needs an MHDPA agent, but rgw2-predinet.pt is a PrediNet agent",
        ),
        (
            lambda pn, mh: predinet_figure(mh),
            r"a PrediNet attention plot needs a PrediNet agent, but rgw2-mhdpa.pt is an MHDPA agent",
        ),
        (lambda pn, mh: r_vectors_figure(mh), r"an R-vector plot needs a PrediNet agent"),
        (
            lambda pn, mh: predinet_figure(pn, step=5),
            r"--step 5 is out of range: episode 0 has steps 0..4",
        ),
        (
            lambda pn, mh: predinet_figure(pn, head=2),
            r"--head 2 is out of range: this agent has heads 0..1",
        ),
        (
            lambda pn, mh: mhdpa_figure(mh, object="key(red)"),
            r"--object key\(red\): no key\(red\) on the grid at step 0",
        ),
        (
            lambda pn, mh: mhdpa_figure(mh, object="wall"),
            r"--object wall: 12 cells hold wall at step 0; pick one with --cell",
        ),
        (lambda pn, mh: mhdpa_figure(mh, cell=(10, 0)), r"--cell 10,0 is outside the 10 x 10 grid"),
        (lambda pn, mh: relations_figure(pn, threshold="top:3"), r"bad threshold 'top:3'"),
        (
            lambda pn, mh: ep_mod.episode_figure(pn, steps=(9, None)),
            r"--steps starts at 9, but episode 0 has states 0..5",
        ),
        (lambda pn, mh: ep_mod.parse_steps("3-4"), r"--steps '3-4': expected START:STOP"),
        (
            lambda pn, mh: save_figure(predinet_figure(pn), "out.jpg"),
            r"the file name must end in .png or .svg",
        ),
        (
            lambda pn, mh: mhdpa_figure(object()),
            r"cannot plot a object: pass a Recording, an Agent",
        ),
    ],
)
def test_bad_requests_are_one_line_errors(pn: Recording, mh: Recording, call, message: str) -> None:
    with pytest.raises(ConfigError, match=message) as info:
        call(pn, mh)
    assert "\n" not in str(info.value)
    assert re.search(message, str(info.value))


def test_names_from_files_are_drawn_as_written(pn: Recording) -> None:
    """``$...$`` in a checkpoint's name is text, not mathtext (``$\\frac$`` was a parse error)."""
    import dataclasses

    from neurosym.viz.probes import probes_figure

    hostile = dataclasses.replace(pn, meta={**pn.meta, "checkpoint": "runs/$\\frac$.pt"})
    for fig in (
        predinet_figure(hostile, step=0),
        r_vectors_figure(hostile),
        ep_mod.episode_figure(hostile, frames=2),
        relations_figure(hostile),
    ):
        assert "$\\frac$.pt" in fig.get_suptitle()
        assert figure_bytes(fig, "png", 30)[:4] == b"\x89PNG"
    assert ep_mod.episode_frames(ep_mod.load_trace(hostile, episode=0), steps=(0, 1))
    table = pd.DataFrame(
        {"head": [0], "relation": ["all"], "predicate": ["$\\frac$"], "accuracy": [0.9],
         "control": [0.5], "selectivity": [0.4], "untrained_selectivity": [0.0]}
    )  # fmt: skip
    assert figure_bytes(probes_figure(table), "png", 30)[:4] == b"\x89PNG"
