"""Write pandas tables as a plain Prolog fact file (and optionally its .qlf).

``write_prolog(path, {"relation": df, ...})`` writes one fact per row,
``relation(0,3,1,5,agent,sword,0.8125).``, the DataFrame's columns being the
predicate's arguments in order. Cell values are spelled by
:mod:`neurosym.terms` (the one authority on Prolog text):

=====================  =====================================================
column / value         written as
=====================  =====================================================
str                    atom, quoted exactly when Prolog needs it
int, numpy integer     integer (any size)
float, numpy float     shortest text that reads back to the same double
                       (``-0.0`` and subnormals included)
bool                   ``true`` / ``false``
:class:`Term`          compound term (``picked(sword)``)
tuple / list           Prolog list
term text              with ``term_columns={"event": ["event"]}``, a str
                       column holding Prolog text (``"picked(sword)"``) is
                       parsed and written as the term, not as a quoted atom
=====================  =====================================================

NaN, infinities, None/NA and other types are refused with a
:class:`~neurosym.errors.FactError` naming the table, row (0-based position)
and column. Columns become Arrow string arrays (numbers formatted in C++,
atoms and terms spelled once per distinct value) and Arrow joins them into
lines, so a million relation/7 facts take well under a second. The file is
written to a temporary file beside ``path`` and renamed over it, so readers
never see half a KB.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.compute as pc

from neurosym.atomic import make_folder, open_atomic
from neurosym.errors import FactError
from neurosym.terms import atom_text, float_text, format_value, parse_term

CHUNK_ROWS = 500_000  # rows converted at a time: bounds memory for huge tables
_INDICATOR = re.compile(r"(.+)/(\d+)")


def format_term(value: Any) -> str:
    """Prolog text of one Python value, exactly as :func:`write_prolog` writes it in a fact."""
    return format_value(value)


class _CellError(Exception):
    """A value that cannot be written; ``row`` is its position within the converted block."""

    def __init__(self, row: int, reason: str) -> None:
        super().__init__(reason)
        self.row, self.reason = row, reason


def _first(mask: np.ndarray) -> int:
    return int(np.flatnonzero(mask)[0])


_TEXT = pa.large_string()
_TRUE, _FALSE = pa.scalar("true", _TEXT), pa.scalar("false", _TEXT)


def _take(spelled: list[str], codes: np.ndarray) -> pa.Array:
    """The spelled distinct values, one per row (codes index into them)."""
    return pa.array(spelled, type=_TEXT).take(pa.array(codes))


def _floats_text(values: np.ndarray) -> pa.Array:
    """Shortest round-trip text of every float, exactly as :func:`float_text` spells it.

    Arrow formats in C++ with the same shortest digits as Python's repr; they
    differ only in where they switch to exponent notation and in dropping
    '.0', so those few cells are re-spelled by float_text.
    """
    values = values.astype(np.float64, copy=False)
    bad = ~np.isfinite(values)
    if bad.any():
        row = _first(bad)
        reason = (
            f"{float(values[row])!r} cannot be written as a Prolog float; replace NaN/inf first"
        )
        raise _CellError(row, reason)
    text = pc.cast(pa.array(values), _TEXT)
    magnitude = np.abs(values)
    fix = (magnitude != 0) & ((magnitude < 1e-4) | (magnitude >= 1e16))  # repr's exponent range
    fix |= ~pc.match_substring(text, ".").to_numpy(zero_copy_only=False)  # '100', '-0'
    fix |= pc.match_substring(text, "e").to_numpy(zero_copy_only=False)  # Arrow's exponent range
    where = np.flatnonzero(fix)
    if len(where) == 0:
        return text
    spelled = pa.array([float_text(v) for v in values[where].tolist()], type=_TEXT)
    return pc.replace_with_mask(text, pa.array(fix), spelled)


def _by_unique(values: np.ndarray, spell: Any, key: str) -> pa.Array:
    """Spell each distinct value once. ``key='value'`` factorises by equality (exact
    for str and int), ``key='id'`` by object identity (exact for anything: 1, 1.0,
    True and -0.0/0.0 compare equal but are written differently)."""
    n = len(values)
    if key == "id":
        ids = np.fromiter(map(id, values), dtype=np.int64, count=n)
        codes, uniques = pd.factorize(ids)
        first = np.empty(len(uniques), dtype=np.int64)
        first[codes[::-1]] = np.arange(n - 1, -1, -1)  # first position of each object
        representatives = values[first].tolist()
    else:
        codes, representatives = pd.factorize(values)
        representatives, first = list(representatives), None
    spelled = []
    for k, value in enumerate(representatives):
        try:
            spelled.append(spell(value))
        except FactError as exc:
            row = int(first[k]) if first is not None else _first(codes == k)
            raise _CellError(row, str(exc)) from None
    return _take(spelled, codes)


def _spell_term_text(value: Any) -> str:
    if isinstance(value, str):
        return format_value(parse_term(value))
    return format_value(value)


def _spell(value: Any) -> str:
    if value is None or value is pd.NA or (isinstance(value, float) and value != value):
        raise FactError(f"{value!r} is missing; a fact needs a value in every column")
    return format_value(value)


def _column_text(series: pd.Series, term_text: bool) -> pa.Array:
    """Prolog text of every cell of one column (see the module docstring)."""
    dtype = series.dtype
    if isinstance(dtype, pd.CategoricalDtype):
        codes = series.cat.codes.to_numpy()
        if (codes < 0).any():
            raise _CellError(_first(codes < 0), "missing value (NaN)")
        categories = _column_text(pd.Series(series.cat.categories), term_text)
        return categories.take(pa.array(codes))
    if isinstance(dtype, pd.api.extensions.ExtensionDtype) and not isinstance(dtype, np.dtype):
        missing = series.isna().to_numpy()
        if missing.any():
            raise _CellError(_first(missing), "missing value (NA)")
        if isinstance(dtype, pd.StringDtype):  # factorise without making a Python str per cell
            codes, uniques = series.factorize()
            spell = _spell_term_text if term_text else atom_text
            try:
                return _take([spell(u) for u in uniques.tolist()], codes)
            except FactError:
                return _by_unique(series.to_numpy(dtype=object), spell, "value")
        np_dtype = getattr(dtype, "numpy_dtype", None)
        target = np_dtype if np_dtype is not None and np_dtype.kind in "biuf" else object
        series = pd.Series(series.to_numpy(dtype=target))
    values = series.to_numpy()
    kind = values.dtype.kind
    if kind == "b":
        return pc.if_else(pa.array(values), _TRUE, _FALSE)
    if kind in "iu":
        return pc.cast(pa.array(values), _TEXT)
    if kind == "f":
        return _floats_text(values)
    if kind in "OSU":
        values = values.astype(object, copy=False)
        inferred = pd.api.types.infer_dtype(values, skipna=False)
        if term_text:
            return _by_unique(values, _spell_term_text, "value" if inferred == "string" else "id")
        if inferred == "string":
            return _by_unique(values, atom_text, "value")
        if inferred == "integer":
            return _by_unique(values, format_value, "value")
        if inferred == "floating":
            return _floats_text(values.astype(np.float64))
        if inferred == "boolean":
            return pc.if_else(pa.array(values.astype(bool)), _TRUE, _FALSE)
        return _by_unique(values, _spell, "id")
    raise _CellError(-1, f"columns of dtype {values.dtype} cannot be written as Prolog terms")


def _table_blocks(name: str, df: pd.DataFrame, term_cols: set[str]) -> Iterable[memoryview]:
    """The facts of one table as UTF-8 blocks of up to CHUNK_ROWS lines.

    Lines are assembled by Arrow in C++ ("name(" + cells joined by "," +
    ").\n"); the block is the Arrow string array's data buffer itself.
    """
    prefix, end = pa.scalar(atom_text(name) + "(", _TEXT), pa.scalar(").\n", _TEXT)
    columns = list(df.columns)
    for start in range(0, len(df), CHUNK_ROWS):
        block = df.iloc[start : start + CHUNK_ROWS]
        cells = []
        for position, col in enumerate(columns):
            try:
                cells.append(_column_text(block.iloc[:, position], str(col) in term_cols))
            except _CellError as exc:
                where = f", row {start + exc.row}" if exc.row >= 0 else ""
                raise FactError(f"table {name!r}{where}, column {col!r}: {exc.reason}") from None
        body = pc.binary_join_element_wise(*cells, pa.scalar(",", _TEXT))
        lines = pc.binary_join_element_wise(prefix, body, end, pa.scalar("", _TEXT))
        offsets = np.frombuffer(lines.buffers()[1], dtype=np.int64)
        first, last = offsets[lines.offset], offsets[lines.offset + len(lines)]
        yield memoryview(lines.buffers()[2])[first:last]


def _indicator(spec: str | tuple[str, int]) -> tuple[str, int]:
    if isinstance(spec, tuple):
        name, arity = spec
    else:
        match = _INDICATOR.fullmatch(str(spec))
        if not match:
            raise FactError(f"dynamic declaration {spec!r} is not name/arity (e.g. 'holds/5')")
        name, arity = match.group(1), int(match.group(2))
    if not isinstance(name, str) or not name or not isinstance(arity, int) or arity < 0:
        raise FactError(f"dynamic declaration {spec!r} is not name/arity (e.g. 'holds/5')")
    return name, arity


def _comments(
    comments: Mapping[str, Iterable[str]], declared: Mapping[tuple[str, int], None]
) -> dict[tuple[str, int], list[str]]:
    """``comments`` by indicator, each line checked to be one Prolog comment line."""
    out: dict[tuple[str, int], list[str]] = {}
    for spec, lines in comments.items():
        key = _indicator(spec)
        if key not in declared:
            raise FactError(f"comments name {spec!r}, which is not declared dynamic")
        out[key] = [str(line) for line in lines]
        for line in out[key]:
            if not line.startswith("%") or line.splitlines() != [line]:
                raise FactError(f"comment line {line!r} of {spec} is not one line starting with %")
    return out


def write_prolog(
    path: str | os.PathLike[str],
    tables: Mapping[str, pd.DataFrame],
    *,
    header: str | None = None,
    dynamic: Iterable[str | tuple[str, int]] = (),
    qlf: bool = False,
    term_columns: Mapping[str, Iterable[str]] | None = None,
    comments: Mapping[str, Iterable[str]] | None = None,
) -> Path:
    """Write ``tables`` (predicate name -> DataFrame of its arguments) as facts at ``path``.

    ``header`` becomes ``%`` comment lines at the top. ``dynamic`` names extra
    predicates (``"name/arity"``) to declare ``:- dynamic``, so rules can ask
    for facts a KB lacks; empty tables are declared dynamic automatically.
    ``term_columns`` maps a table to its columns of Prolog term text.
    ``comments`` maps a declared ``"name/arity"`` to comment lines (each one
    line starting with ``%``: a PlDoc ``%!`` line naming its arguments) written
    above its ``:- dynamic`` line, a blank line before each. With
    ``qlf=True`` the file is also compiled to ``<stem>.qlf`` beside it
    (``path`` must then end in ``.pl``). Returns the ``.pl`` path.
    """
    path = Path(path)
    if qlf and path.suffix != ".pl":
        raise FactError(f"qlf=True needs a .pl path (the .qlf goes beside it), not {path}")
    term_columns = {k: {str(c) for c in v} for k, v in (term_columns or {}).items()}
    unknown = set(term_columns) - set(tables)
    if unknown:
        raise FactError(
            f"term_columns names tables that are not written: {', '.join(sorted(unknown))}"
        )
    declared: dict[tuple[str, int], None] = dict.fromkeys(_indicator(d) for d in dynamic)
    docs = _comments(comments or {}, declared)
    for name, df in tables.items():
        if not isinstance(name, str) or not name:
            raise FactError(f"table name {name!r} is not a predicate name")
        if not isinstance(df, pd.DataFrame) or df.shape[1] == 0:
            raise FactError(f"table {name!r} must be a DataFrame with one column per argument")
        missing = term_columns.get(name, set()) - {str(c) for c in df.columns}
        if missing:
            raise FactError(
                f"table {name!r} has no column {', '.join(sorted(missing))} (term_columns)"
            )
        if len(df) == 0:
            declared[(name, df.shape[1])] = None

    make_folder(path.parent)
    with open_atomic(path, "wb") as out:
        lines = [f"% {line}".rstrip() for line in (header or "").splitlines()]
        lines.append(":- encoding(utf8).")
        for name, arity in declared:
            doc = docs.get((name, arity))
            lines += ["", *doc] if doc else []
            lines.append(f":- dynamic {atom_text(name)}/{arity}.")
        out.write(("\n".join(lines) + "\n").encode("utf-8"))
        for name, df in tables.items():
            if len(df):
                out.write(b"\n")
                for block in _table_blocks(name, df, term_columns.get(name, set())):
                    out.write(block)
    if qlf:
        from neurosym.prolog.qlf import qcompile

        qcompile(path)
    return path
