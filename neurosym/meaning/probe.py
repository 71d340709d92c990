"""Linear probes: which predicates of the true state each head's relations encode.

For every head h, every relation j (PrediNet: D^h_j; and ``all``, the head's
whole vector) and every predicate of :mod:`neurosym.meaning.predicates`, a
logistic regression (scikit-learn) is fitted on the states of some episodes and
scored on the states of the others (the split is by episode, so a probe never
scores on an episode it saw). Three numbers go with each accuracy:

* **control** (Hewitt and Liang 2019): the same probe on control labels that
  keep the predicate's balance but are a random function of the state. Each
  distinct observation (what the network sees; the "word type" of H&L) gets
  one random label, so a probe can score on a control only by memorising
  states. Labels that are constant per episode would be unlearnable across an
  episode split and measure only the majority rate; these measure what the
  probe can memorise. The control reported is never below the majority rate
  (what always giving the training majority scores on the held-out states):
  on a rare predicate the types drawn can make the control task score below
  that by chance, which would flatter the probe. The raw score is kept as
  ``control_task``. **selectivity** = accuracy - control.
* **untrained**: the same probe, same states, on an untrained network of the
  same shape (seeded), so that a reader sees what training added.

A predicate that is constant on the recorded states, or within the training or
the held-out episodes, cannot be probed: it is reported in ``skipped`` with
the reason, never given an accuracy. Greedy episodes of a fixed map are all
the same episode, so probes default to sampled actions (``greedy=False``).

MHDPA has no relation vectors: its heads are probed on their outputs,
max-pooled over entities, as relation ``all`` only.
"""

from __future__ import annotations

import datetime as _dt
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from neurosym.agent.networks.adapters import adapter_class
from neurosym.errors import ConfigError
from neurosym.meaning.predicates import StateLabels
from neurosym.progress import Stages

DEFAULT_EPISODES = 200
"""probe episodes by default: sampled, seeds S..S+199 (about 4k states on rgw2)"""
TEST_FRACTION = 0.3
"""share of episodes held out for scoring"""
MAX_TRAIN = 2000
"""states a probe is fitted on at most (a random subset; bounds the time of ~10k fits)"""
MAX_TEST = 5000
"""states a probe is scored on at most"""

TABLE_COLUMNS = (
    "head",
    "relation",
    "predicate",
    "accuracy",
    "control",
    "selectivity",
    "untrained_accuracy",
    "untrained_control",
    "untrained_selectivity",
    "control_task",
    "untrained_control_task",
    "majority",
    "positive_rate",
    "train_states",
    "test_states",
)


@dataclass
class ProbeReport:
    """The probe table (one row per head, relation, predicate), the skipped predicates, meta."""

    table: pd.DataFrame
    skipped: pd.DataFrame
    """``predicate, reason``"""
    meta: dict[str, Any] = field(default_factory=dict)

    def best(self, n: int = 10, relation: str | None = None) -> pd.DataFrame:
        """The n most selective rows (optionally of one relation: ``"all"``, ``"3"``)."""
        t = self.table if relation is None else self.table[self.table["relation"] == relation]
        return t.sort_values(["selectivity", "accuracy"], ascending=False, kind="stable").head(n)

    def facts(self) -> dict[str, pd.DataFrame]:
        """Tables for the Prolog writer: kb_meta/2, probe/5, probe_untrained/5, probe_skipped/2."""
        t = self.table
        j = pd.Series([int(r) if r != "all" else "all" for r in t["relation"]], dtype=object)
        probe = pd.DataFrame(
            {
                "head": t["head"].to_numpy(),
                "j": j,
                "predicate": t["predicate"].to_numpy(),
                "accuracy": t["accuracy"].to_numpy(dtype=np.float64),
                "control": t["control"].to_numpy(dtype=np.float64),
            }
        )
        untrained = probe.assign(
            accuracy=t["untrained_accuracy"].to_numpy(dtype=np.float64),
            control=t["untrained_control"].to_numpy(dtype=np.float64),
        )
        if t["untrained_accuracy"].isna().any():
            untrained = untrained.iloc[0:0]
        keys = [k for k, v in self.meta.items() if isinstance(v, str | int | float | bool)]
        meta = pd.DataFrame(
            {"key": keys, "value": pd.Series([self.meta[k] for k in keys], dtype=object)}
        )
        return {
            "kb_meta": meta,
            "probe": probe,
            "probe_untrained": untrained,
            "probe_skipped": self.skipped.loc[:, ["predicate", "reason"]],
        }

    def to_prolog(self, path: str | os.PathLike[str]) -> Path:
        """Write the facts as a plain Prolog file (atomically, full-precision floats)."""
        from neurosym.facts.prolog_writer import write_prolog
        from neurosym.facts.schema import PROBE, group, indicators, term_columns

        names = [p.name for p in group(PROBE)]
        header = (
            "neurosym probes: what each head's relations encode (neurosym probe).\n"
            + ", ".join(f"{k}={v}" for k, v in self.meta.items())
            + "\nprobe(Head, J, Predicate, Accuracy, Control): held-out accuracy and control-task"
            " accuracy;\nprobe_untrained/5 the same on an untrained network; probe_skipped/2."
        )
        return write_prolog(
            Path(path),
            self.facts(),
            header=header,
            dynamic=indicators(["kb_meta", *names]),
            term_columns=term_columns(names),
        )


