"""Faithfulness: how much of the agent's choices a KB's relation facts predict, beside controls.

A KB says which relations a network holds; that alone does not say the policy
used them (Hewitt and Liang 2019: a probe's figure means nothing without its
control). :func:`measure` learns, on some episodes, to predict two targets from
the facts of a state, and scores the prediction on the other episodes (the
split is by episode: the last :data:`HOLDOUT_SHARE` of them are held out):

* ``next_object``: the next object the agent goes for (its next contact), learned
  by the strategy learner (:func:`neurosym.induce.strategy.induce_strategy`, its
  decision tree over (state, candidate) pairs);
* ``action``: the action taken, learned by a scikit-learn decision tree over the
  same pair features pooled per direction (for each of up, right, down, left: the
  features of the objects that lie that way from the agent).

Each target is learned from three feature sets, side by side:

* ``relations``: the trained network's relation facts (attends/8, holds/5 or attention/6);
* ``world``: world facts only (kinds, distances, routes, what the agent holds);
* ``untrained_relations``: the relation facts of a freshly initialised network of the
  same ModelConfig (seeded), introspected on the very states the agent visited
  (:class:`ControlledAgent`: the trained network chooses every action, the untrained
  one is introspected) -- the control.

``chance`` is what a guess scores: a uniform pick among the state's candidate
objects (its expectation), or always the training episodes' commonest action.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from neurosym.errors import ConfigError, NeurosymError
from neurosym.terms import format_value

HOLDOUT_SHARE = 0.3
"""share of the recorded episodes held out for scoring (the last ones, at least one)"""

CONTROL_SEED = 0
"""the untrained network's initialisation seed"""

TARGETS = ("next_object", "action")
FEATURES = ("relations", "world", "untrained_relations", "chance")
"""the feature sets of a faithfulness row, in the order they are printed"""

MAX_LEAVES = 20
"""leaves of the action tree: the strategy learner's clause bound (same capacity for both targets)"""

DIRECTIONS = ("up", "right", "down", "left")

FAMILIES = {"rgw": "Relational-Grid-World", "boxworld": "Box-World"}
"""the env families measured (the strategy learner's: its contacts and object kinds are theirs)"""


@dataclass(frozen=True)
class Faithfulness:
    """The held-out scores: one row per (target, features), and what they were scored on."""

    table: pd.DataFrame
    """``target, features, score, states, episodes``: share of ``states`` held-out states (of
    ``episodes`` held-out episodes) whose target the learner predicted"""
    episodes: int
    """episodes recorded (the learner fits on the others than the held-out ones)"""
    seconds: float
    """time it took: the control's recording and the six fits"""
    notes: tuple[str, ...] = ()
    """why a row is missing (no next object in the episodes, no relation features, ...)"""

    def facts(self) -> pd.DataFrame:
        """The ``faithfulness/5`` table (columns as declared in the schema)."""
        t = self.table
        return pd.DataFrame(
            {
                "target": t["target"].astype(str),
                "features": t["features"].astype(str),
                "score": t["score"].astype("float64"),
                "states": t["states"].astype("int64"),
                "episodes": t["episodes"].astype("int64"),
            }
        )

    def score(self, target: str, features: str) -> float | None:
        """One figure, or None when it was not measured."""
        rows = self.table[(self.table["target"] == target) & (self.table["features"] == features)]
        return float(rows["score"].iloc[0]) if len(rows) else None


# ------------------------------------------------------------------ the control


@dataclass(frozen=True)
class ControlledAgent:
    """An agent whose actions come from ``actor`` and whose introspection from ``shown``.

    Recording it plays exactly the episodes ``actor`` plays (same actions, same
    sampling draws: only ``actor`` uses the generator) while the facts extracted
    are ``shown``'s: the untrained control sees the states the trained agent visited.
    """

    actor: Any
    shown: Any

    @property
    def config(self) -> Any:
        return self.actor.config

    @property
    def env_name(self) -> str:
        return self.actor.env_name

    @property
    def env_kwargs(self) -> dict[str, Any]:
        return self.actor.env_kwargs

    @property
    def path(self) -> str | None:
        return self.actor.path

    def act(
        self, obs: np.ndarray, greedy: bool = True, introspect: bool = False, generator: Any = None
    ) -> tuple[np.ndarray, Any]:
        """``actor``'s actions and ``shown``'s introspection of the same observations."""
        actions, _ = self.actor.act(obs, greedy=greedy, introspect=False, generator=generator)
        if not introspect:
            return actions, None
        _, intro = self.shown.act(obs, greedy=True, introspect=True)
        return actions, intro


