"""A KB someone sent you runs nothing through ``neurosym induce`` and the files it writes.

Each hostile KB is a small real one edited so that a value (kb_meta, a path, a learned
constant, an object type) holds Prolog code that would run if it were pasted into the
learned file unquoted. Learning, then loading the learned file with ``neurosym play
--policy``, ``neurosym query --rules`` and plain ``swipl kb.pl learned.pl`` must leave no
marker file, and the learned file must read back as exactly the clauses learned.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest
from strategy_kbs import nearest_key_kb

from neurosym.cli import main
from neurosym.induce.strategy import induce_strategy
from neurosym.induce.strategy_features import BACKGROUND as STRATEGY_BACKGROUND
from neurosym.induce.strategy_route import PROLOG as ROUTE
from neurosym.induce.strategy_writer import LIBRARIES, learned_clauses
from neurosym.induce.world import BACKGROUND as WORLD_BACKGROUND
from neurosym.induce.world import DISCONTIGUOUS, induce_world

RUN = 'shell("touch hit")'
"""the code each hostile value carries: it leaves the file ``hit`` in the working folder"""

# The terms of a text, one line each, read by a plain swipl with read_term (nothing runs):
# variables by their names (`_` the anonymous ones), operators written as compounds.
READ_ALL = r"""
main :- read_term(user_input, T, [variable_names(Vs)]),
    (   T == end_of_file -> halt
    ;   maplist([N=V]>>(V = '$VAR'(N)), Vs), numbervars(T, 0, _, [singletons(true)]),
        write_term(T, [quoted(true), ignore_ops(true), numbervars(true)]), nl, main ).
"""


def terms(swipl: Path, text: str, tmp: Path) -> list[str]:
    """Every term of ``text`` as read by SWI-Prolog's read_term, in canonical text."""
    script = tmp / "read_all.pl"
    script.write_text(READ_ALL)
    done = subprocess.run(
        [str(swipl), "-q", "-g", "main", "-t", "halt(1)", str(script)],
        input=text, capture_output=True, text=True, cwd=tmp, timeout=60,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    return done.stdout.splitlines()


def strategy_kb(path: Path, meta: tuple[str, str] = ("", ""), type_: str = "") -> Path:
    """The nearest-key KB, with a kb_meta fact replaced (old, new) or the keys' type replaced."""
    nearest_key_kb(path, 12, seed=3)
    text = path.read_text()
    if meta[0]:
        assert meta[0] in text
        text = text.replace(*meta)
    if type_:  # keys of another type; the contact event is then `opened` (a contact by name)
        text = re.sub(r"object\(key_(\w+),key\(\w+\)\)", lambda m: f"object(key_{m[1]},{type_}({m[1]}))", text)
        text = re.sub(r"event\((\d+),(\d+),got\(key\(\w+\)\)\)", r"event(\1,\2,opened)", text)
    path.write_text(text)
    return path


STRATEGY_CASES = {
    "checkpoint": {"meta": ("kb_meta(env,bw1).", f"kb_meta(env,bw1).\nkb_meta(checkpoint,'x */ :- {RUN}. /* ').")},
    "env": {"meta": ("kb_meta(env,bw1).", f"kb_meta(env,'bw1 */ :- {RUN}. /* ').")},
    "module": {"meta": ("kb_meta(module,predinet).", f"kb_meta(module,'x */ :- {RUN}. /* ').")},
    "path": {"folder": f"x */ :- {RUN}. /* "},
    "type": {"type_": f"'key(x). :- {RUN}. k(y'"},
}


@pytest.mark.parametrize("case", sorted(STRATEGY_CASES))
def test_a_hostile_kb_learns_a_strategy_that_runs_nothing(
    case: str, swipl: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    spec = dict(STRATEGY_CASES[case])
    folder = tmp_path / spec.pop("folder", "kb")
    folder.mkdir(parents=True)  # a "/" in the name is a folder of its own
    kb = strategy_kb(folder / "kb.pl", **spec)
    strategy = induce_strategy(kb, "world")
    out = strategy.write(tmp_path / "learned.pl")
    assert strategy.model.clauses
    assert main(["play", "--policy", str(out), "--env", "bw1", "--episodes", "1",
                 "--env-option", "max_steps=3"]) == 0  # fmt: skip
    query = ["query", "--kb", str(kb), "--rules", "route", "--rules", str(out), "goal(0, 0, O)"]
    assert main([*query, "--limit", "1"]) == 0  # its route features call route.pl's route_moves/4
    loads_in_plain_swipl(swipl, kb, out, tmp_path)
    learned = "".join(f"{term} .\n" for _, term in learned_clauses(strategy))
    want = [*terms(swipl, LIBRARIES, tmp_path), *terms(swipl, learned, tmp_path),
            *terms(swipl, STRATEGY_BACKGROUND + ROUTE, tmp_path)]  # fmt: skip
    assert terms(swipl, out.read_text(), tmp_path) == want
    if case == "type":
        assert "route_not_longer(E, T, O, 'key(x). :- shell(\"touch hit\"). k(y')" in out.read_text()


def loads_in_plain_swipl(swipl: Path, kb: Path, learned: Path, where: Path) -> None:
    """``swipl kb.pl learned.pl`` loads without error, and the marker file never appears."""
    plain = subprocess.run(
        [str(swipl), "-q", "-g", "halt", str(kb), str(learned)], capture_output=True, text=True,
        cwd=where, timeout=60,
    )  # fmt: skip
    assert plain.returncode == 0, plain.stderr
    assert not (where / "hit").exists()


WORLD_CASES = {
    "env": {"meta": f"kb_meta(env,'rgw */\\n:- {RUN}. /* ')."},  # a newline: a % comment ends
    "constant": {"wall": f"'x). :- {RUN}. zz(y'"},
    "path": {"folder": f"x */ :- {RUN}. /* "},
}


@pytest.mark.parametrize("case", sorted(WORLD_CASES))
def test_a_hostile_kb_learns_world_rules_that_run_nothing(
    hostile_world_kb,
    case: str, world_kb: Path, swipl: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    spec = dict(WORLD_CASES[case])
    kb = hostile_world_kb(world_kb, tmp_path / spec.pop("folder", "kb") / "kb.pl", **spec)
    rules = induce_world(kb, holdout=kb)
    out = rules.write(tmp_path / "world.pl")
    assert main(["query", "--kb", str(kb), "--rules", str(out), "predicts(E, T, X)", "--limit", "1"]) == 0
    loads_in_plain_swipl(swipl, kb, out, tmp_path)
    learned = "".join(f"{c.term()} .\n" for c in rules.clauses)
    want = [*terms(swipl, DISCONTIGUOUS, tmp_path), *terms(swipl, learned, tmp_path),
            *terms(swipl, WORLD_BACKGROUND, tmp_path)]  # fmt: skip
    assert terms(swipl, out.read_text(), tmp_path) == want
    if case == "constant":
        assert rules.scores["bumped(wall)"].clauses[0].text() == (
            "predicts(E, T, bumped(wall)) :-\n    ahead(E, T, 'x). :- shell(\"touch hit\"). zz(y')."
        )