# ------------------------------------------------------------------ fitting


def state_types(obs: np.ndarray) -> np.ndarray:
    """(S,) code of each distinct observation (the control task's "word type")."""
    flat = np.ascontiguousarray(obs.reshape(len(obs), -1))
    view = flat.view(np.dtype((np.void, flat.shape[1])))[:, 0]
    return pd.factorize(view)[0].astype(np.int64)


def control_labels(types: np.ndarray, positive_rate: float, rng: np.random.Generator) -> np.ndarray:
    """A random function of the state type with the predicate's balance.

    Types are shuffled and labelled positive in that order until their states
    reach ``positive_rate`` of all states: every state of a type shares its label.
    """
    counts = np.bincount(types)
    order = rng.permutation(len(counts))
    filled = np.cumsum(counts[order])
    target = positive_rate * len(types)
    chosen = order[filled - counts[order] / 2 < target]  # types whose middle falls below it
    positive = np.zeros(len(counts), dtype=bool)
    positive[chosen] = True
    return positive[types]


def split_episodes(
    episodes: np.ndarray, test_fraction: float, rng: np.random.Generator
) -> np.ndarray:
    """(S,) True for states of held-out episodes; at least one episode on each side."""
    ids = np.unique(episodes)
    if len(ids) < 2:
        raise ConfigError(
            f"probes need at least 2 episodes (one to fit on, one to score on), got {len(ids)}"
        )
    n_test = min(len(ids) - 1, max(1, round(test_fraction * len(ids))))
    test_ids = rng.permutation(ids)[:n_test]
    return np.isin(episodes, test_ids)


def logistic_fit(
    X: np.ndarray, Y: np.ndarray, C: float = 1.0, iters: int = 100
) -> tuple[np.ndarray, np.ndarray]:
    """M L2-regularised logistic regressions on one design matrix: (M, d) weights, (M,) intercepts.

    The objective of scikit-learn's ``LogisticRegression(C=C)`` (log-loss
    summed over the samples plus ||w||^2 / (2C), the intercept unpenalised),
    solved by Newton's method for all M label vectors at once: X (n, d)
    shared, Y (M, n) bool. A probe run fits thousands of tiny probes; one
    sklearn call each costs 5 ms on a quiet core and 50 ms on a busy one
    (2-3 minutes per checkpoint here), while here every Newton step of all of
    them is a few matrix products. ``tests/meaning/test_meaning_probe.py`` checks the
    fits against scikit-learn's, and ``solver="sklearn"`` uses it directly.
    """
    n, d = X.shape
    M = Y.shape[0]
    Xa = np.concatenate([X, np.ones((n, 1))], axis=1)  # (n, d + 1)
    outer = (Xa[:, :, None] * Xa[:, None, :]).reshape(n, -1)  # (n, (d + 1)^2)
    target = Y.astype(np.float64)  # (M, n)
    theta = np.zeros((M, d + 1))
    rate = target.mean(axis=1).clip(1e-3, 1 - 1e-3)
    theta[:, d] = np.log(rate / (1 - rate))  # start from the balance: fewer Newton steps
    ridge = np.full(d + 1, 1.0 / C)
    ridge[-1] = 1e-10  # the intercept is not penalised (a hair keeps the Hessian invertible)
    for _ in range(iters):
        p = 0.5 * (1.0 + np.tanh(0.5 * (theta @ Xa.T)))  # (M, n) sigmoid, overflow-free
        grad = (p - target) @ Xa + ridge * theta  # (M, d + 1)
        hess = ((p * (1.0 - p)) @ outer).reshape(M, d + 1, d + 1) + np.diag(ridge)
        step = np.linalg.solve(hess, grad[..., None])[..., 0]
        theta -= step
        if np.abs(step).max() < 1e-8:
            break
    return theta[:, :d], theta[:, d]


