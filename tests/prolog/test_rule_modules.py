"""The shipped rule files are modules: each KB gets its own copy, whose queries read that KB's
facts, and plain swipl loads them together with a KB (the facts in module user) without a word."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from neurosym.errors import PrologError
from neurosym.prolog.knowledge_base import KnowledgeBase
from neurosym.terms import Term

REPO = Path(__file__).resolve().parents[2]
RULES = REPO / "rules"
RGW_FACTS = RULES / "tests" / "rgw_facts.pl"

# Episode 7: the enemy first, then the sword; the network relates sword and enemy
# only through the teleport.
OTHER_KB = """\
:- dynamic holding/3, attention/6.
object(sword, sword).
object(tele_1, teleport).
episode(7, 9, 1.0, terminal).
event(7, 2, hurt_by(enemy)).
event(7, 4, picked(sword)).
event(7, 6, defeated(enemy)).
holds(7, 1, r(2), sword, teleport).
holds(7, 3, r(2), teleport, enemy).
"""


def test_two_kbs_with_the_same_rules_answer_from_their_own_facts(tmp_path: Path) -> None:
    other = tmp_path / "other.pl"
    other.write_text(OTHER_KB)
    kb1 = KnowledgeBase(RGW_FACTS, rules=["rgw", "relations"])
    kb2 = KnowledgeBase(other, rules=["rgw"])
    try:
        link = "sword_enemy_link(A), format(atom(T), '~q', [A])"
        assert kb1.query("sword_before_enemy(E)") == [{"E": 0}, {"E": 3}]
        assert kb2.query("sword_before_enemy(E)") == []
        assert kb2.query("teleport_before_enemy(E)") == []
        assert kb2.query("visit_order(E, O)") == [{"E": 7, "O": ("enemy", "sword")}]
        assert kb1.query(link)[0]["T"] == "direct([r(1),r(0)],share(4,124))"
        # sword-teleport at state 1, teleport-enemy at state 3: never within one step
        assert kb2.query(link)[0]["T"] == (
            "co_occurring([apart(teleport,share(1,9),share(1,9))])"
        )
        # each KB imports from its own copy of module rgw; relations only where it was loaded
        imported = "predicate_property(sword_before_enemy(_), imported_from(M))"
        assert kb1.query(imported) == [{"M": f"rgw@{kb1.module}"}]
        assert kb2.query(imported) == [{"M": f"rgw@{kb2.module}"}]
        with pytest.raises(PrologError, match="Unknown procedure: head/1"):
            kb2.query("head(H)")
        kb1.close()
        assert kb2.query("sword_enemy_link(A), format(atom(T), '~q', [A])")[0]["T"] == (
            "co_occurring([apart(teleport,share(1,9),share(1,9))])"
        )
        with KnowledgeBase(RGW_FACTS, rules=["rgw"]) as kb3:  # after kb1 closed
            assert kb3.query("optimal_order(E)") == [{"E": 0}]
    finally:
        kb1.close()
        kb2.close()


def test_a_fact_for_an_exported_rule_is_refused(tmp_path: Path) -> None:
    facts = tmp_path / "kb.pl"
    facts.write_text("episode(0, 1, 1.0, terminal).\nsword_before_enemy(0).\n")
    with pytest.raises(
        PrologError,
        match=rf"{facts}:2: found a fact for sword_before_enemy/1, which the rules import "
        "from module rgw",
    ):
        KnowledgeBase(facts, rules=["rgw"])


def test_facts_a_kb_lacks_altogether_are_no_error_for_causal_and_meaning(tmp_path: Path) -> None:
    """A probe KB without holds/5, a KB of experiments without relates/4: nothing declared."""
    probes = tmp_path / "probe.pl"
    probes.write_text("probe(0, 3, holding(sword), 0.95, 0.6).\n")
    with KnowledgeBase(probes, rules=["meaning"]) as kb:
        assert kb.query("relation_name(R, P, S)") == [
            {"R": Term("r", (3,)), "P": Term("holding", ("sword",)), "S": pytest.approx(0.35)}
        ]
        assert kb.query("named_holds(E, T, N, A, B)") == []
        assert kb.query("training_added(H, J, P, G)") == []
    experiments = tmp_path / "intervene.pl"
    experiments.write_text("experiment(baseline, baseline, none).\n")
    with KnowledgeBase(experiments, rules=["causal"]) as kb:
        assert kb.query("sword_enemy_cause(A)") == [{"A": "none"}]


def test_a_module_rule_file_of_ones_own(tmp_path: Path) -> None:
    """Written like the shipped ones, it serves several KBs; a broken one is said with its line."""
    mine = tmp_path / "mine.pl"
    mine.write_text(":- module(mine, [answer/1]).\nanswer(X) :- fact(X).\n")
    a, b = tmp_path / "a.pl", tmp_path / "b.pl"
    a.write_text("fact(1).\n")
    b.write_text("fact(2).\n")
    with KnowledgeBase(a, rules=[mine]) as kb_a, KnowledgeBase(b, rules=[mine]) as kb_b:
        assert kb_a.query("answer(X)") == [{"X": 1}]
        assert kb_b.query("answer(X)") == [{"X": 2}]
    broken = tmp_path / "broken.pl"
    broken.write_text(":- module(broken, [p/1]).\np(X :- q.\n")
    for _ in range(2):  # every KB that loads it is told
        with pytest.raises(PrologError, match=rf"cannot load {broken}:2:"):
            KnowledgeBase(None, rules=[broken])


def _toplevel(swipl: Path, files: list[Path], queries: str) -> subprocess.CompletedProcess[str]:
    """``swipl -q FILES`` answering ``queries`` at its top level (read from stdin)."""
    return subprocess.run(
        [str(swipl), "-q", *map(str, files)],
        input=queries, capture_output=True, text=True, timeout=60,
    )  # fmt: skip


def test_plain_swipl_loads_the_rule_files_together_and_answers_at_the_top_level(
    swipl: Path,
) -> None:
    rules = [RULES / "rgw.pl", RULES / "relations.pl", RULES / "boxworld.pl"]
    proc = _toplevel(
        swipl,
        [RGW_FACTS, *rules],
        "sword_enemy_link(A).\n"
        "findall(E, sword_before_enemy(E), Es).\n"
        "findall(J-B, consistently_orders(J, sword, B), L).\n",
    )
    assert (proc.returncode, proc.stderr) == (0, "")
    assert proc.stdout == (
        "A = direct([r(1), r(0)], share(4, 124)).\n\n"
        "Es = [0, 3].\n\n"
        "L = [1-enemy, 2-teleport, 0-empty].\n\n\n"  # the last line: the top level's halt
    )
    proc = _toplevel(
        swipl,
        [RULES / "tests" / "boxworld_facts.pl", *reversed(rules)],
        "findall(C, solution_chain(0, C), Cs).\n",
    )
    assert (proc.returncode, proc.stderr) == (0, "")
    assert proc.stdout == "Cs = [[key(red), key(blue), gem]].\n\n\n"
