"""The fact writer: exact text, refusals, atomic writes, and round trips through real SWI-Prolog."""

from __future__ import annotations

import math
import subprocess
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from neurosym.errors import FactError
from neurosym.facts.prolog_writer import format_term, write_prolog
from neurosym.prolog.knowledge_base import KnowledgeBase
from neurosym.terms import Term


def test_exact_text(tmp_path: Path) -> None:
    tables = {
        "kb_meta": pd.DataFrame({"key": ["env", "seed", "greedy"], "value": ["rgw2", 3, True]}),
        "relation": pd.DataFrame(
            {
                "e": [0, 0],
                "t": np.array([1, 2], dtype=np.int32),
                "a": ["agent", "Sword"],
                "b": pd.Categorical(["key(red)", "it's"]),
                "v": [0.1, -0.0],
            }
        ),
        "event": pd.DataFrame({"e": [0, 0], "ev": ["picked(sword)", "opened(lock(red))"]}),
        "holds": pd.DataFrame({"j": [Term("r", (1,))], "a": [Term("key", ("red",))]}),
        "attention": pd.DataFrame({"e": [], "w": []}),
    }
    path = write_prolog(
        tmp_path / "kb.pl",
        tables,
        header="made by a test\nsecond line",
        dynamic=["threshold/2", ("holds", 2)],
        term_columns={"event": ["ev"]},
    )
    assert path == tmp_path / "kb.pl"
    assert path.read_text(encoding="utf-8") == (
        "% made by a test\n"
        "% second line\n"
        ":- encoding(utf8).\n"
        ":- dynamic threshold/2.\n"
        ":- dynamic holds/2.\n"
        ":- dynamic attention/2.\n"
        "\n"
        "kb_meta(env,rgw2).\n"
        "kb_meta(seed,3).\n"
        "kb_meta(greedy,true).\n"
        "\n"
        "relation(0,1,agent,'key(red)',0.1).\n"
        "relation(0,2,'Sword','it\\'s',-0.0).\n"
        "\n"
        "event(0,picked(sword)).\n"
        "event(0,opened(lock(red))).\n"
        "\n"
        "holds(r(1),key(red)).\n"
    )


def test_format_term_matches_the_file() -> None:
    assert format_term(Term("opened", (Term("lock", ("red",)),))) == "opened(lock(red))"
    assert format_term(np.float32(0.5)) == "0.5"
    assert format_term(np.int64(-7)) == "-7"
    assert format_term(np.bool_(False)) == "false"
    assert format_term(1e22) == "1.0e22"


@pytest.mark.parametrize(
    ("column", "message"),
    [
        ([1.0, math.nan], r"table 'p', row 1, column 'x': nan cannot be written as a Prolog float"),
        ([0.5, 2.0, -math.inf], r"table 'p', row 2, column 'x': -inf cannot be written"),
        (["a", None], r"table 'p', row 1, column 'x': .*missing"),
        ([1, object()], r"table 'p', row 1, column 'x': cannot write a object"),
        (pd.array([1, None], dtype="Int64"), r"table 'p', row 1, column 'x': missing value"),
        (pd.to_datetime(["2024-01-01"]), r"table 'p', column 'x': columns of dtype datetime64"),
    ],
)
def test_unwritable_values_are_refused_naming_table_row_column(
    tmp_path: Path, column: object, message: str
) -> None:
    with pytest.raises(FactError, match=message):
        write_prolog(tmp_path / "kb.pl", {"p": pd.DataFrame({"x": column})})
    assert list(tmp_path.iterdir()) == []  # no temporary file left behind


def test_term_text_that_is_not_a_term_is_refused(tmp_path: Path) -> None:
    df = pd.DataFrame({"ev": ["picked(sword)", "picked(X)"]})
    with pytest.raises(FactError, match=r"table 'event', row 1, column 'ev': .*variable X"):
        write_prolog(tmp_path / "kb.pl", {"event": df}, term_columns={"event": ["ev"]})
    with pytest.raises(FactError, match="no column nope"):
        write_prolog(tmp_path / "kb.pl", {"event": df}, term_columns={"event": ["nope"]})


def test_bad_dynamic_and_table_shapes(tmp_path: Path) -> None:
    with pytest.raises(FactError, match="not name/arity"):
        write_prolog(tmp_path / "kb.pl", {}, dynamic=["holds"])
    with pytest.raises(FactError, match="one column per argument"):
        write_prolog(tmp_path / "kb.pl", {"p": pd.DataFrame(index=[0, 1])})
    with pytest.raises(FactError, match="needs a .pl path"):
        write_prolog(tmp_path / "kb.txt", {}, qlf=True)