def logistic_accuracy(
    X_train: np.ndarray, Y_train: np.ndarray, X_test: np.ndarray, Y_test: np.ndarray
) -> np.ndarray:
    """(M,) held-out accuracies of M probes sharing features; a constant label predicts itself."""
    w, b = logistic_fit(X_train, Y_train)
    predicted = w @ X_test.T + b[:, None] > 0  # (M, n_test)
    constant = Y_train.min(axis=1) == Y_train.max(axis=1)
    predicted = np.where(constant[:, None], Y_train[:, :1], predicted)
    return (predicted == Y_test).mean(axis=1)


def sklearn_accuracy(
    X_train: np.ndarray, y_train: np.ndarray, X_test: np.ndarray, y_test: np.ndarray
) -> float:
    """The same probe as one scikit-learn ``LogisticRegression`` (the reference; slower)."""
    if y_train.min() == y_train.max():
        return float(np.mean(y_test == y_train[0]))
    from sklearn.linear_model import LogisticRegression

    clf = LogisticRegression(C=1.0, max_iter=1000, tol=1e-8).fit(X_train, y_train)
    return float(np.mean(clf.predict(X_test) == y_test))


def _standardise(X: np.ndarray, train: np.ndarray) -> np.ndarray:
    mean = X[train].mean(axis=0)
    std = X[train].std(axis=0)
    return (X - mean) / np.where(std > 1e-12, std, 1.0)


