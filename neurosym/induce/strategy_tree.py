"""A decision tree over (state, candidate) pairs, read as a decision list of goal/3 clauses.

scikit-learn fits a tree with at most ``max_clauses`` leaves to the pairs
(1 when the candidate is the state's next object). Each leaf with a non-zero
share of next objects becomes one clause ``goal(E, T, O) :- goal_candidate(E, T,
O), <the tests on the path to the leaf>``; clauses are ordered by that share
(then by the number of pairs). A pair falls in exactly one leaf, so the first
answer of goal/3 is the candidate whose leaf comes first, the first of those
in candidate order: :meth:`DecisionList.choose` computes the same in Python.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from neurosym.induce.strategy_features import Feature


@dataclass(frozen=True)
class Test:
    """One test on a tree path: ``feature <= threshold`` (low) or ``>`` (not low)."""

    feature: int
    threshold: float
    low: bool


@dataclass
class Clause:
    """One leaf: its path's tests, the share of next objects and the pairs it holds."""

    leaf: int
    tests: list[Test]
    share: float
    pairs: int


@dataclass
class DecisionList:
    """The fitted tree's leaves as ordered clauses."""

    features: list[Feature]
    clauses: list[Clause]
    learner: str  # "tree" or "covering"

    def ranks(self, x: np.ndarray) -> np.ndarray:
        """Each pair's rank: the first clause whose tests it passes; len(clauses) for none."""
        ranks = np.full(len(x), len(self.clauses), dtype=int)
        for i in range(len(self.clauses) - 1, -1, -1):
            ranks[holds(self.clauses[i].tests, x)] = i
        return ranks

    def choose(self, x: np.ndarray, state: np.ndarray) -> dict[int, int]:
        """State index -> index of the chosen pair (pairs in candidate order within a state)."""
        ranks = self.ranks(x)
        best: dict[int, tuple[int, int]] = {}
        for i, (s, r) in enumerate(zip(state.tolist(), ranks.tolist(), strict=True)):
            if r < len(self.clauses) and (s not in best or r < best[s][0]):
                best[s] = (r, i)
        return {s: i for s, (_, i) in best.items()}


def holds(tests: list[Test], x: np.ndarray) -> np.ndarray:
    """Which pairs (rows of ``x``) pass every test."""
    mask = np.ones(len(x), dtype=bool)
    for t in tests:
        col = x[:, t.feature]
        mask &= col <= t.threshold if t.low else col > t.threshold
    return mask


def fit(
    features: list[Feature], x: np.ndarray, y: np.ndarray, max_clauses: int, seed: int = 0
) -> DecisionList:
    """Fit the tree (at most ``max_clauses`` leaves) and read its leaves as clauses."""
    from sklearn.tree import DecisionTreeClassifier

    tree = DecisionTreeClassifier(max_leaf_nodes=max(2, max_clauses), random_state=seed)
    tree.fit(x.astype(np.float32), y)
    t = tree.tree_
    positive = list(tree.classes_).index(1) if 1 in tree.classes_ else None
    clauses: list[Clause] = []

    def walk(node: int, path: list[Test]) -> None:
        if t.children_left[node] == -1:
            counts = t.value[node][0]
            share = float(counts[positive] / counts.sum()) if positive is not None else 0.0
            if share > 0:
                clauses.append(Clause(node, path, share, int(t.n_node_samples[node])))
            return
        f, th = int(t.feature[node]), float(t.threshold[node])
        walk(int(t.children_left[node]), [*path, Test(f, th, True)])
        walk(int(t.children_right[node]), [*path, Test(f, th, False)])

    walk(0, [])
    clauses.sort(key=lambda c: (-c.share, -c.pairs, c.leaf))
    return DecisionList(features, clauses[:max_clauses], "tree")


def simplify(tests: list[Test], features: list[Feature]) -> list[Test]:
    """The path's tests with each feature's bounds merged (the tightest kept), in path order."""
    kept: dict[tuple[int, bool], Test] = {}
    for test in tests:
        key = (test.feature, test.low)
        old = kept.get(key)
        if old is None:
            kept[key] = test
        elif test.low and test.threshold < old.threshold or not test.low and test.threshold > old.threshold:
            kept[key] = test
    out = [tk for tk in tests if kept.get((tk.feature, tk.low)) is tk]
    if any(not features[tk.feature].numeric for tk in out):
        # a binary feature tested both ways cannot happen on a tree path; keep each once
        seen: set[int] = set()
        out = [tk for tk in out if features[tk.feature].numeric or not (tk.feature in seen or seen.add(tk.feature))]
    return out
