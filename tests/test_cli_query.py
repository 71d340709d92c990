"""`neurosym query` run as users run it: a subprocess on real files."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

FACTS = """\
object(agent, agent).
object(s1, sword).
object('It''s', 'key(red)').
event(0, 3, picked(sword)).
event(0, 5, opened(lock(red))).
path(1, [a, f(x)]).
"""
RULES = "picked_item(E, I) :- event(E, _, picked(I)).\n"


@pytest.fixture
def kb_files(tmp_path: Path) -> tuple[Path, Path]:
    facts, rules = tmp_path / "kb.pl", tmp_path / "rules.pl"
    facts.write_text(FACTS)
    rules.write_text(RULES)
    return facts, rules


def test_json_and_csv(run_neurosym, kb_files: tuple[Path, Path]) -> None:
    facts, rules = kb_files
    proc = run_neurosym(
        "query", "--kb", facts, "--rules", rules, "--format", "json", "event(E, T, Ev), path(1, P)"
    )
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout) == [
        {"E": 0, "T": 3, "Ev": "picked(sword)", "P": ["a", "f(x)"]},
        {"E": 0, "T": 5, "Ev": "opened(lock(red))", "P": ["a", "f(x)"]},
    ]
    proc = run_neurosym("query", "--kb", facts, "--format", "csv", "object(Id, Type)")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == "Id,Type\nagent,agent\ns1,sword\nIt's,key(red)\n"


def test_table_limit_and_bind(run_neurosym, kb_files: tuple[Path, Path]) -> None:
    facts, rules = kb_files
    proc = run_neurosym("query", "--kb", facts, "--rules", rules, "picked_item(E, I)")
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert any("E" in ln and "I" in ln for ln in lines[:3])
    assert any("sword" in ln for ln in lines)
    assert lines[-1] == "1 answer"
    proc = run_neurosym("query", "--kb", facts, "--limit", "1", "--format", "csv", "object(Id, _)")
    assert proc.stdout == "Id\nagent\n"
    proc = run_neurosym(
        "query", "--kb", facts, "--bind", "Ev=opened(lock(red))", "--bind", "E=0", "--format", "csv",
        "event(E, T, Ev)",
    )  # fmt: skip
    assert proc.stdout == "T\n5\n", proc.stderr


def test_goal_without_outputs_prints_true_or_false(
    run_neurosym, kb_files: tuple[Path, Path]
) -> None:
    facts, _ = kb_files
    assert run_neurosym("query", "--kb", facts, "object(s1, sword)").stdout == "true\n"
    assert run_neurosym("query", "--kb", facts, "object(s1, enemy)").stdout == "false\n"


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--kb", "{dir}/missing.pl", "object(X, Y)"], "no such Prolog file: {dir}/missing.pl"),
        (["--kb", "{facts}", "object(X"], "Syntax error: Operator expected"),
        (["--kb", "{facts}", "nope(X)"], "Unknown procedure: nope/1"),
        (
            ["--kb", "{facts}", "--bind", "x=1", "object(X, Y)"],
            "input 'x' is not a Prolog variable name",
        ),
        (["--kb", "{facts}", "--bind", "X", "object(X, Y)"], "expected NAME=TERM"),
        (["--kb", "{facts}", "--limit", "0", "object(X, Y)"], "--limit must be at least 1"),
        (["--kb", "{dir}/bad.pl", "p(X)"], "cannot load {dir}/bad.pl:1:"),
    ],
)
def test_errors_are_one_line_and_exit_non_zero(
    run_neurosym, kb_files: tuple[Path, Path], args: list[str], message: str
) -> None:
    facts, _ = kb_files
    (facts.parent / "bad.pl").write_text("p(.\n")
    fill = {"dir": str(facts.parent), "facts": str(facts)}
    proc = run_neurosym("query", *(a.format(**fill) for a in args))
    assert proc.returncode == 1
    assert proc.stdout == ""
    assert proc.stderr.count("\n") == 1, proc.stderr
    assert proc.stderr.startswith("neurosym query: error: ")
    assert message.format(**fill) in proc.stderr


def test_load_warnings_go_to_stderr(run_neurosym, kb_files: tuple[Path, Path]) -> None:
    facts, _ = kb_files
    rules = facts.parent / "w.pl"
    rules.write_text("p(X) :- true.\n")
    proc = run_neurosym("query", "--kb", facts, "--rules", rules, "--format", "csv", "p(1)")
    assert proc.returncode == 0
    assert proc.stdout == "\n\n"  # no output variables: an empty header, one empty row
    assert "neurosym query: warning: " in proc.stderr and "Singleton variables: [X]" in proc.stderr
