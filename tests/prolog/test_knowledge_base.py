"""KnowledgeBase: isolation between KBs, values in and out through janus, errors, qlf loading."""

from __future__ import annotations

import os
import subprocess
import sys
import time
import warnings
from pathlib import Path

import pandas as pd
import pytest

from neurosym.errors import ConfigError, NeurosymError, PrologError
from neurosym.prolog.knowledge_base import (
    KnowledgeBase,
    KnowledgeBaseFileNotFoundError,
    PrologWarning,
)
from neurosym.terms import Term

FACTS = """\
object(agent, agent).
object(s1, sword).
object('It''s', 'key(red)').
event(0, 3, picked(sword)).
event(0, 5, opened(lock(red))).
event(1, 2, hurt_by(enemy)).
val(1, -0.0).
val(2, 1.0e16).
val(3, 123456789012345678901234567890).
path(1, [a, f(x), [1, 2]]).
"""

RULES = """\
picked_item(E, I) :- event(E, _, picked(I)).
total(S) :- aggregate_all(sum(V), val(_, V), S).
"""


def _write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture
def files(tmp_path: Path) -> tuple[Path, Path]:
    return _write(tmp_path / "kb.pl", FACTS), _write(tmp_path / "rules.pl", RULES)


@pytest.fixture
def kb(files: tuple[Path, Path]) -> KnowledgeBase:
    facts, rules = files
    with KnowledgeBase(facts, rules=[rules]) as kb:
        yield kb


def test_values_come_back_as_plain_python(kb: KnowledgeBase) -> None:
    assert kb.query("object(Id, Type)") == [
        {"Id": "agent", "Type": "agent"},
        {"Id": "s1", "Type": "sword"},
        {"Id": "It's", "Type": "key(red)"},
    ]
    assert kb.query("event(0, T, Ev)") == [
        {"T": 3, "Ev": Term("picked", ("sword",))},
        {"T": 5, "Ev": Term("opened", (Term("lock", ("red",)),))},
    ]
    assert [str(a["Ev"]) for a in kb.query("event(_, _, Ev)")] == [
        "picked(sword)",
        "opened(lock(red))",
        "hurt_by(enemy)",
    ]
    vals = kb.query("val(I, V)")
    assert [v["V"] for v in vals] == [-0.0, 1e16, 123456789012345678901234567890]
    assert str(vals[0]["V"]) == "-0.0"
    assert kb.query("path(1, P)") == [{"P": ("a", Term("f", ("x",)), (1, 2))}]
    assert kb.query("X = Y, Z = a-b") == [{"X": None, "Y": None, "Z": Term("-", ("a", "b"))}]


def test_rules_and_libraries(kb: KnowledgeBase) -> None:
    assert kb.query("picked_item(E, I)") == [{"E": 0, "I": "sword"}]
    assert kb.once("total(S)") == {"S": 1e16 + 123456789012345678901234567890}
    assert kb.once("event(9, _, _)") is None
    assert kb.count("event(_, _, _)") == 3
    assert kb.query("between(1, 10, X)", limit=2) == [{"X": 1}, {"X": 2}]
    assert kb.query("object(_Id, T)", limit=1) == [{"T": "agent"}]  # _Id is not an output


def test_a_list_is_a_tuple_at_the_top_and_inside_a_term(kb: KnowledgeBase) -> None:
    top = kb.once("path(1, P)")["P"]
    inside = kb.once("path(1, P), T = w(P, [P])")["T"]
    assert top == ("a", Term("f", ("x",)), (1, 2))
    assert type(top) is tuple and type(top[2]) is tuple
    assert inside == Term("w", (top, (top,)))
    assert kb.solve("path(1, P)").rows == [[top]]
    assert inside in {inside}  # a Term holding lists stays hashable


def test_query_df_keeps_columns_when_empty(kb: KnowledgeBase) -> None:
    df = kb.query_df("event(E, T, Ev)")
    assert list(df.columns) == ["E", "T", "Ev"]
    assert df["E"].tolist() == [0, 0, 1]
    empty = kb.query_df("event(E, T, Ev), E > 5")
    assert list(empty.columns) == ["E", "T", "Ev"] and len(empty) == 0
    assert isinstance(empty, pd.DataFrame)


def test_inputs_reach_prolog_as_data(kb: KnowledgeBase) -> None:
    assert kb.query("object(Id, T)", Id="It's") == [{"T": "key(red)"}]
    assert kb.query("event(E, T, Ev)", Ev=Term("picked", ("sword",))) == [{"E": 0, "T": 3}]
    assert kb.query("event(E, T, opened(lock(C)))", C="red") == [{"E": 0, "T": 5}]
    assert kb.query("val(I, V)", V=123456789012345678901234567890) == [{"I": 3}]
    assert kb.query("path(I, P)", P=["a", Term("f", ("x",)), (1, 2)]) == [{"I": 1}]
    assert kb.query("X == true", X=True) == [{}]
    # text that would be code if it were pasted into the goal stays one atom
    assert kb.query("atom(X), atom_length(X, N)", X="a), halt, (b") == [{"N": 12}]


