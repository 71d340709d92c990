"""The learned strategy as a Prolog file that loads in plain swipl beside a KB."""

from __future__ import annotations

from typing import TYPE_CHECKING

from neurosym.induce.strategy_features import BACKGROUND, Feature
from neurosym.induce.strategy_route import PROLOG as ROUTE
from neurosym.induce.strategy_tree import Clause, simplify

if TYPE_CHECKING:
    from neurosym.induce.strategy import Strategy

LEARNERS = {
    "covering": "sequential covering over tests of (state, candidate object) features, each clause "
    "grown greedily to raise right - wrong choices on the states no earlier clause decides",
    "tree": "a scikit-learn decision tree over (state, candidate object) pairs, one clause per leaf "
    "holding next objects, ordered by their share",
}

READS = {
    "world": "at/5, holding/3, object/2, grid/3, terrain/4",
    "relations": "at/5 and object/2 (to map cells and entities to objects), attends/8, holds/5, attention/6",
    "both": "at/5, holding/3, object/2, grid/3, terrain/4, attends/8, holds/5, attention/6",
}


def _number(x: float) -> str:
    return f"{x:g}" if "e" not in f"{x:g}" else repr(x)


def body(clause: Clause, features: list[Feature]) -> list[str]:
    """The literals of one clause, candidate first, numeric bounds as comparisons."""
    lits = ["goal_candidate(E, T, O)"]
    names: dict[int, str] = {}
    tests = simplify(clause.tests, features)
    if any(features[t.feature].name.startswith("kind=") and not t.low for t in tests):
        # O's kind is fixed by a positive test: tests that it is not of another kind are implied
        tests = [t for t in tests if not (features[t.feature].name.startswith("kind=") and t.low)]
    for test in tests:
        f = features[test.feature]
        if f.numeric:
            var = names.setdefault(test.feature, f"V{len(names) + 1}")
            goal = f.goal.replace("V)", f"{var})")
            if goal not in lits:
                lits.append(goal)
            lits.append(f"{var} {'=<' if test.low else '>'} {_number(test.threshold)}")
        else:
            lits.append(f"\\+ {f.goal}" if test.low else f.goal)
    # positive goals before negations so every variable is bound when \+ runs
    return [lits[0]] + [x for x in lits[1:] if not x.startswith("\\+")] + [
        x for x in lits[1:] if x.startswith("\\+")
    ]


def clauses_text(strategy: Strategy) -> str:
    """The goal/3 clauses, each with a comment: how often it was right in training."""
    out = []
    for i, clause in enumerate(strategy.model.clauses, 1):
        lits = body(clause, strategy.model.features)
        if strategy.model.learner == "covering":
            note = f"right in {clause.share:.3f} of the {clause.pairs} training states it decides"
        else:
            note = f"{clause.share:.3f} of its {clause.pairs} training pairs are next objects"
        out.append(
            f"% clause {i}: {note}\n"
            "goal(E, T, O) :-\n    " + ",\n    ".join(lits) + ".\n"
        )
    return "\n".join(out)


def render(strategy: Strategy) -> str:
    """The whole file: features line, PlDoc header, goal/3, background predicates."""
    meta = strategy.meta
    model = strategy.model
    header = f"""%! features: {strategy.features}
/** <module> Learned strategy: the object the agent goes for next

goal(E, T, Object): the object the agent goes for next in state T of episode E.
The clauses are a decision list: the FIRST answer of goal/3 is the choice.

Learned by `neurosym induce --what strategy` from {strategy.kb}
(checkpoint {meta.get('checkpoint', '?')}, env {meta.get('env', '?')}, module {meta.get('module', '?')}).
Features: {strategy.features} (reads {READS[strategy.features]}).
Learner: {LEARNERS[model.learner]}; {len(model.clauses)} clauses (at most {strategy.max_clauses}).
Scores: fidelity {strategy.fidelity:.4f} on {strategy.states} held-out states ({strategy.holdout});
{strategy.train_fidelity:.4f} on the {strategy.train_states} training states.
Learning took {strategy.seconds:.1f} s.

Load it beside a KB of the same schema (every predicate below is defined here):
  ?- consult('kb.pl'), consult('strategy.pl'), goal(0, 0, O).
*/

:- use_module(library(lists)).
:- use_module(library(aggregate)).

"""
    return header + clauses_text(strategy) + "\n% Background predicates\n" + BACKGROUND + ROUTE
