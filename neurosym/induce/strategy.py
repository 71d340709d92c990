"""The agent's strategy as rules: which object it goes for next, learned from a KB.

>>> s = induce_strategy("kb/bw1/kb.pl", features="world", holdout="kb/bw1-test/kb.pl")
>>> s.fidelity            # share of held-out states whose first goal/3 answer is the label
>>> s.write("bw1.world.pl")

The learner is a scikit-learn decision tree over propositionalised (state,
candidate object) pairs (:mod:`neurosym.induce.strategy_features`), read as
a decision list of ``goal(E, T, O)`` clauses (:mod:`neurosym.induce.strategy_tree`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from neurosym.errors import ConfigError, FactError
from neurosym.induce.strategy_data import KBTables, candidates, labels, load_trace
from neurosym.induce.strategy_features import FEATURE_SETS, Feature, features
from neurosym.induce.strategy_tree import DecisionList
from neurosym.terms import parse_term

LEARNERS = ("best", "tree", "covering")

MAX_CLAUSES = 20
"""At most this many goal/3 clauses per strategy."""


@dataclass
class Table:
    """The pairs of a set of states, their feature matrix and labels."""

    pairs: pd.DataFrame  # E, T, O, R, C; candidates of a state together, in id order
    x: np.ndarray  # (pairs, features)
    y: np.ndarray  # (pairs,) 1 where O is the state's next object
    state: np.ndarray  # (pairs,) index of the pair's state in `states`
    states: pd.DataFrame  # E, T, Goal


def table(trace: KBTables, which: str, names: list[Feature] | None = None) -> tuple[list[Feature], Table]:
    """The labelled states' pairs and features; with ``names``, columns aligned to them (absent: 0)."""
    states = labels(trace)
    pairs = candidates(trace).merge(states, on=["E", "T"], how="inner")
    feats, x = features(trace, pairs[["E", "T", "O", "R", "C"]], which)
    if names is not None:
        index = {f.name: i for i, f in enumerate(feats)}
        x = np.column_stack(
            [x[:, index[f.name]] if f.name in index else np.zeros(len(pairs)) for f in names]
        ) if names else np.zeros((len(pairs), 0))
        feats = names
    key = {(e, t): i for i, (e, t) in enumerate(zip(states["E"], states["T"], strict=True))}
    state = np.array([key[(e, t)] for e, t in zip(pairs["E"], pairs["T"], strict=True)], dtype=int)
    y = (pairs["O"] == pairs["Goal"]).to_numpy().astype(int)
    return feats, Table(pairs[["E", "T", "O", "R", "C"]], x, y, state, states)


def fidelity(model: DecisionList, tab: Table) -> tuple[float, int]:
    """Share of ``tab``'s states whose chosen object is the label, and the number of states."""
    n = len(tab.states)
    if n == 0:
        return math.nan, 0
    chosen = model.choose(tab.x, tab.state)
    right = sum(1 for s, i in chosen.items() if tab.y[i] == 1)
    return right / n, n


@dataclass
class Strategy:
    """A learned strategy: the decision list, its scores and where it came from."""

    model: DecisionList
    features: str
    kb: Path
    holdout: str
    fidelity: float
    states: int
    train_fidelity: float
    train_states: int
    seconds: float
    max_clauses: int = MAX_CLAUSES
    meta: dict[str, str] = field(default_factory=dict)

    def predict(self, trace: KBTables) -> pd.DataFrame:
        """The chosen object of every labelled state of ``trace``: columns E, T, Goal, Choice."""
        _, tab = table(trace, self.features, self.model.features)
        chosen = self.model.choose(tab.x, tab.state)
        out = tab.states.copy()
        choices = [tab.pairs["O"].iloc[chosen[s]] if s in chosen else None for s in range(len(out))]
        out["Choice"] = pd.Series(choices, index=out.index, dtype=object)  # None: no clause fires
        return out

    def text(self) -> str:
        """The learned file's text (:mod:`neurosym.induce.strategy_writer`)."""
        from neurosym.induce.strategy_writer import render

        return render(self)

    def write(self, path: str | Path) -> Path:
        """Write the learned file atomically, once it reads back as the clauses learned."""
        from neurosym.atomic import make_folder, write_bytes_atomic
        from neurosym.induce.readback import check_reads_back
        from neurosym.induce.strategy_writer import render_parts

        text, parts = render_parts(self)
        check_reads_back(text, parts, path)
        make_folder(Path(path).parent)
        return write_bytes_atomic(path, text.encode("utf-8"))


