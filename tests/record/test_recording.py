"""Recording: schema conformance and the Parquet round trip."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from neurosym.errors import ConfigError
from neurosym.record.recording import SCHEMA, Recording


def small_recording() -> Recording:
    """Two episodes by hand, with a compound entity name and a float that needs full precision."""
    return Recording(
        episodes=pd.DataFrame(
            {
                "episode": [0, 1],
                "steps": [2, 1],
                "return": [0.9, -1.0],
                "outcome": ["terminal", "pit"],
                "seed": [7, 8],
            }
        ),
        steps=pd.DataFrame(
            {
                "episode": [0, 0, 1],
                "t": [0, 1, 0],
                "action": ["right", "down", "left"],
                "reward": [-0.1, 1.0, -1.0],
            }
        ),
        positions=pd.DataFrame(
            {
                "episode": [0, 0, 0],
                "t": [0, 1, 2],
                "object": ["agent", "agent", "agent"],
                "type": ["agent", "agent", "agent"],
                "row": [0, 0, 1],
                "col": [0, 1, 1],
            }
        ),
        holding=pd.DataFrame({"episode": [0], "t": [2], "item": ["key(red)"]}),
        events=pd.DataFrame(
            {"episode": [0, 1], "t": [1, 0], "event": ["got(key(red))", "fell(pit)"]}
        ),
        relations=pd.DataFrame(
            {
                "episode": [0],
                "t": [0],
                "head": [1],
                "j": [3],
                "a": ["sword"],
                "b": ["lock(blue)"],
                "value": [0.1 + 0.2],
            }
        ),
        meta={"env": "rgw2", "module": "predinet", "heads": 4, "relations": 8, "seed": 7},
    )


def test_missing_tables_are_empty_with_schema_columns() -> None:
    rec = Recording()
    for name, cols in SCHEMA.items():
        table = getattr(rec, name)
        assert list(table.columns) == [c for c, _ in cols]
        assert [str(t) for t in table.dtypes] == [d for _, d in cols]
        assert table.empty


def test_tables_are_brought_to_schema_order_and_dtypes() -> None:
    steps = pd.DataFrame(
        {
            "reward": [1],
            "action": ["up"],
            "t": [np.int32(0)],
            "episode": [np.int16(3)],
            "extra": [1],
        }
    )
    rec = Recording(steps=steps)
    assert list(rec.steps.columns) == ["episode", "t", "action", "reward"]
    assert rec.steps["reward"].dtype == np.float64
    assert rec.steps["episode"].dtype == np.int64


def test_missing_column_is_a_one_line_error() -> None:
    with pytest.raises(
        ConfigError,
        match=r"recording table 'events' lacks column\(s\) event; expected episode, t, event",
    ):
        Recording(events=pd.DataFrame({"episode": [0], "t": [0]}))


def test_parquet_round_trip(tmp_path: Path) -> None:
    rec = small_recording()
    rec.save(tmp_path / "rec")
    back = Recording.load(tmp_path / "rec")
    assert back == rec
    assert back.relations["value"].iloc[0] == 0.1 + 0.2  # full precision
    assert back.meta == rec.meta
    assert sorted(p.name for p in (tmp_path / "rec").iterdir()) == sorted(
        [f"{n}.parquet" for n in SCHEMA] + ["meta.json"]
    )


def test_save_overwrites_and_leaves_no_temp_files(tmp_path: Path) -> None:
    rec = small_recording()
    rec.save(tmp_path)
    rec.save(tmp_path)
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


def test_load_refuses_a_directory_that_is_not_a_recording(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="is not a neurosym recording"):
        Recording.load(tmp_path)
    (tmp_path / "meta.json").write_text('{"format": "something-else"}')
    with pytest.raises(ConfigError, match="no format tag"):
        Recording.load(tmp_path)


def test_counts() -> None:
    rec = small_recording()
    assert rec.n_episodes == 2
    assert rec.n_steps == 3


def test_load_names_the_folder_of_a_damaged_table_or_meta(tmp_path: Path) -> None:
    rec = tmp_path / "rec"
    small_recording().save(rec)
    pd.DataFrame({"x": [1]}).to_parquet(rec / "steps.parquet")
    with pytest.raises(ConfigError) as err:
        Recording.load(rec)
    assert str(err.value) == (
        f"{rec}: recording table 'steps' lacks column(s) episode, t, action, reward; "
        "expected episode, t, action, reward"
    )
    steps = small_recording().steps.assign(episode=["a", "b", "c"])
    steps.to_parquet(rec / "steps.parquet")
    with pytest.raises(ConfigError) as err:
        Recording.load(rec)
    assert str(err.value).startswith(
        f"{rec}: recording table 'steps' has columns of the wrong type (expected episode int64: "
    )
    small_recording().save(rec)
    (rec / "meta.json").write_text('{"format": "neurosym-recording", "meta": 5}')
    with pytest.raises(ConfigError) as err:
        Recording.load(rec)
    assert (
        str(err.value)
        == f"{rec} is not a neurosym recording (its meta.json 'meta' is not an object)"
    )


WRITTEN_BY = (
    "pass a recording folder written by `neurosym extract` (its recording/ folder, or --out)"
)


def test_load_says_what_is_wrong_with_a_table_file(tmp_path: Path) -> None:
    """A table that is missing or not a regular file (a FIFO would block the reader) is named."""
    rec = tmp_path / "rec"
    small_recording().save(rec)
    (rec / "steps.parquet").unlink()
    with pytest.raises(ConfigError) as err:
        Recording.load(rec)
    assert str(err.value) == (
        f"{rec} is not a complete recording: its table steps.parquet is missing; {WRITTEN_BY}"
    )
    os.mkfifo(rec / "steps.parquet")
    with pytest.raises(ConfigError) as err:
        Recording.load(rec)
    assert str(err.value) == (
        f"{rec / 'steps.parquet'} is a FIFO, not a regular file: a recording holds each table "
        f"as a Parquet file; {WRITTEN_BY}"
    )
    (rec / "steps.parquet").unlink()
    (rec / "meta.json").unlink()
    os.mkfifo(rec / "meta.json")
    with pytest.raises(ConfigError) as err:
        Recording.load(rec)
    assert str(err.value) == (
        f"{rec} is not a neurosym recording: its meta.json is a FIFO, not a regular file; "
        f"{WRITTEN_BY}"
    )


@pytest.mark.parametrize(
    ("table", "column", "value"),
    [("relations", "value", math.nan), ("steps", "reward", -math.inf)],
)
def test_load_refuses_numbers_that_are_not_finite(
    tmp_path: Path, table: str, column: str, value: float
) -> None:
    """NaN/inf would reach the report page's JSON ("Out of range float values") or the KB."""
    rec = small_recording()
    df = getattr(rec, table).copy()
    df.loc[len(df) - 1, column] = value
    rec.save(tmp_path / "rec")
    df.to_parquet(tmp_path / "rec" / f"{table}.parquet")
    message = (
        f"recording table {table!r} has {value!r} in column {column!r} (row {len(df) - 1}); "
        "a recording holds finite numbers only (NaN and inf have no JSON or Prolog form)"
    )
    with pytest.raises(ConfigError) as err:
        Recording.load(tmp_path / "rec")
    assert str(err.value) == f"{tmp_path / 'rec'}: {message}"
    with pytest.raises(ConfigError) as err:  # nor is one written
        Recording(**{**rec.tables, table: df}, meta=rec.meta).save(tmp_path / "bad")
    assert str(err.value) == message and not (tmp_path / "bad").exists()


@pytest.mark.parametrize("heads", ["four", 2.5, True, -1, 10**9])
def test_load_refuses_heads_that_are_not_a_count(tmp_path: Path, heads: object) -> None:
    rec = small_recording()
    Recording(**rec.tables, meta={**rec.meta, "heads": heads}).save(tmp_path / "rec")
    with pytest.raises(ConfigError) as err:
        Recording.load(tmp_path / "rec")
    assert str(err.value) == (
        f"{tmp_path / 'rec'}/meta.json gives heads {heads!r}; expected a whole number from 0 "
        "to 1024 (the checkpoint's heads count)"
    )