def test_bad_inputs_are_refused(kb: KnowledgeBase) -> None:
    with pytest.raises(ConfigError, match="input Z is not a variable of the goal"):
        kb.query("object(X, Y)", Z=1)
    with pytest.raises(ConfigError, match="'x' is not a Prolog variable name"):
        kb.query("object(X, Y)", x=1)
    with pytest.raises(ConfigError, match="input X is None"):
        kb.query("object(X, Y)", X=None)
    with pytest.raises(ConfigError, match="cannot pass a set"):
        kb.query("object(X, Y)", X={1})
    with pytest.raises(ConfigError, match="limit must be a positive integer"):
        kb.query("object(X, Y)", limit=0)
    with pytest.raises(ConfigError, match="the goal must be Prolog text"):
        kb.query("  ")


@pytest.mark.parametrize(
    ("goal", "message"),
    [
        ("nope(X)", r"^Unknown procedure: nope/1$"),
        ("object(X", r"^Syntax error: Operator expected"),
        (
            "atom_length(1, a)",
            r"^atom_length/2: Type error: `integer' expected, found `a' \(an atom\)$",
        ),
        ("X is foo + 1", r"Arithmetic: .*foo/0"),
        ("throw(my_ball)", r"my_ball"),
    ],
)
def test_prolog_errors_become_one_line_prolog_errors(
    kb: KnowledgeBase, goal: str, message: str
) -> None:
    with pytest.raises(PrologError, match=message) as info:
        kb.query(goal)
    assert "\n" not in str(info.value)
    assert kb.count("object(_, _)") == 3  # the KB is still usable


def test_kbs_are_isolated(tmp_path: Path) -> None:
    a = _write(tmp_path / "a.pl", "p(1).\nq(a).\n")
    b = _write(tmp_path / "b.pl", "p(2).\n")
    rules = _write(
        tmp_path / "r.pl", "double(Y) :- p(X), Y is 2 * X.\nall(L) :- findall(X, p(X), L).\n"
    )
    kb1, kb2 = KnowledgeBase(a, rules=rules), KnowledgeBase(b, rules=rules)
    kb3 = KnowledgeBase(a)  # the same fact file in a third KB
    try:
        assert kb1.query("double(Y)") == [{"Y": 2}]
        assert kb2.query("double(Y)") == [{"Y": 4}]
        assert kb3.query("p(X)") == [{"X": 1}]
        with pytest.raises(PrologError, match="Unknown procedure: q/1"):
            kb2.query("q(X)")
        kb1.close()
        # closing one KB unloads nothing the others use (files, autoloaded libraries)
        assert kb2.query("all(L)") == [{"L": (2,)}]
        assert kb3.count("p(_)") == 1
        with pytest.raises(NeurosymError, match="is closed"):
            kb1.query("p(X)")
    finally:
        kb1.close()
        kb2.close()
        kb3.close()


def test_several_fact_files_add_up(tmp_path: Path) -> None:
    a = _write(tmp_path / "a.pl", ":- dynamic p/1.\np(1).\nq(a).\n")
    b = _write(tmp_path / "b.pl", ":- dynamic p/1.\np(2).\nq(b).\n")
    for qlf in (False, True):
        with KnowledgeBase([a, b], qlf=qlf) as kb:
            assert kb.query("p(X), q(Y)") == [{"X": x, "Y": y} for x in (1, 2) for y in ("a", "b")]


def test_kb_does_not_see_the_user_module(kb: KnowledgeBase) -> None:
    from neurosym.prolog.knowledge_base import _janus

    _janus().query_once("assertz(user:neurosym_test_leak(1))")
    try:
        with pytest.raises(PrologError, match="Unknown procedure: neurosym_test_leak/1"):
            kb.query("neurosym_test_leak(X)")
    finally:
        _janus().query_once("retractall(user:neurosym_test_leak(_))")