def untrained_agent(agent: Any, seed: int = CONTROL_SEED) -> Any:
    """``agent`` with a freshly initialised network of its ModelConfig (seeded; the global RNG untouched)."""
    from dataclasses import replace

    from neurosym.meaning.probe import untrained_like

    return replace(agent, model=untrained_like(agent.config, seed), path=None)


def record_control(
    agent: Any, rec: Any, *, control_seed: int = CONTROL_SEED, **record_options: Any
) -> Any:
    """The untrained network's recording of the states ``agent`` visited in ``rec``.

    ``record_options`` are the options ``rec`` was recorded with. ConfigError
    when the trace differs from ``rec``'s (an env that is not deterministic
    given the seed): the control would then not see the agent's states.
    """
    from neurosym.record.recorder import record

    control = record(ControlledAgent(agent, untrained_agent(agent, control_seed)), **record_options)
    for name in ("positions", "steps", "episodes"):
        if not getattr(control, name).equals(getattr(rec, name)):
            raise ConfigError(
                f"the untrained control's replay left the agent's episodes ({name} differ): "
                "its env is not deterministic given the seed"
            )
    return control


# ------------------------------------------------------------------ the tables the learners read




def trace_from_facts(facts: Any, relations: Any = None) -> Any:
    """The strategy learner's :class:`~neurosym.induce.strategy_data.KBTables` of a FactSet, in memory.

    What :func:`~neurosym.induce.strategy_data.load_trace` reads from the written
    KB, without writing and loading it. ``relations``: another FactSet of the same
    states (the untrained control's, whose world tables are the agent's: its recording is
    checked to hold the same positions, steps and episodes) read instead of ``facts``.
    """
    from neurosym.induce.strategy_data import COLUMNS, KBTables

    tables = {}
    for name, columns in COLUMNS.items():
        if name == "kb_meta" or name not in facts.tables:
            continue
        source = facts if relations is None else relations  # the same world tables (checked)
        tables[name] = (
            source[name].loc[:, list(columns)].rename(columns=columns).reset_index(drop=True)
        )
    meta = {
        k: format_value(v)  # as load_trace reads them: Prolog text ('rgw-random' quoted)
        for k, v in zip(facts["kb_meta"]["key"], facts["kb_meta"]["value"], strict=True)
    }
    return KBTables(Path("the extracted facts"), meta=meta, **tables)


def split(episodes: list[int], share: float = HOLDOUT_SHARE) -> tuple[list[int], list[int]]:
    """(fit, held-out) episodes: the last ``share`` of them (at least one) held out."""
    if len(episodes) < 2:
        raise ConfigError(
            f"{len(episodes)} episode(s): faithfulness needs at least 2 (one to learn from, one to score on)"
        )
    n_test = min(len(episodes) - 1, max(1, math.ceil(share * len(episodes))))
    return episodes[:-n_test], episodes[-n_test:]


# ------------------------------------------------------------------ the two targets


@dataclass(frozen=True)
class Pairs:
    """Every (state, candidate object) pair of a trace and one feature set's columns, computed once.

    Both targets read them: the next-object learner its labelled states' pairs,
    the action learner every acted state's pairs pooled per direction.
    """

    pairs: pd.DataFrame  # E, T, O, R, C, in candidate order (strategy_data.candidates)
    names: list[Any]  # the strategy learner's Feature of each column
    x: np.ndarray  # (pairs, features)


def pair_features(trace: Any, which: str) -> Pairs:
    """The candidates of every state of ``trace`` and their ``which`` features (world, relations)."""
    from neurosym.induce.strategy_data import candidates
    from neurosym.induce.strategy_features import features

    pairs = candidates(trace)[["E", "T", "O", "R", "C"]].reset_index(drop=True)
    names, x = features(trace, pairs, which)
    if not names:
        raise ConfigError(f"the facts have no {which} features (no relation facts?)")
    return Pairs(pairs, names, x)