def test_comments_stay_comments(tmp_path: Path) -> None:
    path = write_prolog(
        tmp_path / "kb.pl", {"p": pd.DataFrame({"x": [1]})}, dynamic=["q/1"],
        comments={"q/1": ["%!  q(?X)", "%   what q means"]},
    )
    assert path.read_text() == ":- encoding(utf8).\n\n%!  q(?X)\n%   what q means\n:- dynamic q/1.\n\np(1).\n"
    for lines, why in (
        (["%!  q(?X)\n:- initialization(halt)."], "is not one line starting with %"),
        (["%!  q(?X)\r:- initialization(halt)."], "is not one line starting with %"),
        (["q(?X)"], "is not one line starting with %"),
    ):
        with pytest.raises(FactError, match=f"comment line .* of q/1 {why}$"):
            write_prolog(tmp_path / "bad.pl", {}, dynamic=["q/1"], comments={"q/1": lines})
    with pytest.raises(FactError, match=r"^comments name 'r/1', which is not declared dynamic$"):
        write_prolog(tmp_path / "bad.pl", {}, dynamic=["q/1"], comments={"r/1": ["% r"]})
    assert not (tmp_path / "bad.pl").exists()


def test_failed_write_leaves_the_old_file_intact(tmp_path: Path) -> None:
    path = write_prolog(tmp_path / "kb.pl", {"p": pd.DataFrame({"x": [1]})})
    before = path.read_text()
    with pytest.raises(FactError):
        write_prolog(path, {"p": pd.DataFrame({"x": [1.0, math.nan]})})
    assert path.read_text() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["kb.pl"]


