"""Untrusted knowledge bases run no code: planted code in fact files and .qlf files never runs.

Every planted payload would create a marker file if it ran; each test
asserts the marker is absent afterwards. Positive controls load the same
payload as rules or with ``trusted=True`` and see the marker appear, so the
detector itself is shown to work.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from neurosym.errors import ConfigError, NeurosymError, PrologError
from neurosym.facts.prolog_writer import write_prolog
from neurosym.prolog.knowledge_base import KnowledgeBase
from neurosym.prolog.signature import signature_path
from neurosym.terms import atom_text

REPO = Path(__file__).resolve().parents[2]


def _touch(marker: Path) -> str:
    """Prolog goal text that creates ``marker``."""
    return f"(open({atom_text(str(marker))}, write, S), close(S))"


# (name, planted text with {touch}, what the one-line error says was found)
PLANTED = [
    ("directive", ":- {touch}.", "a directive"),
    ("initialization", ":- initialization({touch}).", "a directive"),
    ("query", "?- {touch}.", "a directive"),
    ("encoding-and", ":- encoding(utf8), {touch}.", "a directive"),
    ("dynamic-and", ":- dynamic ok/1, {touch}.", "a directive"),
    ("dynamic-qualified", ":- dynamic user:ok/1.", "a directive"),
    ("op", ":- op(700, xfx, ===>).", "a directive"),
    ("if", ":- if({touch}).\n:- endif.", "a directive"),
    ("include", ":- include('payload.pl').", "a directive"),
    ("use_module", ":- use_module('payload.pl').", "a directive"),
    ("rule", "ok(2) :- {touch}.", "a clause with a body"),
    ("expansion-rule", "term_expansion(end_of_file, _) :- {touch}.", "a clause with a body"),
    ("expansion-fact", "term_expansion(ok(9), (:- initialization({touch}))).", "hook predicate term_expansion/2"),
    ("goal-expansion", "goal_expansion(ok(_), {touch}).", "hook predicate goal_expansion/2"),
    ("portray", "portray(_).", "hook predicate portray/1"),
    ("message-hook", "message_hook(_, _, _).", "hook predicate message_hook/3"),
    ("load-hook", "prolog_load_file(_, _).", "hook predicate prolog_load_file/2"),
    ("user-qualified", "user:term_expansion(_, (:- initialization({touch}))).", "a module-qualified clause"),
    ("system-qualified", "system:ok(1).", "a module-qualified clause"),
    ("grammar", "ok --> {{ {touch} }}.", "a grammar rule"),
    ("builtin-fact", "initialization({touch}).", "built-in predicate initialization/1"),
    ("builtin-dynamic", ":- dynamic shell/1.", "built-in predicate shell/1"),
    ("library-fact", "member(x, [x]).", "library predicate member/2"),
    ("variable", "_.", "a variable"),
    ("number", "42.", "a term that is not a fact"),
    ("ssu-rule", "ok(_) => {touch}.", "a rule (Head => Body)"),
    ("ssu-guard", "ok(X), X > 0 => {touch}.", "a rule (Head => Body)"),
    ("ssu-quoted", "'=>'(ok(_), {touch}).", "a rule (Head => Body)"),
    ("operator-fact", "'?=>'(ok(1), true).", "not a plain predicate name"),
    ("symbol-fact", "'$hidden'(1).", "not a plain predicate name"),
    ("dynamic-operator", ":- dynamic (=>)/2.", "not a plain predicate name"),
    ("non-ground", "ok(_).", "a fact with a variable"),
]  # fmt: skip


@pytest.fixture
def marker(tmp_path: Path) -> Path:
    path = tmp_path / "RAN"
    # what include/use_module would pull in: a file whose loading creates the marker
    (tmp_path / "payload.pl").write_text(f":- {_touch(path)}.\n")
    return path


def _plant(tmp_path: Path, marker: Path, text: str, name: str = "kb.pl") -> Path:
    path = tmp_path / name
    path.write_text(
        ":- encoding(utf8).\nok(1).\n" + text.format(touch=_touch(marker)) + "\nok(3).\n"
    )
    return path


@pytest.mark.parametrize(("text", "found"), [p[1:] for p in PLANTED], ids=[p[0] for p in PLANTED])
def test_planted_code_in_a_fact_file_is_refused_and_never_runs(
    tmp_path: Path, marker: Path, text: str, found: str
) -> None:
    path = _plant(tmp_path, marker, text)
    with pytest.raises(PrologError) as info:
        KnowledgeBase(path)
    message = str(info.value)
    assert message.startswith(f"cannot load {path}:3: found ")  # file and line of the payload
    assert found in message
    assert "\n" not in message
    assert not marker.exists()


@pytest.mark.parametrize("qlf", [False, True])
def test_the_cli_refuses_planted_code_in_one_line(neurosym_main, tmp_path: Path, marker: Path, qlf):
    path = _plant(tmp_path, marker, ":- initialization({touch}).")
    args = ["query", "--kb", path, "ok(X)"] + (["--qlf"] if qlf else [])
    proc = neurosym_main(*args)
    assert proc.returncode == 1
    assert proc.stderr.count("\n") == 1, proc.stderr
    assert proc.stderr.startswith(f"neurosym query: error: cannot load {path}:3: found a directive")
    assert not marker.exists()
    assert not path.with_suffix(".qlf").exists()  # nothing of an unchecked source is compiled


def _rgw_kb(tmp_path: Path) -> Path:
    """A small KB as ``neurosym extract`` writes it (the writer's headers and shapes)."""
    tables = {
        "object": pd.DataFrame({"id": ["s1", "e1"], "type": ["sword", "enemy"]}),
        "holds": pd.DataFrame(
            {"e": [0, 0], "t": [1, 1], "r": ["r(1)", "r(1)"], "a": ["sword", "agent"], "b": ["agent", "enemy"]}
        ),
    }
    return write_prolog(
        tmp_path / "K.pl", tables, dynamic=["attention/6"], term_columns={"holds": ["r"]}
    )


@pytest.mark.parametrize("qlf", [False, True])
def test_an_ssu_rule_appended_to_an_extracted_kb_never_runs(
    neurosym_main, tmp_path: Path, marker: Path, qlf: bool
) -> None:
    path = _rgw_kb(tmp_path)
    with KnowledgeBase(path, rules=[REPO / "rules" / "rgw.pl"]) as kb:  # the KB as written works
        assert str(kb.once("sword_enemy_link(L)")["L"]) == "indirect([via(agent,share(1,1))])"
    line = path.read_text().count("\n") + 1
    with path.open("a") as fh:
        fh.write(f"attention(_,_,_,_,_,_) => {_touch(marker)}, fail.\n")
    args = ["query", "--kb", path, "--rules", REPO / "rules" / "rgw.pl", "sword_enemy_link(L)"]
    proc = neurosym_main(*args, *(["--qlf"] if qlf else []))
    assert proc.returncode == 1, proc.stdout
    assert proc.stderr.count("\n") == 1, proc.stderr
    assert proc.stderr.startswith(
        f"neurosym query: error: cannot load {path}:{line}: found a rule (Head => Body)"
    )
    with pytest.raises(PrologError, match=rf"^cannot load {path}:{line}: found a rule"):
        KnowledgeBase(path, rules=[REPO / "rules" / "rgw.pl"], qlf=qlf)
    assert not marker.exists()
    assert not path.with_suffix(".qlf").exists()


def test_trust_and_rules_load_the_same_file_as_code(neurosym_main, tmp_path, marker) -> None:
    """Positive controls: the payload does run when the user says the file is code."""
    path = _plant(tmp_path, marker, ":- {touch}.")
    with KnowledgeBase(None, rules=[path]) as kb:
        assert kb.count("ok(_)") == 2
    assert marker.exists()
    marker.unlink()
    with KnowledgeBase(path, trusted=True) as kb:
        assert kb.count("ok(_)") == 2
    assert marker.exists()
    marker.unlink()
    proc = neurosym_main("query", "--kb", path, "--trust", path, "--csv", "ok(X)")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == "X\n1\n3\n"
    assert marker.exists()
    proc = neurosym_main("query", "--kb", path, "--trust", tmp_path / "other.pl", "ok(X)")
    assert (
        proc.returncode == 1 and "--trust" in proc.stderr and "not one of the --kb" in proc.stderr
    )


def test_facts_for_predicates_the_rules_define_are_refused(tmp_path: Path) -> None:
    rules = tmp_path / "rules.pl"
    rules.write_text("safe(X) :- ok(X).\n:- dynamic extra/1.\n")
    facts = tmp_path / "kb.pl"
    facts.write_text("ok(1).\nextra(2).\nsafe(99).\n")
    with pytest.raises(
        PrologError, match=rf"{facts}:3: found a fact for safe/1, which the rule files define"
    ):
        KnowledgeBase(facts, rules=[rules])
    facts.write_text(
        "ok(1).\nextra(2).\n"
    )  # a predicate the rules declare dynamic is data's to fill
    with KnowledgeBase(facts, rules=[rules]) as kb:
        assert kb.query("safe(X)") == [{"X": 1}] and kb.query("extra(X)") == [{"X": 2}]


def test_a_refused_file_leaves_the_kb_as_it_was(tmp_path: Path, marker: Path) -> None:
    good = tmp_path / "good.pl"
    good.write_text(":- dynamic later/1.\nok(0).\n")
    bad = tmp_path / "bad.pl"
    bad.write_text(f"ok(1).\nok(2).\nnew(1).\n:- dynamic fresh/1.\n:- {_touch(marker)}.\n")
    with KnowledgeBase(good) as kb:
        with pytest.raises(PrologError, match=rf"{bad}:5: found a directive"):
            kb.load(bad)
        assert kb.query("ok(X)") == [{"X": 0}]
        for gone in ("new(X)", "fresh(X)"):
            with pytest.raises(PrologError, match="Unknown procedure"):
                kb.query(gone)
        assert kb.files == [good.resolve()]
    assert not marker.exists()


def test_quasi_quotations_are_read_unparsed(tmp_path: Path, marker: Path) -> None:
    """A quasi-quotation parser is code; reading facts must not call one, even a known one."""
    from neurosym.prolog.knowledge_base import _janus

    janus = _janus()
    janus.consult(
        "/neurosym/test_qq.pl",
        data=(
            ":- use_module(library(quasi_quotations)).\n"
            ":- quasi_quotation_syntax(user:nsqq).\n"
            f"user:nsqq(_, _, _, x) :- {_touch(marker)}.\n"
        ),
    )
    path = tmp_path / "kb.pl"
    path.write_text("ok(1).\nq({|nsqq||text|}).\n")
    with pytest.raises(PrologError, match=rf"{path}:2: found a quasi-quotation"):
        KnowledgeBase(path)
    assert not marker.exists()


def test_kbs_that_neurosym_writes_load_unchanged(tmp_path: Path) -> None:
    tables = {
        "object": pd.DataFrame(
            {"id": ["agent", "It's", "ключ"], "type": ["agent", "key(red)", "x"]}
        ),
        "event": pd.DataFrame({"e": [0, 0], "t": [1, 2], "ev": ["picked(sword)", "got(key(red))"]}),
        "relation": pd.DataFrame({"e": [0], "v": [-0.0]}),
        "empty": pd.DataFrame({"a": pd.Series([], dtype="int64")}),
    }
    path = write_prolog(
        tmp_path / "kb.pl",
        tables,
        header="made by a test\nsecond line",
        dynamic=["holds/5"],
        term_columns={"event": ["ev"]},
    )
    with KnowledgeBase(path) as kb:
        assert [a["Id"] for a in kb.query("object(Id, _)")] == ["agent", "It's", "ключ"]
        assert [str(a["Ev"]) for a in kb.query("event(_, _, Ev)")] == [
            "picked(sword)",
            "got(key(red))",
        ]
        assert kb.query("holds(E, T, R, A, B)") == [] and kb.query("empty(X)") == []
        assert str(kb.once("relation(0, V)")["V"]) == "-0.0"


# --- .qlf: compiled code --------------------------------------------------------


def _attacker_qlf(swipl: Path, tmp_path: Path, marker: Path, stem: str = "evil") -> Path:
    """A .qlf compiled elsewhere whose loading creates the marker (and defines ok(666))."""
    src = tmp_path / f"{stem}_src" / f"{stem}.pl"
    src.parent.mkdir()
    src.write_text(f"ok(666).\n:- initialization({_touch(marker)}).\n")
    subprocess.run(
        [str(swipl), "-f", "none", "-q", "-g", f"qcompile(neurosym_qlf:{atom_text(str(src))})", "-t", "halt"],
        check=True, capture_output=True,
    )  # fmt: skip
    marker.unlink(missing_ok=True)  # compiling ran it; loading must not
    return src.with_suffix(".qlf")


def test_a_qlf_from_elsewhere_is_refused(swipl: Path, tmp_path: Path, marker: Path) -> None:
    qlf = _attacker_qlf(swipl, tmp_path, marker)
    with pytest.raises(
        PrologError, match=r"a \.qlf is compiled code .*\(it has no signature evil\.qlf\.sig\)"
    ):
        KnowledgeBase(qlf)
    assert not marker.exists()
    with KnowledgeBase(qlf, trusted=True) as kb:  # positive control
        assert kb.query("ok(X)") == [{"X": 666}]
    assert marker.exists()


def test_a_copied_or_foreign_signature_does_not_help(
    swipl: Path, tmp_path: Path, marker: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    legit = write_prolog(tmp_path / "legit.pl", {"ok": pd.DataFrame({"x": [1]})}, qlf=True)
    with KnowledgeBase(legit.with_suffix(".qlf")) as kb:  # neurosym's own .qlf loads as it is
        assert kb.query("ok(X)") == [{"X": 1}]
    qlf = _attacker_qlf(swipl, tmp_path, marker)
    signature_path(qlf).write_bytes(signature_path(legit.with_suffix(".qlf")).read_bytes())
    with pytest.raises(PrologError, match="it is not the file evil.qlf.sig signed"):
        KnowledgeBase(qlf)
    # signed with someone else's key (their neurosym compiled it)
    monkeypatch.setenv("NEUROSYM_KEY_FILE", str(tmp_path / "their.key"))
    from neurosym.prolog.signature import sign

    sign(qlf, qlf.with_suffix(".pl"))
    monkeypatch.undo()
    with pytest.raises(PrologError, match="was not made with this account's key"):
        KnowledgeBase(qlf)
    assert not marker.exists()


def test_a_planted_qlf_beside_a_source_is_replaced_not_loaded(
    swipl: Path, tmp_path: Path, marker: Path
) -> None:
    source = tmp_path / "kb.pl"
    source.write_text("ok(1).\n")
    evil = _attacker_qlf(swipl, tmp_path, marker, stem="kb")
    planted = tmp_path / "kb.qlf"
    os.replace(evil, planted)
    later = source.stat().st_mtime_ns + 10**9
    os.utime(planted, ns=(later, later))  # newer than its source: mtime alone would trust it
    with KnowledgeBase(source, qlf=True) as kb:
        assert kb.query("ok(X)") == [{"X": 1}]
    assert not marker.exists()
    assert signature_path(planted).is_file()  # recompiled from the checked source, and signed


def test_the_cli_refuses_a_foreign_qlf_and_trust_loads_it(
    neurosym_main, swipl: Path, tmp_path: Path, marker: Path
) -> None:
    qlf = _attacker_qlf(swipl, tmp_path, marker)
    proc = neurosym_main("query", "--kb", qlf, "ok(X)")
    assert proc.returncode == 1 and proc.stderr.count("\n") == 1, proc.stderr
    assert "a .qlf is compiled code" in proc.stderr and f"--trust {qlf.name}" in proc.stderr
    assert not marker.exists()
    proc = neurosym_main("query", "--kb", qlf, "--trust", qlf, "--csv", "ok(X)")
    assert proc.returncode == 0 and proc.stdout == "X\n666\n", proc.stderr
    assert marker.exists()


# --- queries that cannot hang ---------------------------------------------------


@pytest.fixture
def kb(tmp_path: Path):
    path = tmp_path / "kb.pl"
    path.write_text("ok(1).\nok(2).\n")
    rules = tmp_path / "rules.pl"
    rules.write_text("loop :- loop.\ngrow(L) :- grow([x|L]).\n")
    with KnowledgeBase(path, rules=[rules]) as kb:
        yield kb


@pytest.mark.parametrize(
    ("goal", "bounds", "term", "message"),
    [
        ("repeat, fail", {"timeout": 0.3}, "timeout", "time limit exceeded: the goal ran longer than 0.3 s"),
        ("loop", {"inferences": 100_000}, "inferences", "inference limit exceeded: the goal took more than 100,000 inferences"),
        ("grow([])", {"stack_limit": 32 << 20}, "stack", "stack limit exceeded: the goal needed more than 32.0 MB"),
        ("numlist(1, 100000000, L), length(L, N)", {"stack_limit": 32 << 20, "timeout": 60}, "stack", "stack limit exceeded"),
    ],
)  # fmt: skip
def test_runaway_goals_stop_with_one_line_and_the_kb_still_answers(
    kb: KnowledgeBase, goal: str, bounds: dict, term: str, message: str
) -> None:
    with pytest.raises(PrologError) as info:
        kb.query(goal, **bounds)
    assert str(info.value).startswith(message)
    assert "\n" not in str(info.value)
    assert info.value.term == term
    assert kb.query("ok(X)") == [{"X": 1}, {"X": 2}]
    assert kb.count("ok(_)", timeout=5) == 2
    with pytest.raises(PrologError, match="time limit exceeded"):
        kb.count("repeat, fail", timeout=0.2)


def test_bounds_are_checked(kb: KnowledgeBase) -> None:
    with pytest.raises(ConfigError, match="timeout must be a positive number"):
        kb.query("ok(X)", timeout=0)
    with pytest.raises(ConfigError, match="inferences must be an integer"):
        kb.query("ok(X)", inferences=1.5)
    with pytest.raises(ConfigError, match="stack_limit must be an integer of at least 1048576"):
        kb.query("ok(X)", stack_limit=10)
    assert kb.query("ok(X)", timeout=5, inferences=1000, stack_limit=64 << 20) == [
        {"X": 1},
        {"X": 2},
    ]


def test_cli_timeout_and_limits(neurosym_main, tmp_path: Path) -> None:
    facts = tmp_path / "kb.pl"
    facts.write_text("ok(1).\n")
    rules = tmp_path / "rules.pl"
    rules.write_text("grow(L) :- grow([x|L]).\n")
    for args, message in [
        (
            ["--timeout", "0.5", "repeat, fail"],
            "time limit exceeded: the goal ran longer than 0.5 s",
        ),
        (["--max-inferences", "1000", "repeat, fail"], "inference limit exceeded"),
        (
            ["--stack-limit", "16", "grow([])"],
            "stack limit exceeded: the goal needed more than 16.0 MB",
        ),
        (["--timeout", "0", "ok(X)"], "--timeout must be a positive number"),
    ]:
        proc = neurosym_main("query", "--kb", facts, "--rules", rules, *args)
        assert proc.returncode == 1, proc.stderr
        assert proc.stderr.count("\n") == 1, proc.stderr
        assert proc.stderr.startswith(f"neurosym query: error: {message}"), proc.stderr
    help_text = neurosym_main("query", "--help").stdout
    assert "--timeout SECONDS" in help_text and "(default: none)" in help_text


# --- facts that would bring the process down --------------------------------------


def _nested(depth: int) -> str:
    return "f(" * depth + "x" + ")" * depth



@pytest.mark.parametrize(
    "nested",
    [
        _nested(101), _nested(50_000), "[" * 400_000 + "x" + "]" * 400_000, "- " * 300_000 + "x",
        "x-" * 300_000 + "x", "(x, " * 100_000 + "x" + ")" * 100_000,
    ],
    ids=["101", "50000", "lists", "prefix-operators", "infix-operators", "brackets-and-commas"],
)
def test_a_deeply_nested_fact_is_refused_and_python_lives_on(tmp_path: Path, nested: str) -> None:
    """Parsed past the C stack, such a fact killed the process (SIGSEGV): nothing printed."""
    path = tmp_path / "kb.pl"
    path.write_text(f"ok(1).\nobject(a, {nested}).\n")
    code = (
        "import sys\nfrom neurosym.prolog.knowledge_base import KnowledgeBase\n"
        "from neurosym.errors import PrologError\n"
        f"try:\n    KnowledgeBase({str(path)!r})\nexcept PrologError as exc:\n    print(exc)\n"
        "print('alive')\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=REPO)
    assert proc.returncode == 0, proc.stderr
    first, alive = proc.stdout.splitlines()
    assert first.startswith(f"cannot load {path}:2: found a term nested more than 100 levels deep")
    assert alive == "alive"


def test_a_fact_100_levels_deep_loads(tmp_path: Path) -> None:
    path = tmp_path / "kb.pl"
    path.write_text(f"object(a, {_nested(99)}).\nlist([{','.join(['g(1)'] * 5000)}]).\n")
    with KnowledgeBase(path) as kb:
        assert str(kb.once("object(a, X)")["X"]).count("f(") == 99
        assert len(kb.once("list(L)")["L"]) == 5000


def test_text_that_is_not_utf8_is_refused_in_one_line(neurosym_main, tmp_path: Path) -> None:
    path = tmp_path / "kb.pl"
    path.write_bytes(b"object(a, b).\nobject(\xff\xfe, \x80).\n")
    proc = neurosym_main("query", "--kb", path, "object(X, Y)")
    assert proc.returncode == 1 and proc.stdout == ""
    assert proc.stderr.count("\n") == 1, proc.stderr
    assert proc.stderr.startswith(f"neurosym query: error: cannot load {path}: ")
    assert "Illegal UTF-8 start" in proc.stderr
    latin = tmp_path / "latin.pl"
    latin.write_bytes(b":- encoding(iso_latin_1).\nobject(a, '\xe9t\xe9').\n")
    with KnowledgeBase(latin) as kb:  # a file that says its encoding reads as it says
        assert kb.query("object(a, X)") == [{"X": "été"}]


# --- read once: what is checked is what is compiled and loaded ---------------------


def test_a_source_swapped_after_its_check_is_not_compiled(
    tmp_path: Path, marker: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A writer on a shared drive swaps the file between the check and the compile."""
    source = tmp_path / "kb.pl"
    source.write_text("ok(1).\n")
    checked = KnowledgeBase._read_facts

    def check_then_swap(self, path, mode, copy=None):
        count = checked(self, path, mode, copy)
        if mode == "check":
            source.write_text(f"ok(666).\n:- initialization({_touch(marker)}).\n")
        return count

    monkeypatch.setattr(KnowledgeBase, "_read_facts", check_then_swap)
    with KnowledgeBase(source, qlf=True) as kb:
        assert kb.query("ok(X)") == [{"X": 1}]  # the bytes that were checked
    assert not marker.exists()
    monkeypatch.undo()
    with pytest.raises(PrologError, match=rf"^cannot load {source}:2: found a directive"):
        KnowledgeBase(source, qlf=True)  # the .qlf is not the new source's: that is checked again
    assert not marker.exists()


def test_a_qlf_swapped_after_its_signature_check_is_not_loaded(
    swipl: Path, tmp_path: Path, marker: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    source = tmp_path / "kb.pl"
    source.write_text("ok(1).\n")
    with KnowledgeBase(source, qlf=True) as kb:  # compiled and signed
        assert kb.query("ok(X)") == [{"X": 1}]
    evil = _attacker_qlf(swipl, tmp_path, marker, stem="evil")
    from neurosym.prolog import signature

    checked = signature.check_digests

    def check_then_swap(*args, **kwargs):
        reason = checked(*args, **kwargs)
        if evil.exists():
            os.replace(evil, source.with_suffix(".qlf"))
        return reason

    monkeypatch.setattr(signature, "check_digests", check_then_swap)
    with KnowledgeBase(source, qlf=True) as kb:
        assert kb.query("ok(X)") == [{"X": 1}]  # the bytes whose signature was checked
    assert not marker.exists()
    monkeypatch.undo()
    with pytest.raises(PrologError, match="it is not the file kb.qlf.sig signed"):
        KnowledgeBase(source.with_suffix(".qlf"))  # the swapped-in .qlf, loaded directly
    assert not marker.exists()


def test_a_read_only_folder_for_qlf_is_one_line(
    neurosym_main, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    source = tmp_path / "kb.pl"
    source.write_text("ok(1).\n")
    import tempfile

    made = tempfile.mkstemp

    def read_only(*args, dir=None, **kwargs):
        if dir is not None and Path(dir) == tmp_path:
            raise OSError(30, "Read-only file system")
        return made(*args, dir=dir, **kwargs)

    monkeypatch.setattr(tempfile, "mkstemp", read_only)
    with pytest.raises(NeurosymError) as info:
        KnowledgeBase(source, qlf=True)
    assert str(info.value) == (
        f"cannot write {source.with_suffix('.qlf')}: Read-only file system; it was left as it "
        "was; load kb.pl without --qlf (qlf=False)"
    )
    assert not source.with_suffix(".qlf").exists()


def test_a_qlf_loaded_directly_is_the_checked_bytes(
    swipl: Path, tmp_path: Path, marker: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    source = tmp_path / "kb.pl"
    source.write_text("ok(1).\n")
    with KnowledgeBase(source, qlf=True):
        pass
    evil = _attacker_qlf(swipl, tmp_path, marker, stem="evil")
    from neurosym.prolog import signature

    checked = signature.check_digests

    def check_then_swap(*args, **kwargs):
        reason = checked(*args, **kwargs)
        os.replace(evil, source.with_suffix(".qlf"))
        return reason

    monkeypatch.setattr(signature, "check_digests", check_then_swap)
    with KnowledgeBase(source.with_suffix(".qlf")) as kb:
        assert kb.query("ok(X)") == [{"X": 1}]
    assert not marker.exists()
