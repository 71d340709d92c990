"""The learned strategy as a Prolog file that loads in plain swipl beside a KB."""

from __future__ import annotations

from typing import TYPE_CHECKING

from neurosym.errors import ConfigError
from neurosym.facts.schema import indicators
from neurosym.induce.readback import Code, Part, comment
from neurosym.induce.strategy_features import (
    BACKGROUND,
    E_,
    O_,
    T_,
    V_,
    Feature,
    goal_term,
    goal_text,
)
from neurosym.induce.strategy_route import PROLOG as ROUTE
from neurosym.induce.strategy_tree import Clause, simplify
from neurosym.terms import Term, Var, format_value

if TYPE_CHECKING:
    from neurosym.induce.strategy import Strategy

LEARNERS = {
    "covering": "sequential covering over tests of (state, candidate object) features, each clause "
    "grown greedily to raise right - wrong choices on the states no earlier clause decides",
    "tree": "a scikit-learn decision tree over (state, candidate object) pairs, one clause per leaf "
    "holding next objects, ordered by their share",
}

def _reads(*names: str) -> str:
    """``name/arity, ...`` of the named predicates, arities from the schema."""
    return ", ".join(indicators(names))


_WORLD = _reads("at", "holding", "object", "grid", "terrain")
_NETWORK = _reads("attends", "holds", "attention")
READS = {
    "world": _WORLD,
    "relations": f"{_reads('at')} and {_reads('object')} (to map cells and entities to objects), "
    + _NETWORK,
    "both": f"{_WORLD}, {_NETWORK}",
}
"""the facts each feature set reads, as the learned file's notes name them"""


def threshold(x: float) -> int | float:
    """A numeric test's bound as written: an integral bound as an integer (``V1 =< 3``)."""
    return int(x) if float(x).is_integer() and abs(x) < 2**53 else float(x)


def body(clause: Clause, features: list[Feature]) -> list[Term]:
    """The literals of one clause, candidate first, numeric bounds as comparisons."""
    lits = [goal_term("goal_candidate", E_, T_, O_)]
    names: dict[int, str] = {}
    tests = simplify(clause.tests, features)
    if any(features[t.feature].name.startswith("kind=") and not t.low for t in tests):
        # O's kind is fixed by a positive test: tests that it is not of another kind are implied
        tests = [t for t in tests if not (features[t.feature].name.startswith("kind=") and t.low)]
    negated = []
    for test in tests:
        f = features[test.feature]
        if f.numeric:
            var = Var(names.setdefault(test.feature, f"V{len(names) + 1}"))
            goal = Term(f.term.functor, tuple(var if a == V_ else a for a in f.term.args))
            if goal not in lits:
                lits.append(goal)
            lits.append(Term("=<" if test.low else ">", (var, threshold(test.threshold))))
        elif test.low:
            negated.append(Term("\\+", (f.term,)))
        else:
            lits.append(f.term)
    # positive goals before negations so every variable is bound when \+ runs
    return lits + negated


def literal_text(goal: Term) -> str:
    """One body literal as it is written: ``\\+ g``, ``V1 =< 3``, else ``pred(E, T, O)``."""
    if goal.functor == "\\+":
        return "\\+ " + literal_text(goal.args[0])  # type: ignore[arg-type]
    if goal.functor in ("=<", ">"):
        left, right = goal.args
        return f"{format_value(left)} {goal.functor} {format_value(right)}"
    return goal_text(goal)


def clause_term(lits: list[Term]) -> Term:
    """``goal(E, T, O) :- lits`` as the term its text must read back as."""
    body_term = lits[-1]
    for lit in reversed(lits[:-1]):
        body_term = Term(",", (lit, body_term))
    return Term(":-", (goal_term("goal", E_, T_, O_), body_term))


def learned_clauses(strategy: Strategy) -> list[tuple[str, Term]]:
    """Each goal/3 clause's text, a comment first (how often it was right in training), and term."""
    out = []
    for i, clause in enumerate(strategy.model.clauses, 1):
        lits = body(clause, strategy.model.features)
        if strategy.model.learner == "covering":
            note = f"right in {clause.share:.3f} of the {clause.pairs} training states it decides"
        else:
            note = f"{clause.share:.3f} of its {clause.pairs} training pairs are next objects"
        text = (
            f"% clause {i}: {note}\n"
            "goal(E, T, O) :-\n    " + ",\n    ".join(literal_text(x) for x in lits) + ".\n"
        )
        out.append((text, clause_term(lits)))
    return out


def clauses_text(strategy: Strategy) -> str:
    """The goal/3 clauses, each with a comment: how often it was right in training."""
    return "\n".join(text for text, _ in learned_clauses(strategy))


HEADER = """/** <module> Learned strategy: the object the agent goes for next

goal(E, T, Object): the object the agent goes for next in state T of episode E.
The clauses are a decision list: the FIRST answer of goal/3 is the choice.
Where and how it was learned, and its scores, follow in the % lines below.

Load it beside a KB of the same schema and rules/route.pl (its route lengths
call route_moves/4 there; every other predicate below is defined here):
  ?- consult('kb.pl'), consult('rules/route.pl'), consult('strategy.pl'), goal(0, 0, O).
*/
"""
"""The PlDoc header: fixed text only (data goes in one-line ``%`` comments)."""

LIBRARIES = ":- use_module(library(lists)).\n:- use_module(library(aggregate)).\n"


def render(strategy: Strategy) -> str:
    """The whole file: features line, PlDoc header, goal/3, background predicates."""
    return render_parts(strategy)[0]


def render_parts(strategy: Strategy) -> tuple[str, list[Part]]:
    """The whole file's text and what it must read back as (:mod:`neurosym.induce.readback`)."""
    meta = strategy.meta
    model = strategy.model
    if strategy.features not in READS:
        raise ConfigError(f"unknown feature set {strategy.features!r}; use one of {', '.join(READS)}")
    notes = [
        f"Learned by `neurosym induce strategy` from {strategy.kb}",
        f"(checkpoint {meta.get('checkpoint', '?')}, env {meta.get('env', '?')}, "
        f"module {meta.get('module', '?')}).",
        f"Features: {strategy.features} (reads {READS[strategy.features]}).",
        f"Learner: {LEARNERS[model.learner]}; {len(model.clauses)} clauses "
        f"(at most {strategy.max_clauses}).",
        f"Scores: fidelity {strategy.fidelity:.4f} on {strategy.states} held-out states "
        f"({strategy.holdout});",
        f"{strategy.train_fidelity:.4f} on the {strategy.train_states} training states.",
        f"Learning took {strategy.seconds:.1f} s.",
    ]
    clauses = learned_clauses(strategy)
    text = (
        f"%! features: {strategy.features}\n"
        + HEADER
        + "".join(comment(n) + "\n" for n in notes)
        + "\n"
        + LIBRARIES
        + "\n"
        + "\n".join(t for t, _ in clauses)
        + "\n% Background predicates\n"
        + BACKGROUND
        + ROUTE
    )
    parts: list[Part] = [Code(LIBRARIES), *(term for _, term in clauses), Code(BACKGROUND + ROUTE)]
    return text, parts
