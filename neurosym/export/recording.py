"""Recorded episodes as pandas tables: the hand-over between the recorder and the fact writer.

A :class:`Recording` is what :func:`neurosym.export.recorder.record` returns and what
:func:`neurosym.export.facts.extract_facts` reads. Its tables and their columns are
fixed in ``docs/interfaces.md`` ("Recording"); this module owns that schema, brings
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

import pandas as pd

from neurosym.atomic import atomic_write, make_folder
from neurosym.errors import ConfigError

# table -> ordered (column, dtype); "str" columns hold Prolog text (atoms or terms).
SCHEMA: dict[str, tuple[tuple[str, str], ...]] = {
    "episodes": (
        ("episode", "int64"),
        ("steps", "int64"),
        ("return", "float64"),
        ("outcome", "str"),
        ("seed", "int64"),
    ),
    "steps": (("episode", "int64"), ("t", "int64"), ("action", "str"), ("reward", "float64")),
    "positions": (
        ("episode", "int64"),
        ("t", "int64"),
        ("object", "str"),
        ("type", "str"),
        ("row", "int64"),
        ("col", "int64"),
    ),
    "holding": (("episode", "int64"), ("t", "int64"), ("item", "str")),
    "terrain": (("episode", "int64"), ("type", "str"), ("row", "int64"), ("col", "int64")),
    "grids": (("episode", "int64"), ("rows", "int64"), ("cols", "int64")),
    "events": (("episode", "int64"), ("t", "int64"), ("event", "str")),
    "attends": (
        ("episode", "int64"),
        ("t", "int64"),
        ("head", "int64"),
        ("arg", "int64"),
        ("entity", "str"),
        ("row", "int64"),
        ("col", "int64"),
        ("weight", "float64"),
    ),
    "relations": (
        ("episode", "int64"),
        ("t", "int64"),
        ("head", "int64"),
        ("j", "int64"),
        ("a", "str"),
        ("b", "str"),
        ("value", "float64"),
    ),
    "attention": (
        ("episode", "int64"),
        ("t", "int64"),
        ("head", "int64"),
        ("query", "str"),
        ("key", "str"),
        ("weight", "float64"),
        ("query_row", "int64"),
        ("query_col", "int64"),
        ("key_row", "int64"),
        ("key_col", "int64"),
    ),
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

OPTIONAL_TABLES = ("terrain", "grids")
"""tables that recordings of older versions lack: they load as empty tables"""

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
    or ``grids`` (each episode's map size)). Tables are brought to the schema on
    construction, so column order and dtypes are always the documented ones.
    """

    episodes: pd.DataFrame = field(default_factory=lambda: empty_table("episodes"))
    steps: pd.DataFrame = field(default_factory=lambda: empty_table("steps"))
    positions: pd.DataFrame = field(default_factory=lambda: empty_table("positions"))
    holding: pd.DataFrame = field(default_factory=lambda: empty_table("holding"))
    terrain: pd.DataFrame = field(default_factory=lambda: empty_table("terrain"))
    grids: pd.DataFrame = field(default_factory=lambda: empty_table("grids"))
    events: pd.DataFrame = field(default_factory=lambda: empty_table("events"))
    attends: pd.DataFrame = field(default_factory=lambda: empty_table("attends"))
    relations: pd.DataFrame = field(default_factory=lambda: empty_table("relations"))
    attention: pd.DataFrame = field(default_factory=lambda: empty_table("attention"))
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
        reader never sees a half-written table.
        """
        out = make_folder(directory)
        for name, df in self.tables.items():
            atomic_write(out / f"{name}.parquet", lambda p, df=df: df.to_parquet(p, index=False))
        meta = {"format": _FORMAT, "format_version": _FORMAT_VERSION, "meta": self.meta}
        text = json.dumps(meta, indent=2, sort_keys=True, default=str) + "\n"
        atomic_write(out / "meta.json", lambda p: Path(p).write_text(text))
        return out

    @classmethod
    def load(cls, directory: str | os.PathLike[str]) -> Recording:
        """Read a recording written by :meth:`save`; ConfigError if it is not one.

        A folder published by ``neurosym extract`` is a link that the next run
        re-points; it is resolved once, so every table comes from the same run.
        """
        src = Path(directory)
        meta_path = src.resolve() / "meta.json"
        try:
            head = json.loads(meta_path.read_text())
        except (OSError, ValueError) as exc:
            raise ConfigError(
                f"{src} is not a neurosym recording (cannot read {meta_path.name}: {exc})"
            ) from None
        if not isinstance(head, dict) or head.get("format") != _FORMAT:
            raise ConfigError(
                f"{src} is not a neurosym recording ({meta_path.name} has no format tag {_FORMAT!r})"
            )
        tables: dict[str, pd.DataFrame] = {}
        for name in SCHEMA:
            path = meta_path.parent / f"{name}.parquet"
            if name in OPTIONAL_TABLES and not path.exists():
                tables[name] = empty_table(name)
                continue
            try:
                tables[name] = pd.read_parquet(path)
            except (OSError, ValueError) as exc:
                raise ConfigError(f"cannot read {src / path.name}: {exc}") from None
        meta = head.get("meta", {})
        if not isinstance(meta, dict):
            raise ConfigError(
                f"{src} is not a neurosym recording (its meta.json 'meta' is not an object)"
            )
        try:
            return cls(**tables, meta=meta)
        except ConfigError as exc:
            raise ConfigError(f"{src}: {exc}") from None

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
