"""Recorded episodes as pandas tables: the hand-over between the recorder and the fact writer.

A :class:`Recording` is what :func:`neurosym.record.recorder.record` returns and what
:func:`neurosym.facts.tables.extract_facts` reads. Its tables and their columns are
fixed in ``docs/interfaces.md`` ("Recording"); this module owns that schema (the tables
the fact writer copies column for column into a predicate's facts take their columns
from that predicate's declaration in :mod:`neurosym.facts.schema`), brings
hand-made tables to it (so tests and notebooks can build recordings directly) and
round-trips a recording through one Parquet file per table plus ``meta.json``.

Time convention: ``t`` indexes states. State 0 follows the reset; the action of
``steps`` row t leads from state t to state t+1, and the events of that transition
carry time t. An episode of S steps has states 0..S; model outputs (attends,
relations, attention, r_vectors) exist for the states 0..S-1 the agent acted in.
Heads and relations are numbered from 0; ``arg`` is 1 or 2 (the argmax of a1 or a2).
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from neurosym.atomic import atomic_write, file_kind, make_folder
from neurosym.errors import ConfigError
from neurosym.facts.schema import SCHEMA as PREDICATES


def _arguments(predicate: str, *extra: tuple[str, str]) -> tuple[tuple[str, str], ...]:
    """The columns of a table the fact writer copies into ``predicate``'s facts: its arguments'
    columns and dtypes (:mod:`neurosym.facts.schema`; atoms and terms are "str"), then ``extra``."""
    return tuple((a.column, a.dtype) for a in PREDICATES[predicate].args) + extra


# table -> ordered (column, dtype); "str" columns hold Prolog text (atoms or terms).
SCHEMA: dict[str, tuple[tuple[str, str], ...]] = {
    "episodes": _arguments("episode", ("seed", "int64")),
    "steps": _arguments("step"),
    "positions": (
        ("episode", "int64"),
        ("t", "int64"),
        ("object", "str"),
        ("type", "str"),
        ("row", "int64"),
        ("col", "int64"),
    ),
    "holding": _arguments("holding"),
    "terrain": _arguments("terrain"),
    "grids": _arguments("grid"),
    "optimal": _arguments("optimal_visits"),
    "events": _arguments("event"),
    "attends": _arguments("attends"),
    "relations": _arguments("relation"),
    "attention": _arguments(
        "attention",
        ("query_row", "int64"),
        ("query_col", "int64"),
        ("key_row", "int64"),
        ("key_col", "int64"),
    ),
    "facing": _arguments("facing"),
    "doors": _arguments("door_state"),
    "missions": _arguments("mission"),
    "r_vectors": (
        ("episode", "int64"),
        ("t", "int64"),
        ("head", "int64"),
        ("j", "int64"),
        ("value", "float64"),
    ),
}

META_KEYS = (
    "checkpoint", "env", "module", "heads", "relations", "seed", "actions", "created", "version",
)  # fmt: skip

OPTIONAL_TABLES = ("terrain", "grids", "facing", "doors", "missions", "optimal")
"""tables that recordings of older versions lack: they load as empty tables (RGW and Box-World
recordings have no rows in Minigrid's facing, doors and missions; only RGW ones in optimal)"""

MAX_COUNT = 1024
"""the most heads or relations a recording's meta may give (they size the tables readers draw)"""

_FORMAT = "neurosym-recording"
_FORMAT_VERSION = 1


def empty_table(name: str) -> pd.DataFrame:
    """An empty table with the schema's columns and dtypes."""
    return pd.DataFrame({c: pd.Series([], dtype=d) for c, d in SCHEMA[name]})


def conform(name: str, df: pd.DataFrame | None) -> pd.DataFrame:
    """Return ``df`` with exactly the schema's columns, in order, with the schema's dtypes.

    Raises ConfigError naming the table and the missing columns, so that a
    hand-built table with a typo fails here rather than deep inside the writer.
    """
    if df is None:
        return empty_table(name)
    columns = [c for c, _ in SCHEMA[name]]
    missing = [c for c in columns if c not in df.columns]
    if missing:
        raise ConfigError(
            f"recording table {name!r} lacks column(s) {', '.join(missing)}; "
            f"expected {', '.join(columns)}"
        )
    out = df.loc[:, columns]
    dtypes = {c: d for c, d in SCHEMA[name] if str(out[c].dtype) != d}
    if dtypes:
        try:
            out = out.astype(dtypes)
        except (TypeError, ValueError, OverflowError) as exc:
            wanted = ", ".join(f"{c} {d}" for c, d in dtypes.items())
            raise ConfigError(
                f"recording table {name!r} has columns of the wrong type (expected {wanted}: "
                f"{str(exc).splitlines()[0] if str(exc) else type(exc).__name__})"
            ) from None
    return out.reset_index(drop=True)


@dataclass
class Recording:
    """Episodes recorded from one agent: pandas tables per docs/interfaces.md plus ``meta``.

    Missing tables default to empty ones (an MHDPA recording has no ``relations``,
    a PrediNet one no ``attention``; a hand-made one may have no ``terrain``
    (the cells of each episode's map that hold terrain, read after the reset)
    or ``grids`` (each episode's map size) or ``optimal`` (each RGW level's optimal
    visit order, Prolog list text)). Tables are brought to the schema on
    construction, so column order and dtypes are always the documented ones.
    """

    episodes: pd.DataFrame = field(default_factory=lambda: empty_table("episodes"))
    steps: pd.DataFrame = field(default_factory=lambda: empty_table("steps"))
    positions: pd.DataFrame = field(default_factory=lambda: empty_table("positions"))
    holding: pd.DataFrame = field(default_factory=lambda: empty_table("holding"))
    terrain: pd.DataFrame = field(default_factory=lambda: empty_table("terrain"))
    grids: pd.DataFrame = field(default_factory=lambda: empty_table("grids"))
    optimal: pd.DataFrame = field(default_factory=lambda: empty_table("optimal"))
    events: pd.DataFrame = field(default_factory=lambda: empty_table("events"))
    attends: pd.DataFrame = field(default_factory=lambda: empty_table("attends"))
    relations: pd.DataFrame = field(default_factory=lambda: empty_table("relations"))
    attention: pd.DataFrame = field(default_factory=lambda: empty_table("attention"))
    facing: pd.DataFrame = field(default_factory=lambda: empty_table("facing"))
    doors: pd.DataFrame = field(default_factory=lambda: empty_table("doors"))
    missions: pd.DataFrame = field(default_factory=lambda: empty_table("missions"))
    r_vectors: pd.DataFrame = field(default_factory=lambda: empty_table("r_vectors"))
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for name in SCHEMA:
            setattr(self, name, conform(name, getattr(self, name)))
        self.meta = dict(self.meta)

    @property
    def tables(self) -> dict[str, pd.DataFrame]:
        """The tables by name, in schema order."""
        return {name: getattr(self, name) for name in SCHEMA}

    @property
    def n_episodes(self) -> int:
        return len(self.episodes)

    @property
    def n_steps(self) -> int:
        return int(self.episodes["steps"].sum())

    def save(self, directory: str | os.PathLike[str]) -> Path:
        """Write one Parquet file per table and ``meta.json`` into ``directory``.

        Each file is written to a temporary name and renamed into place, so a
        reader never sees a half-written table. A NaN or infinity is refused
        first (:func:`check_finite`): :meth:`load` would refuse the recording.
        """
        check_finite(self.tables)
        out = make_folder(directory)
        for name, df in self.tables.items():
            atomic_write(out / f"{name}.parquet", lambda p, df=df: df.to_parquet(p, index=False))
        meta = {"format": _FORMAT, "format_version": _FORMAT_VERSION, "meta": self.meta}
        text = json.dumps(meta, indent=2, sort_keys=True, default=str) + "\n"
        atomic_write(out / "meta.json", lambda p: Path(p).write_text(text))
        return out

    @classmethod
    def load(cls, directory: str | os.PathLike[str]) -> Recording:
        """Read a recording written by :meth:`save`; ConfigError (one line) if it is not one.

        A folder published by ``neurosym extract`` is a link that the next run
        re-points; it is resolved once, so every table comes from the same run.
        Refused, naming what is wrong: a table file that is missing or not a
        regular file, a non-finite number (NaN or inf: JSON, the page's data,
        and Prolog facts have none), ``heads`` or ``relations`` in meta.json
        that are not whole numbers within :data:`MAX_COUNT`.
        """
        src = Path(directory)
        meta_path = src.resolve() / "meta.json"
        head = _read_meta(src, meta_path)
        meta = head.get("meta", {})
        if not isinstance(meta, dict):
            raise ConfigError(
                f"{src} is not a neurosym recording (its meta.json 'meta' is not an object)"
            )
        check_meta(meta, f"{src}/meta.json")
        tables: dict[str, pd.DataFrame] = {}
        for name in SCHEMA:
            path = meta_path.parent / f"{name}.parquet"
            if name in OPTIONAL_TABLES and not os.path.lexists(path):
                tables[name] = empty_table(name)
                continue
            tables[name] = _read_table(src, path)
        try:
            rec = cls(**tables, meta=meta)
            check_finite(rec.tables)
        except ConfigError as exc:
            raise ConfigError(f"{src}: {exc}") from None
        return rec

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Recording):
            return NotImplemented
        if self.meta != other.meta:
            return False
        return all(
            getattr(self, f.name).equals(getattr(other, f.name))
            for f in fields(self)
            if f.name in SCHEMA
        )


