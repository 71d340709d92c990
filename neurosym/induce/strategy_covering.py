"""Sequential covering: a decision list of goal/3 clauses grown to choose the next object.

Each clause is a conjunction of tests on (state, candidate) features. A
clause *fires* in a state when some candidate passes its tests, and then
chooses the first such candidate (candidate order). Clauses are learned one
at a time on the states no earlier clause fires in: a clause starts empty and
greedily takes the test that most raises ``right - penalty * wrong`` over the
states it fires in, as long as that rises (FOIL's and CN2's greedy
specialisation, scored on the choice the clause makes rather than on pairs);
the states it fires in are then decided. This scores what fidelity measures,
which a tree fitted to pairs does not.
"""

from __future__ import annotations

import numpy as np

from neurosym.induce.strategy_features import Feature
from neurosym.induce.strategy_tree import Clause, DecisionList, Test

MAX_TESTS = 5
"""At most this many tests per clause."""


def candidate_tests(features: list[Feature], x: np.ndarray, thresholds: int = 24) -> list[Test]:
    """Every test the search may add: a binary feature true or false, a numeric one below or above a cut."""
    tests = []
    for j, f in enumerate(features):
        if not f.numeric:
            tests += [Test(j, 0.5, False), Test(j, 0.5, True)]
            continue
        values = np.unique(x[:, j])
        if len(values) > thresholds:
            values = np.unique(np.round(np.quantile(values, np.linspace(0, 1, thresholds))))
        for v in values[:-1]:
            tests += [Test(j, float(v), True), Test(j, float(v), False)]
    return tests


def _score(mask: np.ndarray, y: np.ndarray, state: np.ndarray, penalty: float) -> tuple[float, int, int]:
    """Right and wrong choices of a clause whose passing pairs are ``mask`` (pairs in state order)."""
    idx = np.flatnonzero(mask)
    if not len(idx):
        return -np.inf, 0, 0
    _, first = np.unique(state[idx], return_index=True)
    right = int(y[idx[first]].sum())
    wrong = len(first) - right
    return right - penalty * wrong, right, wrong


def _grow(x, y, state, columns, tests, penalty):  # type: ignore[no-untyped-def]
    """One clause: greedy specialisation from the empty conjunction."""
    chosen: list[Test] = []
    mask = np.ones(len(y), dtype=bool)
    best, right, wrong = _score(mask, y, state, penalty)
    while len(chosen) < MAX_TESTS:
        step = None
        for k in range(len(tests)):
            m = mask & columns[k]
            score, r, w = _score(m, y, state, penalty)
            if score > best + 1e-9:
                best, step, right, wrong = score, (k, m), r, w
        if step is None:
            break
        chosen.append(tests[step[0]])
        mask = step[1]
    return chosen, mask, best, right, wrong


def fit(
    features: list[Feature], x: np.ndarray, y: np.ndarray, state: np.ndarray,
    max_clauses: int, penalty: float = 1.0,
) -> DecisionList:
    """Learn up to ``max_clauses`` clauses; stop when no clause makes a right choice.

    A state no clause fires in counts as wrong, so a clause that is right in some states
    adds to fidelity even when it is wrong in more; the score only orders the clauses.
    """
    tests = candidate_tests(features, x)
    columns = [x[:, t.feature] <= t.threshold if t.low else x[:, t.feature] > t.threshold for t in tests]
    open_ = np.ones(len(y), dtype=bool)  # pairs of states no clause fires in yet
    clauses: list[Clause] = []
    while len(clauses) < max_clauses and open_.any():
        chosen, mask, score, right, wrong = _grow(
            x[open_], y[open_], state[open_], [c[open_] for c in columns], tests, penalty
        )
        if right == 0:
            break
        share = right / (right + wrong)
        clauses.append(Clause(len(clauses), chosen, share, right + wrong))
        fired = np.unique(state[open_][mask])
        open_ &= ~np.isin(state, fired)
    return DecisionList(features, clauses, "covering")