def next_object_table(trace: Any, got: Pairs, episodes: list[int]) -> Any:
    """The strategy learner's :class:`~neurosym.induce.strategy.Table` of ``episodes``' labelled states
    (as :func:`neurosym.induce.strategy.table` builds it, from the pairs computed once)."""
    from neurosym.induce.strategy import Table
    from neurosym.induce.strategy_data import labels

    states = labels(trace)
    states = states[states["E"].isin(episodes)].reset_index(drop=True)
    index = pd.MultiIndex.from_frame(states[["E", "T"]])
    state = index.get_indexer(pd.MultiIndex.from_frame(got.pairs[["E", "T"]]))
    keep = state >= 0
    pairs = got.pairs[keep].reset_index(drop=True)
    goal = states["Goal"].to_numpy(dtype=object)[state[keep]]
    y = (pairs["O"].to_numpy(dtype=object) == goal).astype(int)
    return Table(pairs, got.x[keep], y, state[keep], states)


def next_object(
    trace: Any, got: Pairs, fit_eps: list[int], test_eps: list[int], seed: int = 0
) -> tuple[float, int]:
    """Held-out share of states whose next object the strategy learner (its tree) picks, and the states."""
    from neurosym.induce.strategy import MAX_CLAUSES, fidelity
    from neurosym.induce.strategy_tree import fit

    train = next_object_table(trace, got, fit_eps)
    if not len(train.states) or not train.y.any():
        raise ConfigError("no state of the fit episodes has a next object (no contact event)")
    model = fit(got.names, train.x, train.y, MAX_CLAUSES, seed)
    return fidelity(model, next_object_table(trace, got, test_eps))


def next_object_chance(trace: Any, test_eps: list[int]) -> tuple[float, int]:
    """The expected held-out score of a uniform pick among each state's candidate objects."""
    from neurosym.induce.strategy_data import candidates, labels

    states = labels(trace)
    states = states[states["E"].isin(test_eps)]
    if states.empty:
        return math.nan, 0
    counts = candidates(trace).groupby(["E", "T"]).size()
    per_state = counts.reindex(pd.MultiIndex.from_frame(states[["E", "T"]])).to_numpy(dtype=float)
    return float(np.mean(1.0 / per_state)), len(states)


def acted_states(trace: Any) -> pd.DataFrame:
    """The states with a move recorded: E, T, A (the action), sorted."""
    steps = trace.step[trace.step["A"].isin(DIRECTIONS)].drop_duplicates(["E", "T"])
    return steps.sort_values(["E", "T"], kind="stable").reset_index(drop=True)[["E", "T", "A"]]


def action_features(trace: Any, got: Pairs) -> tuple[pd.DataFrame, np.ndarray]:
    """The acted states (E, T, A) and their features: the pair features pooled per direction.

    For each direction (up, right, down, left) and pair feature, the largest value
    (binary features: whether any object that way has it) or, for numeric ones,
    the smallest (the nearest distance) over the objects that lie that way from
    the agent (a row or column offset of that sign); -1 when none does.
    """
    steps = acted_states(trace)
    agent = trace.at[trace.at["O"] == "agent"].drop_duplicates(["E", "T"])
    keys = pd.MultiIndex.from_frame(got.pairs[["E", "T"]])
    state = pd.MultiIndex.from_frame(steps[["E", "T"]]).get_indexer(keys)
    at = pd.MultiIndex.from_frame(agent[["E", "T"]]).get_indexer(keys)
    keep = (state >= 0) & (at >= 0)
    state, x = state[keep], got.x[keep]
    dr = got.pairs["R"].to_numpy()[keep] - agent["R"].to_numpy()[at[keep]]
    dc = got.pairs["C"].to_numpy()[keep] - agent["C"].to_numpy()[at[keep]]
    numeric = np.array([f.numeric for f in got.names], dtype=bool)
    blocks = []
    for way in (dr < 0, dc > 0, dr > 0, dc < 0):
        high = np.full((len(steps), x.shape[1]), -np.inf)
        low = np.full((len(steps), x.shape[1]), np.inf)
        np.maximum.at(high, state[way], x[way])
        np.minimum.at(low, state[way], x[way])
        pooled = np.where(numeric, low, high)
        blocks.append(np.where(np.isfinite(pooled), pooled, -1.0))
    return steps, np.hstack(blocks)


def action(trace: Any, got: Pairs, fit_eps: list[int], seed: int = 0) -> tuple[float, int]:
    """Held-out share of acted states whose action a decision tree over the pooled features predicts."""
    from sklearn.tree import DecisionTreeClassifier

    steps, x = action_features(trace, got)
    train = steps["E"].isin(fit_eps).to_numpy()
    y = steps["A"].to_numpy(dtype=object).astype(str)
    if not train.any() or train.all():
        return math.nan, 0
    tree = DecisionTreeClassifier(max_leaf_nodes=MAX_LEAVES, random_state=seed)
    tree.fit(x[train].astype(np.float32), y[train])
    predicted = tree.predict(x[~train].astype(np.float32))
    return float(np.mean(predicted == y[~train])), int((~train).sum())