_WRITTEN_BY = "a recording folder written by `neurosym extract` (its recording/ folder, or --out)"


def _read_meta(src: Path, meta_path: Path) -> dict[str, Any]:
    """meta.json's object, checked to be a recording's; ConfigError naming what is wrong."""
    kind = file_kind(meta_path)
    if kind is not None:
        raise ConfigError(
            f"{src} is not a neurosym recording: its meta.json is {kind}, not a regular file; "
            f"pass {_WRITTEN_BY}"
        )
    if not meta_path.exists():
        raise ConfigError(
            f"{src} is not a neurosym recording: it has no meta.json; pass {_WRITTEN_BY}"
        )
    try:
        head = json.loads(meta_path.read_text())
    except (OSError, ValueError) as exc:
        why = exc.strerror if isinstance(exc, OSError) and exc.strerror else exc
        raise ConfigError(
            f"{src} is not a neurosym recording (cannot read {meta_path.name}: {why})"
        ) from None
    if not isinstance(head, dict) or head.get("format") != _FORMAT:
        raise ConfigError(
            f"{src} is not a neurosym recording ({meta_path.name} has no format tag {_FORMAT!r})"
        )
    return head


def _read_table(src: Path, path: Path) -> pd.DataFrame:
    """One table's Parquet file; ConfigError saying what is wrong (missing, not a file, damaged)."""
    shown = src / path.name
    kind = file_kind(path)
    if kind is not None:
        raise ConfigError(
            f"{shown} is {kind}, not a regular file: a recording holds each table as a Parquet "
            f"file; pass {_WRITTEN_BY}"
        )
    if not path.exists():
        raise ConfigError(
            f"{src} is not a complete recording: its table {path.name} is missing; "
            f"pass {_WRITTEN_BY}"
        )
    try:
        return pd.read_parquet(path)
    except (OSError, ValueError) as exc:
        why = exc.strerror if isinstance(exc, OSError) and exc.strerror else exc
        raise ConfigError(
            f"cannot read {shown}: {why} (not a Parquet table written by neurosym)"
        ) from None