def test_load_errors_name_the_file_and_line(tmp_path: Path) -> None:
    bad = _write(tmp_path / "bad.pl", "p(1).\np(.\n")
    with pytest.raises(PrologError, match=rf"^cannot load {bad}:2:\d+: Syntax error"):
        KnowledgeBase(bad)
    static = _write(tmp_path / "static.pl", "atom(1).\n")
    with pytest.raises(
        PrologError,
        match=rf"^cannot load {static}:1: found a fact for the built-in predicate atom/1",
    ):
        KnowledgeBase(static)
    with pytest.raises(  # consulted as code, Prolog itself refuses
        PrologError, match=rf"{static}:1: No permission to modify static procedure `atom/1'"
    ):
        KnowledgeBase(static, trusted=True)
    with pytest.raises(KnowledgeBaseFileNotFoundError, match="no such Prolog file: .*missing.pl"):
        KnowledgeBase(tmp_path / "missing.pl")
    good = _write(tmp_path / "good.pl", "p(1).\n")
    with KnowledgeBase(good) as kb:
        with pytest.raises(PrologError, match="bad.pl:2"):
            kb.load(bad)
        assert kb.query("p(X)") == [{"X": 1}]  # the failed load left the KB as it was
        assert kb.files == [good.resolve()]


def test_load_warnings_are_one_line_at_the_users_file_and_line(tmp_path: Path) -> None:
    rules = _write(tmp_path / "w.pl", "q.\np(X) :- q.\n")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        KnowledgeBase(None, rules=[rules]).close()
    [w] = caught
    assert (w.category, w.filename, w.lineno) == (PrologWarning, str(rules), 2)
    shown = warnings.formatwarning(w.message, w.category, w.filename, w.lineno)
    assert shown == f"{rules}:2: warning: Singleton variables: [X]\n"


def test_relative_includes_resolve_beside_the_rule_file(tmp_path: Path) -> None:
    (tmp_path / "lib").mkdir()
    _write(tmp_path / "lib" / "helper.pl", "helper(42).\n")
    rules = _write(tmp_path / "rules.pl", ":- include('lib/helper.pl').\nanswer(X) :- helper(X).\n")
    with KnowledgeBase(None, rules=[rules]) as kb:
        assert kb.query("answer(X)") == [{"X": 42}]


def test_qlf_is_compiled_once_and_shared_by_kbs(tmp_path: Path) -> None:
    facts = _write(tmp_path / "kb.pl", "p(1).\np(2).\n:- dynamic absent/1.\n")
    qlf = tmp_path / "kb.qlf"
    kb1 = KnowledgeBase(facts, qlf=True)
    first = qlf.stat().st_mtime_ns
    kb2 = KnowledgeBase(facts, qlf=True)  # fresh .qlf: reused, not recompiled
    kb3 = KnowledgeBase(qlf)  # the .qlf named directly
    try:
        assert qlf.stat().st_mtime_ns == first
        for kb in (kb1, kb2, kb3):
            assert kb.query("p(X)") == [{"X": 1}, {"X": 2}]
            assert kb.query("absent(X)") == []
        kb1.close()
        assert kb2.count("p(_)") == 2 and kb3.count("p(_)") == 2
        # the .qlf's dynamic declaration landed in each KB, not in user
        from neurosym.prolog.knowledge_base import _janus

        assert not _janus().query_once("predicate_property(user:absent(_), dynamic)")["truth"]
    finally:
        for kb in (kb1, kb2, kb3):
            kb.close()
    time.sleep(0.01)
    _write(facts, "p(3).\n")
    os.utime(facts, ns=(first + 10**9, first + 10**9))  # newer than the .qlf: recompiled
    with KnowledgeBase(facts, qlf=True) as kb:
        assert kb.query("p(X)") == [{"X": 3}]


def test_qlf_compile_errors_name_the_file(tmp_path: Path) -> None:
    bad = _write(tmp_path / "bad.pl", "p(.\n")
    with pytest.raises(PrologError, match=rf"^cannot load {bad}:1:\d+: Syntax error"):
        KnowledgeBase(bad, qlf=True)  # the source is checked as data before compiling
    assert not (tmp_path / "bad.qlf").exists()
    with pytest.raises(
        PrologError, match=r"qcompile .*bad.pl failed: .*bad.pl:1:\d+: Syntax error"
    ):
        KnowledgeBase(bad, qlf=True, trusted=True)
    assert not (tmp_path / "bad.qlf").exists()


def test_unreadable_qlf_is_recompiled_from_its_source(tmp_path: Path) -> None:
    facts = _write(tmp_path / "kb.pl", "p(1).\n")
    qlf = tmp_path / "kb.qlf"
    qlf.write_bytes(b"not a qlf file")  # newer than the source, but unreadable
    with KnowledgeBase(facts, qlf=True) as kb:
        assert kb.query("p(X)") == [{"X": 1}]
    assert qlf.read_bytes() != b"not a qlf file"
    qlf.write_bytes(b"not a qlf file")
    with pytest.raises(PrologError, match="kb.qlf"):  # named directly: nothing to recompile from
        KnowledgeBase(qlf)


# --- locating SWI-Prolog -------------------------------------------------------


