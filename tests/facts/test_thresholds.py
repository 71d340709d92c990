"""Threshold specs and per-relation thresholds (abs, quantile of |value|, z-score)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from neurosym.errors import ConfigError
from neurosym.facts.thresholds import Threshold, parse_threshold


def rel(values: dict[int, list[float]]) -> pd.DataFrame:
    rows = [(j, v) for j, vs in values.items() for v in vs]
    return pd.DataFrame(rows, columns=["j", "value"])


@pytest.mark.parametrize(
    ("spec", "expected"),
    [
        ("quantile:0.9", Threshold("quantile", 0.9)),
        ("abs:0.5", Threshold("abs", 0.5)),
        ("z:2", Threshold("z", 2.0)),
        ("z:-1", Threshold("z", -1.0)),
        (" ABS:1e-3 ", Threshold("abs", 0.001)),
        (0.25, Threshold("abs", 0.25)),
        (1, Threshold("abs", 1.0)),
    ],
)
def test_parse(spec: object, expected: Threshold) -> None:
    assert parse_threshold(spec) == expected  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("foo", "bad threshold 'foo'"),
        ("quantile", "bad threshold 'quantile'"),
        ("quantile:x", "'x' is not a number"),
        ("quantile:1.5", "quantile:1.5 is outside [0, 1]"),
        ("abs:-1", "abs:-1.0 is negative"),
        ("z:nan", "not a finite number"),
        ("median:0.5", "bad threshold 'median:0.5'"),
        (True, "bad threshold True"),
    ],
)
def test_bad_specs_are_one_line_config_errors(spec: object, message: str) -> None:
    with pytest.raises(ConfigError) as err:
        parse_threshold(spec)  # type: ignore[arg-type]
    text = str(err.value)
    assert message in text
    assert "\n" not in text
    assert "quantile:0.9" in text  # names what would be right


def test_abs_is_the_same_for_every_relation() -> None:
    thr = parse_threshold("abs:0.5").per_relation(rel({0: [1.0, -2.0], 3: [0.1]}))
    assert thr.to_dict() == {0: 0.5, 3: 0.5}


def test_quantile_is_of_the_magnitude_per_relation() -> None:
    values = {0: [-4.0, 1.0, 2.0, 3.0, -0.0], 1: [10.0, -20.0]}
    thr = parse_threshold("quantile:0.5").per_relation(rel(values))
    assert thr[0] == pytest.approx(np.quantile([4, 1, 2, 3, 0], 0.5))
    assert thr[1] == pytest.approx(15.0)


def test_z_is_mean_plus_k_std_of_the_magnitude() -> None:
    values = {2: [1.0, -3.0, 2.0, -6.0]}
    mags = np.abs(values[2])
    thr = parse_threshold("z:1.5").per_relation(rel(values))
    assert thr[2] == pytest.approx(mags.mean() + 1.5 * mags.std())


def test_keep_is_strict_and_uses_each_rows_relation() -> None:
    table = rel({0: [0.5, -0.6, 0.4], 1: [0.5, -0.2]})
    mask = parse_threshold("abs:0.5").keep(table)
    assert mask.tolist() == [False, True, False, False, False]
    per_j = pd.Series({0: 0.1, 1: 0.3})
    assert Threshold("abs", 0.0).keep(table, per_j).tolist() == [True, True, True, True, False]


def test_zero_values_never_kept() -> None:
    table = rel({0: [0.0, 0.0, 1.0]})
    assert parse_threshold("abs:0").keep(table).tolist() == [False, False, True]


def test_empty_relations() -> None:
    empty = pd.DataFrame(
        {"j": pd.Series([], dtype="int64"), "value": pd.Series([], dtype="float64")}
    )
    thr = parse_threshold("quantile:0.9")
    assert thr.per_relation(empty).empty
    assert thr.keep(empty).shape == (0,)