def _learn(
    names: list[Feature], tab: Table, learner: str, max_clauses: int, penalty: float, seed: int
) -> tuple[DecisionList, tuple[float, int]]:
    """Fit the learner; ``best`` fits both and keeps the higher training fidelity (then fewer clauses)."""
    from neurosym.induce.strategy_covering import fit as fit_covering
    from neurosym.induce.strategy_tree import fit as fit_tree

    fitted = []
    if learner in ("tree", "best"):
        fitted.append(fit_tree(names, tab.x, tab.y, max_clauses, seed))
    if learner in ("covering", "best"):
        fitted.append(fit_covering(names, tab.x, tab.y, tab.state, max_clauses, penalty))
    scored = [(m, fidelity(m, tab)) for m in fitted]
    return max(scored, key=lambda ms: (ms[1][0], -len(ms[0].clauses)))


def family(trace: KBTables) -> str:
    """The env family of a trace (``rgw`` or ``boxworld``), as ``induce world`` tells it."""
    from neurosym.induce.examples import env_family

    env = trace.meta.get("env", "")
    try:
        name = parse_term(env)  # kb_meta values are Prolog text: 'rgw-random' is quoted
    except FactError:
        name = env
    return env_family([str(t) for t in trace.object["Ty"]], str(name))


def _split(trace: KBTables, holdout: str | Path | KBTables | None, share: float) -> tuple[KBTables, KBTables, str]:
    if holdout is not None:
        test = holdout if isinstance(holdout, KBTables) else load_trace(holdout)
        mine, theirs = family(trace), family(test)
        if theirs != mine:
            raise ConfigError(
                f"held-out KB {test.path} is a {theirs} KB; the rules learned from {trace.path} are "
                f"{mine} rules: give a held-out KB of the same env family"
            )
        return trace, test, f"the episodes of {test.path}"
    if not 0 < share < 1:
        raise ConfigError(f"--holdout-share must be between 0 and 1 (exclusive), got {share}")
    episodes = trace.episodes()
    n_test = max(1, math.ceil(share * len(episodes)))
    if n_test >= len(episodes):
        raise ConfigError(
            f"{trace.path} has {len(episodes)} episode(s): too few to hold out {share:g} of them; "
            "record more or pass --holdout KB"
        )
    test = episodes[-n_test:]
    text = f"the last {n_test} of {len(episodes)} episodes of the KB (share {share:g})"
    return trace.subset(episodes[:-n_test]), trace.subset(test), text


def induce_strategy(
    kb: str | Path | KBTables,
    features: str = "world",
    *,
    holdout: str | Path | KBTables | None = None,
    holdout_share: float = 0.3,
    max_clauses: int = MAX_CLAUSES,
    learner: str = "best",
    penalty: float = 1.0,
    seed: int = 0,
) -> Strategy:
    """Learn which object the agent goes for next from ``kb``'s episodes.

    ``features`` is ``world``, ``relations`` or ``both``. Fidelity is scored
    on the episodes of ``holdout`` (a KB of other episodes) or else on the
    last ``holdout_share`` of ``kb``'s episodes, which are then not learned from.
    """
    if features not in FEATURE_SETS:
        raise ConfigError(f"unknown feature set {features!r}; use one of {', '.join(FEATURE_SETS)}")
    if not 1 <= max_clauses <= MAX_CLAUSES:
        raise ConfigError(f"max_clauses must be 1 to {MAX_CLAUSES}, got {max_clauses}")
    start = time.perf_counter()
    trace = kb if isinstance(kb, KBTables) else load_trace(kb)
    train, test, held = _split(trace, holdout, holdout_share)
    names, tab = table(train, features)
    if not len(tab.states) or not tab.y.any():
        raise ConfigError(f"{trace.path} has no state with a next object (no contact event); nothing to learn")
    if not names:
        raise ConfigError(f"{trace.path} has no {features} features (no relation facts?)")
    if learner not in LEARNERS:
        raise ConfigError(f"unknown learner {learner!r}; use one of {', '.join(LEARNERS)}")
    model, (train_fid, train_n) = _learn(names, tab, learner, max_clauses, penalty, seed)
    _, test_tab = table(test, features, names)
    fid, n = fidelity(model, test_tab)
    return Strategy(
        model, features, trace.path, held, fid, n, train_fid, train_n,
        time.perf_counter() - start, max_clauses, trace.meta,
    )