def fit_probes(
    features: np.ndarray,
    labels: StateLabels,
    types: np.ndarray,
    *,
    relations: int | None,
    seed: int = 0,
    untrained: np.ndarray | None = None,
    test_fraction: float = TEST_FRACTION,
    max_train: int = MAX_TRAIN,
    max_test: int = MAX_TEST,
    solver: str = "batched",
    advance: Callable[[int], None] | None = None,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Fit every (head, relation, predicate) probe; (table, skipped) as in :class:`ProbeReport`.

    ``features`` (S, H, D) per-head vectors; relation j is column j (j <
    ``relations``; None: only ``all``), ``all`` the whole vector. ``types``
    (S,) state types for the control task. ``untrained`` (S, H, D) the same
    from an untrained network, or None. ``advance(1)`` is called after each
    (network, head, relation) fit, for a progress display.
    """
    S, H, D = features.shape
    if len(labels.states) != S or len(types) != S:
        raise ConfigError(
            f"features ({S} states), labels ({len(labels.states)}) and types ({len(types)}) differ"
        )
    rng = np.random.default_rng(seed)
    episodes = labels.states["episode"].to_numpy()
    test = split_episodes(episodes, test_fraction, rng)
    train_idx, test_idx = np.flatnonzero(~test), np.flatnonzero(test)
    if len(train_idx) > max_train:
        train_idx = np.sort(rng.choice(train_idx, max_train, replace=False))
    if len(test_idx) > max_test:
        test_idx = np.sort(rng.choice(test_idx, max_test, replace=False))
    keep_rows = np.zeros(S, dtype=bool)
    keep_rows[train_idx] = True
    columns = [(str(j), slice(j, j + 1)) for j in range(relations or 0)]
    columns.append(("all", slice(0, D)))
    nets = [("", features)] + ([("untrained_", untrained)] if untrained is not None else [])
    scaled = {
        prefix: [
            [_standardise(f[:, h, sl].astype(np.float64), keep_rows) for _, sl in columns]
            for h in range(H)
        ]
        for prefix, f in nets
    }
    if solver not in ("batched", "sklearn"):
        raise ConfigError(f"solver must be batched or sklearn, got {solver!r}")
    rows, skipped = _fit_all(
        labels, nets, scaled, columns, types, train_idx, test_idx, H, rng, solver, advance
    )
    table = pd.DataFrame(rows, columns=[c for c in TABLE_COLUMNS if c not in ("selectivity",)])

    for col in ("untrained_accuracy", "untrained_control", "untrained_control_task"):
        if col not in table or untrained is None:
            table[col] = np.nan
    table["selectivity"] = table["accuracy"] - table["control"]
    table["untrained_selectivity"] = table["untrained_accuracy"] - table["untrained_control"]
    rates = dict(zip(labels.names, labels.values.mean(axis=0), strict=True))
    table["positive_rate"] = table["predicate"].map(rates).astype(np.float64)
    table["train_states"] = len(train_idx)
    table["test_states"] = len(test_idx)
    table = table.loc[:, list(TABLE_COLUMNS)].astype(
        {"head": "int64", "relation": "str", "predicate": "str"}
    )
    skipped_df = pd.DataFrame(skipped, columns=["predicate", "reason"], dtype="str")
    return table.reset_index(drop=True), skipped_df


def _fit_all(
    labels: StateLabels,
    nets: list[tuple[str, np.ndarray]],
    scaled: dict[str, list[list[np.ndarray]]],
    columns: list[tuple[str, slice]],
    types: np.ndarray,
    train_idx: np.ndarray,
    test_idx: np.ndarray,
    H: int,
    rng: np.random.Generator,
    solver: str,
    advance: Callable[[int], None] | None = None,
) -> tuple[list[dict[str, Any]], list[tuple[str, str]]]:
    """The fits of :func:`fit_probes`: predicates are screened, then probed all at once."""
    S = len(types)
    skipped: list[tuple[str, str]] = []
    probed: list[int] = []
    for p, name in enumerate(labels.names):
        y = labels.values[:, p]
        rate = float(y.mean())
        if rate in (0.0, 1.0):
            which = "true" if rate == 1.0 else "false"
            skipped.append((name, f"constant: {which} in all {S} recorded states"))
        elif y[train_idx].min() == y[train_idx].max():
            skipped.append((name, "constant within the training episodes"))
        elif y[test_idx].min() == y[test_idx].max():
            skipped.append((name, "constant within the held-out episodes"))
        else:
            probed.append(p)
    if not probed:
        return [], skipped
    truth = labels.values[:, probed].T  # (P, S)
    control = np.stack([control_labels(types, float(y.mean()), rng) for y in truth])
    both = np.concatenate([truth, control])  # (2P, S): the predicates, then their controls
    Y_tr, Y_te = both[:, train_idx], both[:, test_idx]
    P = len(probed)
    scores: dict[tuple[str, int, int], np.ndarray] = {}
    for prefix, _f in nets:
        for h in range(H):
            for c, _ in enumerate(columns):
                X = scaled[prefix][h][c]  # (S, d)
                if solver == "sklearn":
                    acc = np.array(
                        [sklearn_accuracy(X[train_idx], yt, X[test_idx], ye)
                         for yt, ye in zip(Y_tr, Y_te, strict=True)]
                    )  # fmt: skip
                else:
                    acc = logistic_accuracy(X[train_idx], Y_tr, X[test_idx], Y_te)
                scores[prefix, h, c] = acc  # (2P,)
                if advance is not None:
                    advance(1)
    # What always answering the training majority scores on the held-out states: a
    # control task on a rare predicate can score below it by bad luck in the types
    # drawn, and a control below what a constant answer gets would flatter the probe.
    majority_label = truth[:, train_idx].mean(axis=1) >= 0.5
    majority = (truth[:, test_idx] == majority_label[:, None]).mean(axis=1)
    rows: list[dict[str, Any]] = []
    for k, p in enumerate(probed):
        for h in range(H):
            for c, (rel, _) in enumerate(columns):
                row: dict[str, Any] = {"head": h, "relation": rel, "predicate": labels.names[p]}
                for prefix, _f in nets:
                    row[prefix + "accuracy"] = float(scores[prefix, h, c][k])
                    row[prefix + "control_task"] = float(scores[prefix, h, c][P + k])
                    row[prefix + "control"] = max(row[prefix + "control_task"], majority[k])
                row["majority"] = float(majority[k])
                rows.append(row)
    return rows, skipped


# ------------------------------------------------------------------ from an agent


def untrained_like(config: Any, seed: int) -> Any:
    """A freshly initialised network of the same shape (seeded), in eval mode."""
    import torch

    from neurosym.agent.networks.model import ActorCritic

    with torch.random.fork_rng():
        torch.manual_seed(seed)
        model = ActorCritic(config)
    return model.eval()


def probe_recording(
    agent: Any,
    recording: Any,
    *,
    seed: int = 0,
    untrained: bool = True,
    test_fraction: float = TEST_FRACTION,
    max_train: int = MAX_TRAIN,
    solver: str = "batched",
    progress: bool = False,
) -> ProbeReport:
    """Probe ``agent``'s heads on the states of an existing recording of it.

    ``progress``: bars on stderr (replaying the states, fitting the probes).
    """
    with Stages(progress) as stages:
        return _probe_recording(
            agent,
            recording,
            stages,
            seed=seed,
            untrained=untrained,
            test_fraction=test_fraction,
            max_train=max_train,
            solver=solver,
        )


def _probe_recording(
    agent: Any,
    recording: Any,
    stages: Stages,
    *,
    seed: int,
    untrained: bool,
    test_fraction: float,
    max_train: int,
    solver: str,
) -> ProbeReport:
    import torch

    from neurosym.envs import canonical_name, env_family
    from neurosym.meaning.features import head_vectors, replay_observations
    from neurosym.meaning.predicates import state_labels

    env = canonical_name(recording.meta.get("env") or agent.env_name)
    family = env_family(env)
    if len(recording.episodes) < 2:
        raise ConfigError(
            f"probes need at least 2 episodes (one to fit on, one to score on), got {len(recording.episodes)}"
        )
    saved = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        kwargs = recording.meta.get("env_kwargs", agent.env_kwargs)  # what it was played with
        stages.stage("replaying the recorded states", 1)
        obs = replay_observations(recording, env, kwargs)
        labels = state_labels(recording, family)
        feats, _ = head_vectors(agent.model, obs)
        base = None
        if untrained:
            untrained_of = getattr(agent, "untrained", None)  # an outside agent's own re-init
            fresh = untrained_of(seed) if untrained_of else untrained_like(agent.config, seed)
            base, _ = head_vectors(fresh, obs)
    finally:
        torch.set_num_threads(saved)
    module = agent.config.module
    relations = adapter_class(module).relation_count(agent.config)
    fits = (2 if base is not None else 1) * feats.shape[1] * (relations + 1)
    table, skipped = fit_probes(
        feats,
        labels,
        state_types(obs),
        relations=relations or None,
        seed=seed,
        untrained=base,
        test_fraction=test_fraction,
        max_train=max_train,
        solver=solver,
        advance=stages.stage("fitting probes", fits),
    )
    from neurosym import __version__

    meta = {
        "checkpoint": str(getattr(agent, "path", "") or ""),
        "env": env,
        "module": module,
        "heads": int(agent.config.heads),
        "relations": relations,
        "episodes": int(len(recording.episodes)),
        "states": int(len(labels.states)),
        "seed": int(recording.meta.get("seed", seed)),
        "greedy": bool(recording.meta.get("greedy", False)),
        "test_fraction": float(test_fraction),
        "solver": solver,
        "predicates": len(labels.names),
        "probed": len(labels.names) - len(skipped),
        "created": _dt.datetime.now(_dt.UTC).replace(microsecond=0).isoformat(),
        "version": __version__,
    }
    return ProbeReport(table, skipped, meta)


def probe(
    agent: Any,
    env: str | None = None,
    episodes: int = DEFAULT_EPISODES,
    seed: int = 0,
    greedy: bool = False,
    *,
    untrained: bool = True,
    test_fraction: float = TEST_FRACTION,
    max_train: int = MAX_TRAIN,
    solver: str = "batched",
    progress: bool = False,
    env_kwargs: dict[str, Any] | None = None,
) -> ProbeReport:
    """Record ``episodes`` episodes of ``agent`` (sampled by default) and probe its heads.

    Episode k is played from seed ``seed + k`` (as ``neurosym extract`` does).
    ``env``: any env of the agent's family with its observation shape (default:
    its own); ``env_kwargs``: options on top of the agent's.
    """
    from neurosym.record.recorder import record

    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 2:
        raise ConfigError(f"probes need at least 2 episodes, got {episodes!r}")
    if not 0.0 < test_fraction < 1.0:
        raise ConfigError(f"test_fraction must be between 0 and 1, got {test_fraction!r}")
    rec = record(
        agent,
        env,
        episodes=episodes,
        seed=seed,
        greedy=greedy,
        progress=progress,
        env_kwargs=env_kwargs,
    )
    return probe_recording(
        agent,
        rec,
        seed=seed,
        untrained=untrained,
        test_fraction=test_fraction,
        max_train=max_train,
        solver=solver,
        progress=progress,
    )