def check_meta(meta: dict[str, Any], where: str) -> None:
    """Refuse ``heads`` or ``relations`` that are not whole numbers from 0 to MAX_COUNT.

    Readers size their work by them (a range of heads to draw); ``where``
    names the file they came from in the one-line ConfigError.
    """
    for key in ("heads", "relations"):
        value = meta.get(key)
        if value is None:
            continue
        if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= MAX_COUNT:
            raise ConfigError(
                f"{where} gives {key} {value!r}; expected a whole number from 0 to {MAX_COUNT} "
                f"(the checkpoint's {key} count)"
            )


def check_finite(tables: dict[str, pd.DataFrame]) -> None:
    """Refuse a NaN or infinity in any float column, naming the table, column and first row.

    A recording's numbers come from the env and the network and are finite;
    NaN/inf have no JSON (the report page's data) or Prolog fact spelling.
    """
    for name, df in tables.items():
        for column, dtype in SCHEMA[name]:
            if dtype != "float64" or df.empty:
                continue
            values = df[column].to_numpy()
            bad = ~np.isfinite(values)
            if bad.any():
                row = int(np.flatnonzero(bad)[0])
                raise ConfigError(
                    f"recording table {name!r} has {float(values[row])!r} in column {column!r} (row {row}); "
                    "a recording holds finite numbers only (NaN and inf have no JSON or Prolog form)"
                )