def action_chance(trace: Any, fit_eps: list[int]) -> tuple[float, int]:
    """The held-out share of the training episodes' commonest action (ties: the first by name)."""
    steps = acted_states(trace)
    train = steps["E"].isin(fit_eps)
    if not train.any() or train.all():
        return math.nan, 0
    common = steps.loc[train, "A"].value_counts().sort_index(kind="stable").idxmax()
    return float((steps.loc[~train, "A"] == common).mean()), int((~train).sum())


# ------------------------------------------------------------------ all six figures


def measure(
    facts: Any, control: Any | None = None, *, seed: int = 0, started: float | None = None
) -> Faithfulness:
    """The faithfulness table of ``facts`` (a FactSet), with ``control``'s (the untrained
    network's FactSet of the same states) as ``untrained_relations``.

    A figure that cannot be measured (no next object in the fit episodes, no
    relation facts) is left out and its reason kept in ``notes``.
    """
    start = time.perf_counter() if started is None else started
    trace = trace_from_facts(facts)
    episodes = trace.episodes()
    fit_eps, test_eps = split(episodes)
    sets: list[tuple[str, Any, str]] = [
        ("relations", trace, "relations"),
        ("world", trace, "world"),
    ]
    if control is not None:
        sets.append(
            ("untrained_relations", trace_from_facts(facts, relations=control), "relations")
        )
    rows: list[tuple[str, str, float, int]] = []
    notes: dict[str, list[str]] = {}  # why -> the figures it leaves out
    for name, source, which in sets:
        try:
            got = pair_features(source, which)
        except NeurosymError as exc:
            notes.setdefault(str(exc), []).append(name)
            continue
        for target in TARGETS:
            try:
                if target == "next_object":
                    score, states = next_object(source, got, fit_eps, test_eps, seed)
                else:
                    score, states = action(source, got, fit_eps, seed)
            except NeurosymError as exc:
                notes.setdefault(str(exc), []).append(f"{target} from {name}")
                continue
            rows.append((target, name, score, states))
    rows.append(("next_object", "chance", *next_object_chance(trace, test_eps)))
    rows.append(("action", "chance", *action_chance(trace, fit_eps)))
    table = pd.DataFrame(rows, columns=["target", "features", "score", "states"])
    order = {(t, f): i for i, (t, f) in enumerate((t, f) for t in TARGETS for f in FEATURES)}
    table = table[table["states"] > 0]
    table = table.iloc[
        np.argsort(
            [order[k] for k in zip(table["target"], table["features"], strict=True)], kind="stable"
        )
    ]
    table = table.reset_index(drop=True).assign(episodes=len(test_eps))
    said = tuple(f"{', '.join(what)}: {why}" for why, what in notes.items())
    return Faithfulness(table, len(episodes), time.perf_counter() - start, said)


def faithfulness(
    agent: Any, rec: Any, facts: Any, *, control_seed: int = CONTROL_SEED, **record_options: Any
) -> Faithfulness:
    """Record the untrained control on ``rec``'s states, then :func:`measure` (timed together).

    ``record_options``: what ``rec`` was recorded with (env, episodes, seed, greedy, ...);
    ``control_seed`` initialises the untrained network.
    Fewer than 2 episodes, or an env family the strategy learner does not know (Minigrid):
    an empty table and the reason in ``notes``.
    """
    from neurosym.envs import env_family
    from neurosym.facts.tables import extract_facts

    start = time.perf_counter()
    family = env_family(str(rec.meta.get("env")))
    note = None
    if family not in FAMILIES:
        note = (
            f"not measured on {family} envs: the strategy learner knows the objects and contacts "
            f"of {' and '.join(FAMILIES.values())}"
        )
    elif len(rec.episodes) < 2:
        note = f"{len(rec.episodes)} episode: faithfulness needs at least 2 (one to learn from, one to score on)"
    if note is not None:
        empty = pd.DataFrame({c: [] for c in ("target", "features", "score", "states", "episodes")})
        return Faithfulness(empty, len(rec.episodes), 0.0, (note,))
    control = record_control(agent, rec, control_seed=control_seed, **record_options)
    control_facts = extract_facts(control, threshold=facts.threshold)
    return measure(facts, control_facts, started=start)
