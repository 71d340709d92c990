"""experiments/map_copies.py: a map's eight symmetric copies, each with the map's optimal return."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

from neurosym.envs.rgw_maps import load_map

REPO = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("map_copies", REPO / "experiments" / "map_copies.py")
map_copies = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(map_copies)


def test_eight_distinct_copies_of_rgw2_with_its_cells() -> None:
    texts = map_copies.copies("rgw2")
    assert len(texts) == 8 and len(set(texts)) == 8  # rgw2 has no symmetry of its own
    assert texts[0] == load_map("rgw2").text()
    first = load_map(texts[0])
    for text in texts:
        grid = load_map(text)  # each one parses
        assert sorted(grid.cells.tolist()) == sorted(first.cells.tolist())
    # copy 1 is a quarter turn counter-clockwise: the top row's last cell is the left column's top
    assert texts[1].splitlines()[0][0] == texts[0].splitlines()[0][-1]
    # copy 4 is the mirror: every row reversed
    assert texts[4].splitlines() == [row[::-1] for row in texts[0].splitlines()]


def test_the_bench_plays_every_copy_at_the_same_optimum(capsys: pytest.CaptureFixture) -> None:
    path = str(REPO / "checkpoints" / "rgw2-predinet.pt")
    assert map_copies.main([path, "--map", "rgw2"]) == 0
    row = json.loads(capsys.readouterr().out)
    assert row["checkpoint"] == path and row["map"] == "rgw2"
    assert row["optimal"] == [10.7] * 8  # the same best route, turned
    assert row["returns"][0] == pytest.approx(10.7)  # the rgw2 agent on rgw2 itself
    assert row["at_optimum"] + row["short"] + row["unfinished"] == 8
    assert row["at_optimum"] == sum(r >= 10.7 - 1e-6 for r in row["returns"])