def test_large_tables_are_written_in_blocks(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import neurosym.facts.prolog_writer as writer

    monkeypatch.setattr(writer, "CHUNK_ROWS", 3)
    df = pd.DataFrame({"i": range(8), "x": [0.5] * 7 + [math.nan]})
    with pytest.raises(FactError, match="row 7"):  # the position counts across blocks
        write_prolog(tmp_path / "kb.pl", {"p": df})
    path = write_prolog(tmp_path / "kb.pl", {"p": df.iloc[:7]})
    assert path.read_text().splitlines()[2:] == [f"p({i},0.5)." for i in range(7)]


def test_plain_swipl_loads_the_file_without_warnings(tmp_path: Path, swipl: Path) -> None:
    tables = {
        "event": pd.DataFrame(
            {"e": [0, 1], "ev": [Term("picked", ("sword",)), Term("fell", ("pit",))]}
        ),
        "empty": pd.DataFrame({"a": [], "b": []}),
    }
    path = write_prolog(tmp_path / "kb.pl", tables, dynamic=["holds/5"])
    proc = subprocess.run(
        [str(swipl), "-f", "none", "--on-error=status", "--on-warning=status",
         "-g", "forall(event(E,X), (write_canonical(E-X), nl)), \\+ holds(_,_,_,_,_), \\+ empty(_,_)",
         "-t", "halt", str(path)],
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["-(0,picked(sword))", "-(1,fell(pit))"]


def test_qlf_is_written_beside_the_source_and_loads(tmp_path: Path) -> None:
    path = write_prolog(tmp_path / "kb.pl", {"p": pd.DataFrame({"x": [1, 2]})}, qlf=True)
    assert (tmp_path / "kb.qlf").is_file()
    with KnowledgeBase(tmp_path / "kb.qlf") as kb:
        assert kb.query("p(X)") == [{"X": 1}, {"X": 2}]
    assert path.suffix == ".pl"


# --- round trips through SWI-Prolog ------------------------------------------

atoms = st.text(max_size=10) | st.sampled_from(
    [
        "",
        "[]",
        "{}",
        "-",
        ";",
        "!",
        ",",
        "|",
        "a b",
        "It's",
        "\\",
        "'",
        "é",
        "is",
        "dynamic",
        "None",
        "true",
    ]
)
ints = st.integers() | st.integers(min_value=-(2**200), max_value=2**200)
floats = st.floats(allow_nan=False, allow_infinity=False)
# '[|]'(H, T) *is* a list cell and '.'(A, B) is dict access in SWI-Prolog 7: both refused.
functors = atoms.filter(lambda a: a not in ("[|]", "."))
values = st.recursive(
    atoms | ints | floats,
    lambda children: (
        st.builds(Term, functors, st.lists(children, min_size=1, max_size=3).map(tuple))
        | st.lists(children, max_size=3).map(tuple)
    ),
    max_leaves=10,
)


def _key(value: object) -> object:
    """Comparison key that tells -0.0 from 0.0 and 1 from 1.0; lists are tuples or lists."""
    if isinstance(value, bool):
        return ("str", "true" if value else "false")
    if isinstance(value, float):
        return ("float", math.copysign(1.0, value), value)
    if isinstance(value, Term):
        if not value.args:
            return ("str", value.functor)
        return ("term", value.functor, tuple(_key(a) for a in value.args))
    if isinstance(value, tuple | list):
        return ("list", tuple(_key(a) for a in value))
    return (type(value).__name__, value)


def _round_trip(tables: dict[str, pd.DataFrame]) -> dict[str, list[list[object]]]:
    with tempfile.TemporaryDirectory() as tmp:
        path = write_prolog(Path(tmp) / "kb.pl", tables)
        with KnowledgeBase(path) as kb:
            return {
                name: kb.solve(f"{name}({', '.join(f'X{i}' for i in range(df.shape[1]))})").rows
                for name, df in tables.items()
            }


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(values, min_size=1, max_size=8))
def test_mixed_values_read_back_equal(cells: list[object]) -> None:
    column = pd.Series(cells, dtype=object)
    got = _round_trip({"v": pd.DataFrame({"i": range(len(cells)), "x": column})})["v"]
    assert [(i, _key(x)) for i, x in got] == [(i, _key(x)) for i, x in enumerate(cells)]


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.lists(
        st.tuples(atoms, st.integers(-(2**63), 2**63 - 1), floats, st.booleans()),
        min_size=1,
        max_size=20,
    )
)
def test_typed_columns_read_back_equal(rows: list[tuple[str, int, float, bool]]) -> None:
    names, numbers, reals, flags = zip(*rows, strict=True)
    df = pd.DataFrame(
        {
            "name": list(names),
            "n": np.array(numbers, dtype=np.int64),
            "r": np.array(reals, dtype=np.float64),
            "flag": np.array(flags, dtype=bool),
            "cat": pd.Categorical(list(names)),
        }
    )
    got = _round_trip({"row": df})["row"]
    expected = [[a, n, r, "true" if f else "false", a] for a, n, r, f in rows]
    assert [[_key(v) for v in row] for row in got] == [[_key(v) for v in row] for row in expected]


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(values, min_size=1, max_size=5, unique_by=lambda v: repr(_key(v))))
def test_written_values_are_found_again_through_query_inputs(cells: list[object]) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        df = pd.DataFrame({"i": range(len(cells)), "x": pd.Series(cells, dtype=object)})
        path = write_prolog(Path(tmp) / "kb.pl", {"v": df})
        with KnowledgeBase(path) as kb:
            for i, value in enumerate(cells):
                assert {"I": i} in kb.query("v(I, X)", X=value)


@settings(
    max_examples=200, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    st.lists(
        floats
        | st.sampled_from(
            [0.0, -0.0, 100.0, 1e15, 1e16, 1e-4, 9.99e-5, 5e-324, 2.0**63, 10000000001.0]
        ),
        min_size=1,
    ),
    st.lists(st.integers(-(2**63), 2**64 - 1), min_size=1),
)
def test_numeric_columns_are_spelled_like_format_term(
    tmp_path: Path, reals: list[float], whole: list[int]
) -> None:
    path = tmp_path / "kb.pl"
    tables = {"r": pd.DataFrame({"x": np.array(reals, dtype=np.float64)})}
    unsigned = [i for i in whole if i >= 0]
    signed = [i for i in whole if i < 2**63]
    tables["u"] = pd.DataFrame({"x": np.array(unsigned or [0], dtype=np.uint64)})
    tables["s"] = pd.DataFrame({"x": np.array(signed or [0], dtype=np.int64)})
    write_prolog(path, tables)
    lines = [ln for ln in path.read_text().splitlines() if ln[:2] in ("r(", "u(", "s(")]
    expected = [f"r({format_term(x)})." for x in reals]
    expected += [f"u({format_term(x)})." for x in unsigned or [0]]
    expected += [f"s({format_term(x)})." for x in signed or [0]]
    assert lines == expected
