"""experiments/heads_chance.py: random arguments are named by what lies on their cell."""

from __future__ import annotations

import importlib.util
from pathlib import Path

_spec = importlib.util.spec_from_file_location(
    "heads_chance", Path(__file__).resolve().parents[2] / "experiments" / "heads_chance.py"
)
heads_chance = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(heads_chance)


def test_random_arguments_are_named_by_their_cell(scripted_recording) -> None:

    rec = scripted_recording()
    states = rec.attends[["episode", "t"]].drop_duplicates()
    table = heads_chance.random_attends(rec, draws=7, seed=0)
    assert len(table) == len(states) * 7 * 2
    assert sorted(table["head"].unique()) == list(range(7)) and set(table["arg"]) == {1, 2}
    assert table["row"].between(0, 9).all() and table["col"].between(0, 9).all()  # rgw2: 10 x 10
    cells = rec.positions.set_index(["episode", "t", "row", "col"])["type"]
    keys = list(zip(table["episode"], table["t"], table["row"], table["col"], strict=True))
    on_object = [key in cells.index for key in keys]
    for key, entity, on in zip(keys, table["entity"], on_object, strict=True):
        if on:
            assert entity in set(cells.loc[[key]])
        else:
            assert entity == "empty"
    assert any(on_object) and not all(on_object)
