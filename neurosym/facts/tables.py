"""Ground facts from a Recording: the tables behind a Prolog knowledge base.

:func:`extract_facts` turns a :class:`~neurosym.record.recording.Recording` into a
:class:`FactSet`, one pandas table per predicate of the schema in docs/design.md::

    kb_meta(Key, Value)            object(Id, Type)
    episode(E, Steps, Return, Outcome)
    grid(E, Rows, Cols)            terrain(E, Type, Row, Col)
    optimal_visits(E, Order)
    step(E, T, Action, Reward)     at(E, T, Id, Row, Col)
    holding(E, T, Item)            event(E, T, Event)
    facing(E, T, Dir)              door_state(E, T, Id, State)     mission(E, Text)
    attends(E, T, Head, Arg, Entity, Row, Col, Weight)
    relation(E, T, Head, J, A, B, Value)
    holds(E, T, r(J), A, B)        threshold(J, Value)
    attention(E, T, Head, Query, Key, Weight)

Choices the schema leaves open, fixed here:

* Heads and relations are numbered from 0, as in the tensors; ``Arg`` is 1 or 2.
* ``holds/5`` keeps a relation row when ``|value| > threshold(J)`` and orients it so
  that the value is positive: D_j(A, B) = -D_j(B, A), so a row with value -0.8 for
  (sword, enemy) becomes ``holds(E, T, r(J), enemy, sword)``. Heads that attend the
  same oriented pair at one step give one fact (holds/5 has no head argument).
* The ``holds`` table keeps J as an int column ``j``; it is written as ``r(J)``.
* ``kb_meta`` has the recording's meta keys plus ``threshold`` (the spec used), then
  one ``kb_meta(env_option(Name), Value)`` per option the env was made with
  (``kb_meta(env_option(num_mountains), 12)``; ``none`` for None), so a KB says
  which levels it recorded.
* Entity, event, item and type columns hold Prolog text (``key(red)``,
  ``picked(sword)``) and are written as terms; everything else textual is an atom.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from neurosym.atomic import atomic_write, make_folder
from neurosym.errors import ConfigError
from neurosym.facts.schema import TRACE, comments, group, indicators
from neurosym.facts.thresholds import Threshold, parse_threshold
from neurosym.record.recording import META_KEYS, Recording
from neurosym.terms import Term

PREDICATES: dict[str, tuple[str, ...]] = {p.name: p.columns for p in group(TRACE)}
"""predicate -> argument columns, in argument order (declared in :mod:`neurosym.facts.schema`)"""

TERM_COLUMNS: dict[str, tuple[str, ...]] = {
    p.name: p.term_columns for p in group(TRACE) if p.term_columns
}
"""predicate -> columns holding Prolog term text (written as terms, not quoted atoms)"""

DEFAULT_THRESHOLD = "quantile:0.9"


def _frame(name: str, data: Mapping[str, Any]) -> pd.DataFrame:
    df = pd.DataFrame({c: data[c] for c in PREDICATES[name]})
    return df.reset_index(drop=True)


@dataclass
class FactSet:
    """Fact tables, one per predicate (columns = arguments in order), plus the threshold used.

    Build one with :func:`extract_facts`; write it with :meth:`to_prolog` or
    :meth:`to_parquet`.
    """

    tables: dict[str, pd.DataFrame]
    threshold: Threshold
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        unknown = set(self.tables) - set(PREDICATES)
        if unknown:
            raise ValueError(f"unknown predicate table(s): {sorted(unknown)}")
        for name, cols in PREDICATES.items():
            if name not in self.tables:
                self.tables[name] = pd.DataFrame({c: [] for c in cols})

    def __getitem__(self, predicate: str) -> pd.DataFrame:
        return self.tables[predicate]

    def counts(self) -> dict[str, int]:
        """Number of facts per predicate, in schema order."""
        return {name: len(self.tables[name]) for name in PREDICATES}

    @property
    def n_facts(self) -> int:
        return sum(self.counts().values())

    def strongest_relations(self, n: int = 5) -> pd.DataFrame:
        """Oriented pairs of object types most often related above threshold.

        Only types of the map's named objects (``object/2``), the agent and
        Box-World's held key count, two different ones; background cells (empty,
        wall, terrain) do not. When
        the KB lists no objects, every entity counts. Columns: j, a, b, held
        (holds facts: states at which r(j)(a, b) held), mean_value (mean of the
        positive oriented values that held). Sorted by held, then mean_value.
        """
        rel = self.tables["relation"]
        if rel.empty:
            return pd.DataFrame({"j": [], "a": [], "b": [], "held": [], "mean_value": []})
        oriented = orient(rel)
        keep = self.threshold.keep(oriented, self.thresholds())
        keep &= (oriented["a"] != oriented["b"]).to_numpy()
        types = self.tables["object"]["type"]
        if len(types):
            named = set(types) | {"agent"}

            def is_named(col: pd.Series) -> np.ndarray:  # Box-World's held key counts too
                return (col.isin(named) | col.str.startswith("held(")).to_numpy()

            keep &= is_named(oriented["a"]) & is_named(oriented["b"])
        kept = oriented.loc[keep]
        per_step = (
            kept.groupby(["episode", "t", "j", "a", "b"], sort=False)["value"].max().reset_index()
        )
        table = (
            per_step.groupby(["j", "a", "b"])["value"]
            .agg(held="size", mean_value="mean")
            .reset_index()
            .sort_values(["held", "mean_value", "j"], ascending=[False, False, True], kind="stable")
        )
        return table.head(n).reset_index(drop=True)

    def thresholds(self) -> pd.Series:
        """Threshold per relation j, as written in ``threshold/2``."""
        thr = self.tables["threshold"]
        return pd.Series(
            thr["value"].to_numpy(dtype="float64"),
            index=pd.Index(thr["j"].astype("int64"), name="j"),
        )

    def summary(self) -> str:
        """A few lines for people: episodes and returns, facts per predicate, thresholds."""
        ep = self.tables["episode"]
        lines = []
        if len(ep):
            outcomes = ", ".join(
                f"{k} {v}" for k, v in ep["outcome"].value_counts().sort_index().items()
            )
            lines.append(
                f"{len(ep)} episodes, {int(ep['steps'].sum())} steps; return mean "
                f"{ep['return'].mean():.3f} (min {ep['return'].min():.3f}, max {ep['return'].max():.3f}); "
                f"outcomes: {outcomes}"
            )
        else:
            lines.append("0 episodes")
        lines.append(
            "facts: "
            + ", ".join(f"{k} {v}" for k, v in self.counts().items() if v)
            + f" ({self.n_facts} in all)"
        )
        thr = self.thresholds()
        if len(thr):
            lines.append(
                f"thresholds ({self.threshold}): "
                + ", ".join(f"r({j}) {v:.4g}" for j, v in thr.items())
            )
        return "\n".join(lines)

    # ----------------------------------------------------------------- writers

    def prolog_tables(self) -> dict[str, pd.DataFrame]:
        """The tables as the Prolog writer takes them: columns in argument order, r(J) text for holds."""
        out: dict[str, pd.DataFrame] = {}
        for name, df in self.tables.items():
            df = df.loc[:, list(PREDICATES[name])]
            if name == "holds":
                codes, uniques = pd.factorize(df["j"], sort=False)
                text = np.array([f"r({int(u)})" for u in uniques] + [""], dtype=object)
                df = df.assign(j=text[codes])
            out[name] = df
        return out

    def to_prolog(self, path: str | os.PathLike[str], qlf: bool = False) -> Path:
        """Write the KB as one plain Prolog file (atomically); with ``qlf`` also compile ``<stem>.qlf``.

        Every schema predicate is declared dynamic, so rules that ask for facts the
        KB has none of (attention/6 in a PrediNet KB) fail instead of raising, and
        the file loads in plain ``swipl`` without warnings; a PlDoc ``%!`` comment
        above each declaration names its arguments and says what it means (both
        from :mod:`neurosym.facts.schema`). Returns the .pl path.
        """
        from neurosym.facts.prolog_writer import write_prolog

        written = write_prolog(
            Path(path),
            self.prolog_tables(),
            header=self._header(),
            dynamic=predicate_indicators(),
            qlf=qlf,
            term_columns=TERM_COLUMNS,
            comments=comments(PREDICATES),
        )
        return Path(written)

    def to_parquet(self, directory: str | os.PathLike[str]) -> Path:
        """Write one Parquet file per predicate and ``meta.json``, each file atomically."""
        out = make_folder(directory)
        for name, df in self.tables.items():
            if name == "kb_meta":  # atoms, terms and numbers: Parquet needs one type per column
                df = df.assign(key=df["key"].map(str), value=df["value"].map(str))
            atomic_write(out / f"{name}.parquet", lambda p, df=df: df.to_parquet(p, index=False))
        text = (
            json.dumps({"meta": self.meta, "threshold": str(self.threshold)}, indent=2, default=str)
            + "\n"
        )
        atomic_write(out / "meta.json", lambda p: Path(p).write_text(text))
        return out

    def _header(self) -> str:
        meta = ", ".join(f"{k}={self.meta.get(k)}" for k in META_KEYS if k in self.meta)
        return (
            "neurosym knowledge base: facts extracted from recorded episodes.\n"
            f"{meta}\nthreshold={self.threshold}\n"
            "Heads and relations count from 0. The predicates (docs/design.md, \"Facts\"):"
        )


def orient(relations: pd.DataFrame) -> pd.DataFrame:
    """Relation rows oriented so that the value is positive (a and b swapped where it was negative)."""
    value = relations["value"].to_numpy(dtype="float64")
    neg = value < 0
    a = relations["a"].to_numpy(dtype=object)
    b = relations["b"].to_numpy(dtype=object)
    out = relations.copy()
    out["a"] = np.where(neg, b, a)
    out["b"] = np.where(neg, a, b)
    out["value"] = np.abs(value)
    return out


def _objects(positions: pd.DataFrame) -> pd.DataFrame:
    objs = positions.loc[:, ["object", "type"]].drop_duplicates()
    clash = objs["object"].duplicated(keep=False)
    if clash.any():
        bad = objs.loc[clash, "object"].iloc[0]
        raise ConfigError(f"object {bad!r} has more than one type in the recording's positions")
    objs = objs.sort_values("object", kind="stable")
    return _frame("object", {"id": objs["object"], "type": objs["type"]})


def _meta_table(meta: Mapping[str, Any], threshold: Threshold) -> pd.DataFrame:
    keys: list[str | Term] = [k for k in META_KEYS if k in meta and meta[k] is not None]
    values: list[Any] = [meta[k] for k in keys]
    keys.append("threshold")
    values.append(str(threshold))
    options = meta.get("env_kwargs")
    if isinstance(options, Mapping):
        for name in sorted(options, key=str):
            keys.append(Term("env_option", (str(name),)))
            values.append(option_value(options[name]))
    return pd.DataFrame(
        {"key": pd.Series(keys, dtype=object), "value": pd.Series(values, dtype=object)}
    )


def option_value(value: Any) -> str | int | float:
    """An env option's value as kb_meta/2 holds it: numbers as they are, None as ``none``,
    ``true``/``false`` for booleans, anything else (a map path) as the atom of its text."""
    if value is None:
        return "none"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int) or (isinstance(value, float) and math.isfinite(value)):
        return value
    return os.fspath(value) if isinstance(value, os.PathLike) else str(value)


def holds_table(relations: pd.DataFrame, threshold: Threshold, per_j: pd.Series) -> pd.DataFrame:
    """``holds/5`` rows: relation rows above their threshold, oriented, one per (E, T, J, A, B)."""
    if relations.empty:
        return _frame("holds", {c: [] for c in PREDICATES["holds"]})
    keep = threshold.keep(relations, per_j)
    kept = orient(relations.loc[keep])
    kept = kept.drop_duplicates(["episode", "t", "j", "a", "b"]).sort_values(
        ["episode", "t", "j", "a", "b"], kind="stable"
    )
    return _frame("holds", kept)


def extract_facts(
    recording: Recording, threshold: str | float | Threshold = DEFAULT_THRESHOLD
) -> FactSet:
    """Turn a recording into fact tables; ``threshold`` is a spec such as ``quantile:0.9``.

    The thresholds are computed per relation from this recording's own values and
    written into the KB as ``threshold/2``. All work is column operations on the
    recording's tables.
    """
    thr = parse_threshold(threshold)
    rec = recording
    per_j = thr.per_relation(rec.relations)
    ep = rec.episodes
    tables: dict[str, pd.DataFrame] = {
        "kb_meta": _meta_table(rec.meta, thr),
        "object": _objects(rec.positions),
        "episode": _frame(
            "episode",
            {
                "episode": ep["episode"],
                "steps": ep["steps"],
                "return": ep["return"],
                "outcome": ep["outcome"],
            },
        ),
        "grid": _frame("grid", rec.grids),
        "terrain": _frame("terrain", rec.terrain),
        "optimal_visits": _frame("optimal_visits", rec.optimal),
        "step": _frame("step", rec.steps),
        "at": _frame(
            "at",
            {
                **{c: rec.positions[c] for c in ("episode", "t", "row", "col")},
                "id": rec.positions["object"],
            },
        ),
        "holding": _frame("holding", rec.holding),
        "event": _frame("event", rec.events),
        "facing": _frame("facing", rec.facing),
        "door_state": _frame("door_state", rec.doors),
        "mission": _frame("mission", rec.missions),
        "attends": _frame("attends", rec.attends),
        "relation": _frame("relation", rec.relations),
        "holds": holds_table(rec.relations, thr, per_j),
        "threshold": pd.DataFrame(
            {"j": per_j.index.to_numpy(dtype="int64"), "value": per_j.to_numpy()}
        ),
        "attention": _frame("attention", rec.attention),
    }
    return FactSet(tables=tables, threshold=thr, meta=dict(rec.meta))


def predicate_indicators(names: Iterable[str] = PREDICATES) -> list[str]:
    """``name/arity`` for the given schema predicates."""
    return indicators(names)
