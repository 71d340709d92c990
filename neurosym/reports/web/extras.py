"""Optional sections: the folders ``neurosym probe`` and ``neurosym intervene`` write.

``--probe DIR`` reads ``DIR/probes.parquet`` (head, relation, predicate,
accuracy, control, selectivity, ...) and shows each head's most selective
probes; ``--intervene DIR`` reads ``DIR/measures.parquet`` and
``DIR/effects.parquet`` (experiment, measure, value) and shows one row per
experiment. A folder without those files is refused in one line.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pandas as pd

from neurosym.errors import ConfigError

PROBES_PER_HEAD = 5
PROBE_COLUMNS = ("relation", "predicate", "accuracy", "control", "selectivity")


def _read(
    folder: Path, name: str, option: str, command: str, need: tuple[str, ...]
) -> pd.DataFrame:
    path = folder / name
    if not path.is_file():
        raise ConfigError(
            f"{option} {folder} has no {name}: give the folder `neurosym {command} --out` wrote"
        )
    try:
        df = pd.read_parquet(path)
    except (OSError, ValueError) as exc:
        raise ConfigError(f"cannot read {path}: {exc}") from None
    missing = [c for c in need if c not in df.columns]
    if missing:
        raise ConfigError(
            f"{path} lacks column(s) {', '.join(missing)}; expected {', '.join(need)}"
        )
    return df


def _number(value: Any) -> float | None:
    try:
        out = float(value)
    except (TypeError, ValueError):
        return None
    return None if math.isnan(out) else out


def _check_probes(df: pd.DataFrame, path: Path) -> None:
    """Refuse, in one line, a table whose heads are not whole numbers or figures not numbers."""
    heads = df["head"]
    if not pd.api.types.is_integer_dtype(heads):
        bad = next(
            (h for h in heads if isinstance(h, bool) or not isinstance(h, int | float)
             or not math.isfinite(h) or h != int(h)),
            None,
        )  # fmt: skip
        if bad is not None or not pd.api.types.is_numeric_dtype(heads):
            raise ConfigError(
                f"{path}: head {bad!r} is not a whole number; "
                "give the probes.parquet `neurosym probe` wrote"
            )
    for column in ("accuracy", "control", "selectivity"):
        if not pd.api.types.is_numeric_dtype(df[column]) or pd.api.types.is_bool_dtype(df[column]):
            raise ConfigError(
                f"{path}: column {column} holds {df[column].dtype} values, not numbers; "
                "give the probes.parquet `neurosym probe` wrote"
            )


def probe_section(folder: Path) -> dict[str, Any]:
    """Per head, its :data:`PROBES_PER_HEAD` most selective probes (accuracy - control)."""
    df = _read(folder, "probes.parquet", "--probe", "probe", ("head", *PROBE_COLUMNS))
    _check_probes(df, folder / "probes.parquet")
    untrained = "untrained_selectivity" in df.columns
    heads = []
    for head, group in df.groupby("head", sort=True):
        top = group.sort_values(["selectivity", "predicate"], ascending=[False, True]).head(
            PROBES_PER_HEAD
        )
        rows = [
            {
                "relation": str(r["relation"]),
                "predicate": str(r["predicate"]),
                "accuracy": _number(r["accuracy"]),
                "control": _number(r["control"]),
                "selectivity": _number(r["selectivity"]),
                "untrained": _number(r["untrained_selectivity"]) if untrained else None,
            }
            for r in top.to_dict("records")
        ]
        heads.append({"head": int(head), "rows": rows})
    return {"heads": heads, "probes": len(df), "untrained": untrained}


def intervene_section(folder: Path) -> dict[str, Any]:
    """Experiments (rows) x measures (columns): each measure's value and its effect."""
    need = ("experiment", "measure", "value")
    measures = _read(folder, "measures.parquet", "--intervene", "intervene", need)
    effects = _read(folder, "effects.parquet", "--intervene", "intervene", need)
    names = list(dict.fromkeys(str(m) for m in measures["measure"]))
    value = {
        (str(r["experiment"]), str(r["measure"])): r["value"] for r in measures.to_dict("records")
    }
    effect = {
        (str(r["experiment"]), str(r["measure"])): r["value"] for r in effects.to_dict("records")
    }
    rows = []
    for experiment in dict.fromkeys(str(x) for x in measures["experiment"]):
        cells = [
            {
                "value": _number(value.get((experiment, m))),
                "effect": _number(effect.get((experiment, m))),
            }
            for m in names
        ]
        rows.append({"experiment": experiment, "cells": cells})
    return {"measures": names, "rows": rows}