@pytest.fixture
def fresh_locate(monkeypatch: pytest.MonkeyPatch):
    from neurosym.prolog import locate

    locate.find_swipl.cache_clear()
    yield locate
    monkeypatch.undo()
    locate.find_swipl.cache_clear()


def test_neurosym_swipl_is_checked(tmp_path: Path, monkeypatch, fresh_locate, fake_swipl) -> None:
    monkeypatch.setenv("NEUROSYM_SWIPL", str(fake_swipl(tmp_path / "old", 90004)))
    with pytest.raises(NeurosymError, match=r"is SWI-Prolog 9\.0\.4; janus-swi needs >= 9\.1\.12"):
        fresh_locate.find_swipl()
    fresh_locate.find_swipl.cache_clear()
    monkeypatch.setenv("NEUROSYM_SWIPL", str(tmp_path / "nope"))
    with pytest.raises(NeurosymError, match="is not a runnable swipl"):
        fresh_locate.find_swipl()
    fresh_locate.find_swipl.cache_clear()
    new = fake_swipl(tmp_path / "new", 90209)
    monkeypatch.setenv("NEUROSYM_SWIPL", str(new))
    found = fresh_locate.find_swipl()
    assert (found.executable, found.home, found.version_text) == (
        new,
        tmp_path / "new" / "home",
        "9.2.9",
    )


def test_old_swipl_on_path_is_not_used(tmp_path: Path, monkeypatch, fresh_locate, fake_swipl) -> None:
    monkeypatch.delenv("NEUROSYM_SWIPL", raising=False)
    monkeypatch.setattr(sys, "prefix", str(tmp_path / "empty-venv"))
    old = fake_swipl(tmp_path / "bin", 90004)
    monkeypatch.setenv("PATH", str(old.parent))
    with pytest.raises(NeurosymError, match=r"swipl on PATH .* is version 9\.0\.4; .*neurosym setup-prolog"):
        fresh_locate.find_swipl()


def test_janus_gets_the_venv_home_despite_an_old_swipl_on_path(
    tmp_path: Path, swipl: Path, fake_swipl
) -> None:
    if not swipl.is_relative_to(sys.prefix):  # the venv's bin/swipl link or its swipl/ build
        pytest.skip("this setup uses a SWI-Prolog outside the venv")
    old = fake_swipl(tmp_path / "bin", 90004)
    code = (
        "import os, sys\n"
        "from neurosym.prolog.knowledge_base import KnowledgeBase\n"
        "from neurosym.prolog.locate import find_swipl\n"
        "kb = KnowledgeBase(None)\n"
        "assert kb.query('X is 6 * 7') == [{'X': 42}]\n"
        "print(os.environ['SWI_HOME_DIR'] == str(find_swipl().home), find_swipl().executable)\n"
    )
    env = {**os.environ, "PATH": f"{old.parent}{os.pathsep}{os.environ['PATH']}"}
    env.pop("NEUROSYM_SWIPL", None)
    env.pop("SWI_HOME_DIR", None)
    env["PYTHONPATH"] = str(Path(__file__).resolve().parents[2])
    proc = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["True", str(swipl)]


def test_a_deeply_nested_term_in_a_rule_file_does_not_take_python_down(tmp_path: Path) -> None:
    """Rule files are code, but a term nested past the C stack killed the process (SIGSEGV)."""
    rules = _write(tmp_path / "rules.pl", "deep(" + "f(" * 50_000 + "x" + ")" * 50_000 + ").\n")
    facts = _write(tmp_path / "kb.pl", "ok(1).\n")
    code = (
        "from neurosym.prolog.knowledge_base import KnowledgeBase\n"
        f"with KnowledgeBase({str(facts)!r}, rules=[{str(rules)!r}]) as kb:\n"
        "    print(kb.count('deep(_)'))\n"
        "    try:\n        kb.query('deep(X)')\n    except Exception as exc:\n        print(exc)\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    count, message = proc.stdout.splitlines()
    assert count == "1"
    assert message.startswith("an answer is nested more than 100 levels deep")


def test_ctrl_c_stops_a_goal_and_the_kb_still_answers(kb: KnowledgeBase) -> None:
    """Python handles no signal while Prolog runs; Prolog's heartbeat lets it."""
    import signal

    def interrupt(*_: object) -> None:
        raise KeyboardInterrupt

    old = signal.signal(signal.SIGALRM, interrupt)
    signal.setitimer(signal.ITIMER_REAL, 0.5)
    try:
        with pytest.raises(KeyboardInterrupt):
            kb.query("repeat, fail")
        signal.setitimer(signal.ITIMER_REAL, 0.5)
        with pytest.raises(KeyboardInterrupt):
            kb.count("repeat, fail")
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    assert kb.count("object(_, _)") == 3
