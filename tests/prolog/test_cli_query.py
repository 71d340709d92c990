"""`neurosym query` on real files: through ``main()`` in this process where its exit code and
output are what is checked, as a subprocess where the process is (Ctrl-C, closed pipes,
rlimits, a FIFO that an in-process read could hang on)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from neurosym.terms import atom_text

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


def test_json_and_csv(neurosym_main, kb_files: tuple[Path, Path]) -> None:
    facts, rules = kb_files
    proc = neurosym_main(
        "query", "--kb", facts, "--rules", rules, "--json", "event(E, T, Ev), path(1, P)"
    )
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout) == [
        {"E": 0, "T": 3, "Ev": "picked(sword)", "P": ["a", "f(x)"]},
        {"E": 0, "T": 5, "Ev": "opened(lock(red))", "P": ["a", "f(x)"]},
    ]
    proc = neurosym_main("query", "--kb", facts, "--csv", "object(Id, Type)")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == "Id,Type\nagent,agent\ns1,sword\nIt's,key(red)\n"


def test_table_limit_and_bind(neurosym_main, kb_files: tuple[Path, Path]) -> None:
    facts, rules = kb_files
    proc = neurosym_main("query", "--kb", facts, "--rules", rules, "picked_item(E, I)")
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert any("E" in ln and "I" in ln for ln in lines[:3])
    assert any("sword" in ln for ln in lines)
    assert lines[-1] == "1 answer"
    proc = neurosym_main("query", "--kb", facts, "--limit", "1", "--csv", "object(Id, _)")
    assert proc.stdout == "Id\nagent\n"
    proc = neurosym_main(
        "query", "--kb", facts, "--bind", "Ev=opened(lock(red))", "--bind", "E=0", "--csv",
        "event(E, T, Ev)",
    )  # fmt: skip
    assert proc.stdout == "T\n5\n", proc.stderr


def test_goal_without_outputs_prints_true_or_false(
    neurosym_main, kb_files: tuple[Path, Path]
) -> None:
    facts, _ = kb_files
    assert neurosym_main("query", "--kb", facts, "object(s1, sword)").stdout == "true\n"
    assert neurosym_main("query", "--kb", facts, "object(s1, enemy)").stdout == "false\n"


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
        (
            ["--kb", "{dir}", "p(X)"],
            "cannot load {dir}: it is a folder; a Prolog file (.pl or .qlf) is a regular file",
        ),
        (["--kb", "{dir}/fifo.pl", "p(X)"], "cannot load {dir}/fifo.pl: it is a named pipe (FIFO);"),
        (["--kb", "/dev/null", "p(X)"], "cannot load /dev/null: it is a character device;"),
        (
            ["--kb", "{dir}/k\udcff.pl", "p(X)"],
            "cannot load {dir}/k\\xff.pl: its name is not valid UTF-8",
        ),
        (
            ["--kb", "{facts}", "--rules", "{dir}/r\udcff.pl", "p(X)"],
            "cannot load {dir}/r\\xff.pl: its name is not valid UTF-8",
        ),
    ],
)
def test_errors_are_one_line_and_exit_non_zero(
    request: pytest.FixtureRequest, kb_files: tuple[Path, Path], args: list[str], message: str
) -> None:
    facts, _ = kb_files
    (facts.parent / "bad.pl").write_text("p(.\n")
    os.mkfifo(facts.parent / "fifo.pl")
    for name in ("k\udcff.pl", "r\udcff.pl"):  # byte 0xff: not UTF-8
        (facts.parent / name).write_text("p(1).\n")
    fill = {"dir": str(facts.parent), "facts": str(facts)}
    # a FIFO in a subprocess: if a regression opened it, the run would block, and the
    # subprocess' timeout ends it where an in-process run would hang the suite
    runner = request.getfixturevalue("run_neurosym" if "fifo" in args[1] else "neurosym_main")
    proc = runner("query", *(a.format(**fill) for a in args))
    assert proc.returncode == 1
    assert proc.stdout == ""
    assert proc.stderr.count("\n") == 1, proc.stderr
    assert proc.stderr.startswith("neurosym query: error: ")
    assert message.format(**fill) in proc.stderr


def test_load_warnings_go_to_stderr(neurosym_main, kb_files: tuple[Path, Path]) -> None:
    facts, _ = kb_files
    rules = facts.parent / "w.pl"
    rules.write_text("p(X) :- true.\n")
    proc = neurosym_main("query", "--kb", facts, "--rules", rules, "--csv", "p(1)")
    assert proc.returncode == 0
    assert proc.stdout == "\n\n"  # no output variables: an empty header, one empty row
    assert proc.stderr == f"neurosym query: warning: {rules}:1: Singleton variables: [X]\n"


def test_help_lists_every_shipped_rule_file(neurosym_main) -> None:
    from neurosym.shipped import rules_dir

    folder = rules_dir()
    assert folder is not None
    names = sorted(p.stem for p in folder.glob("*.pl"))
    assert "route" in names
    text = " ".join(neurosym_main("query", "--help").stdout.split())
    assert f"a shipped one by name ({', '.join(names)})" in text


def test_a_file_size_limit_is_named_not_read_errors(tmp_path: Path) -> None:
    """Writing the private copy past RLIMIT_FSIZE is a write error, said as one."""
    import resource

    facts = tmp_path / "kb.pl"
    facts.write_text("".join(f"p({i}).\n" for i in range(40_000)))  # 400 KB

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (100_000, 100_000))

    repo = Path(__file__).resolve().parents[2]
    env = {**os.environ, "PYTHONPATH": str(repo), "PYTHONDONTWRITEBYTECODE": "1"}
    proc = subprocess.run(
        [sys.executable, "-m", "neurosym", "query", "--kb", str(facts), "p(1)"],
        capture_output=True, text=True, env=env, cwd=repo, preexec_fn=limit, timeout=300,
    )  # fmt: skip
    assert proc.returncode == 1, proc.stderr
    assert proc.stderr.count("\n") == 1, proc.stderr
    assert proc.stderr.startswith(
        f"neurosym query: error: cannot load {facts}: neurosym reads a private copy of every "
        "file it loads and could not write it to "
    )
    assert proc.stderr.endswith(
        ": File too large (the file-size limit, ulimit -f, is smaller than the file)\n"
    )


# --- output shown as text, whole or not at all -----------------------------------

HOSTILE = """\
object(a, '[link=https://evil.example]click[/link]').
object(b, '\\e[31mred\\e[0m').
object(c, [x, y]).
link(indirect([agent])).
"""


def test_the_table_shows_data_as_text(neurosym_main, tmp_path: Path) -> None:
    facts = tmp_path / "kb.pl"
    facts.write_text(HOSTILE)
    proc = neurosym_main("query", "--kb", facts, "link(How)")
    assert proc.returncode == 0, proc.stderr
    assert "indirect([agent])" in proc.stdout
    proc = neurosym_main("query", "--kb", facts, "object(Id, T)")
    assert proc.returncode == 0, proc.stderr
    assert "[link=https://evil.example]click[/link]" in proc.stdout
    assert "\\e[31mred\\e[0m" in proc.stdout and "\x1b" not in proc.stdout
    assert "[x,y]" in proc.stdout


def test_sword_enemy_link_prints_its_list(neurosym_main, tmp_path: Path) -> None:
    from builders import REPO

    facts = tmp_path / "kb.pl"
    facts.write_text(
        ":- dynamic attention/6.\nobject(s1, sword).\nobject(e1, enemy).\n"
        "holds(0, 1, r(1), sword, agent).\nholds(0, 1, r(1), agent, enemy).\n"
    )
    proc = neurosym_main("query", "--kb", facts, "--rules", REPO / "rules" / "rgw.pl", "sword_enemy_link(How)")
    assert proc.returncode == 0, proc.stderr
    # no episode/4 facts: the share is of the one state with network facts
    assert "indirect([via(agent,share(1,1))])" in proc.stdout


def test_json_writes_infinities_as_text(neurosym_main, tmp_path: Path) -> None:
    facts = tmp_path / "kb.pl"
    facts.write_text("ok(1).\n")
    proc = neurosym_main("query", "--kb", facts, "--json", "X is inf, Y is -inf, Z is nan")
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout) == [{"X": "inf", "Y": "-inf", "Z": "nan"}]


def test_answers_holding_variables_print_with_names(neurosym_main, tmp_path: Path) -> None:
    facts = tmp_path / "kb.pl"
    facts.write_text("ok(1).\n")
    proc = neurosym_main("query", "--kb", facts, "--json", "X = f(Y, Z, [Y])")
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout) == [{"X": "f(_G1,_G2,[_G1])", "Y": None, "Z": None}]
    proc = neurosym_main("query", "--kb", facts, "X = f(Y)")
    assert proc.returncode == 0, proc.stderr
    assert "f(_G1)" in proc.stdout and proc.stdout.endswith("1 answer\n")


@pytest.mark.parametrize(
    ("goal", "message"),
    [
        ("length(L, 10000), foldl([_, A, f(A)]>>true, L, x, T)", "an answer is nested more than 100 levels deep"),
        ("X = f(X)", "an answer is nested more than 100 levels deep (or is cyclic)"),
        ("X is 10^5000", "an answer holds an integer of more than 4,300 digits"),
    ],
)  # fmt: skip
@pytest.mark.parametrize("fmt", ["json", "csv", "table"])
def test_answers_python_cannot_take_are_one_line_and_print_nothing(
    neurosym_main, tmp_path: Path, goal: str, message: str, fmt: str
) -> None:
    facts = tmp_path / "kb.pl"
    facts.write_text("ok(1).\n")
    proc = neurosym_main("query", "--kb", facts, *{"table": []}.get(fmt, [f"--{fmt}"]), goal)
    assert proc.returncode == 1
    assert proc.stdout == ""
    assert proc.stderr == f"neurosym query: error: {message}" + proc.stderr.split(message, 1)[1]
    assert proc.stderr.count("\n") == 1


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--timeout", "inf"], "--timeout must be a positive number of seconds up to 1,000,000,000, not inf"),
        (["--timeout", "nan"], "--timeout must be a positive number"),
        (["--max-inferences", str(10**23)], "--max-inferences must be from 1 to 2**63-1"),
        (["--stack-limit", "inf"], "--stack-limit must be from 1 to 1,048,576 (MB)"),
        (["X"], "the goal is a variable; give a goal such as object(Id, Type)"),
        (["42"], "the goal 42 is not something to run"),
        (["ok(X). halt(3)"], "the goal has text after its full stop (halt(3))"),
        (["ok(X). ok("], "the goal has text after its full stop (ok()"),
        (["--bind", "A=" + "f(" * 150 + "x" + ")" * 150, "ok(A)"], "a term nested more than 100 levels deep"),
        (["f(" * 20000 + "x" + ")" * 20000], "the goal could nest more than 5,000 levels deep"),
        (["X = " + "- " * 20000 + "x"], "the goal could nest more than 5,000 levels deep"),
    ],
)  # fmt: skip
def test_bad_bounds_and_goals_are_refused_in_one_line(
    neurosym_main, tmp_path: Path, args: list[str], message: str
) -> None:
    facts = tmp_path / "kb.pl"
    facts.write_text("ok(1).\n")
    if args[0].startswith("--") and not args[0].startswith("--bind"):
        args = [*args, "ok(X)"]
    proc = neurosym_main("query", "--kb", facts, *args)
    assert proc.returncode == 1, proc.stdout
    assert proc.stdout == ""
    assert proc.stderr.count("\n") == 1, proc.stderr
    assert proc.stderr.startswith("neurosym query: error: ")
    assert message in proc.stderr


def test_a_goal_ending_in_a_full_stop_or_comment_is_one_goal(neurosym_main, tmp_path) -> None:
    facts = tmp_path / "kb.pl"
    facts.write_text("ok(1).\n")
    for goal in ("ok(X).", "ok(X). % a comment", "X = 'a. b'"):
        proc = neurosym_main("query", "--kb", facts, "--csv", goal)
        assert proc.returncode == 0, proc.stderr


# --- Ctrl-C and closed pipes ------------------------------------------------------


def _popen(tmp_path: Path, *args: object, **kw) -> subprocess.Popen:
    from builders import REPO

    path = os.pathsep.join(p for p in (str(REPO), os.environ.get("PYTHONPATH")) if p)
    return subprocess.Popen(
        [sys.executable, "-m", "neurosym", "query", *map(str, args)],
        cwd=REPO, env={**os.environ, "PYTHONPATH": path}, stderr=subprocess.PIPE, text=True, **kw,
    )  # fmt: skip


def test_ctrl_c_stops_any_goal_with_130_and_one_line(tmp_path: Path) -> None:
    facts = tmp_path / "kb.pl"
    facts.write_text("ok(1).\n")
    started = tmp_path / "started"
    goal = f"open({atom_text(str(started))}, write, S), close(S), repeat, fail"
    proc = _popen(tmp_path, "--kb", facts, goal, stdout=subprocess.PIPE)
    try:
        while not started.exists():  # the goal is running
            assert proc.poll() is None, proc.stderr.read()
            time.sleep(0.05)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert proc.returncode == 130
    assert err == "neurosym query: interrupted\n"


@pytest.mark.subprocess
def test_a_closed_pipe_ends_quietly(tmp_path: Path) -> None:
    facts = tmp_path / "kb.pl"
    facts.write_text("".join(f"ok({i}).\n" for i in range(20000)))
    for fmt in ("csv", "json", "table"):
        proc = _popen(tmp_path, "--kb", facts, *{"table": []}.get(fmt, [f"--{fmt}"]), "ok(X)",
                      stdout=subprocess.PIPE)  # fmt: skip
        proc.stdout.close()  # the reader is gone before anything is written
        _, err = proc.communicate(timeout=120)
        assert err == "" and proc.returncode == 141, (fmt, err)
