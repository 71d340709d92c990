"""Probes: a predicate planted in synthetic relation vectors is found, noise is rejected.

Also: the batched logistic fits agree with scikit-learn's, control labels keep
the predicate's balance, constant predicates are skipped with a reason.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from neurosym.errors import ConfigError
from neurosym.meaning.predicates import StateLabels
from neurosym.meaning.probe import (
    control_labels,
    fit_probes,
    logistic_accuracy,
    logistic_fit,
    sklearn_accuracy,
    state_types,
)

EPISODES, STEPS, HEADS, J = 40, 30, 2, 4


def synthetic(seed: int = 0) -> tuple[np.ndarray, StateLabels, np.ndarray]:
    """(S, H, J + 4) features: head 0's relation 2 carries `planted`; everything else is noise."""
    rng = np.random.default_rng(seed)
    S = EPISODES * STEPS
    feats = rng.normal(size=(S, HEADS, J + 4))
    planted = rng.random(S) < 0.4
    feats[:, 0, 2] = np.where(planted, 1.5, -1.5) + 0.3 * rng.normal(size=S)
    noise = rng.random(S) < 0.5  # independent of every feature
    states = pd.DataFrame(
        {"episode": np.repeat(np.arange(EPISODES), STEPS), "t": np.tile(np.arange(STEPS), EPISODES)}
    )
    labels = StateLabels(
        states,
        ["planted", "noise", "constant"],
        np.stack([planted, noise, np.zeros(S, dtype=bool)], axis=1),
    )
    types = np.arange(S)  # every state its own type: nothing to memorise across episodes
    return feats, labels, types


def test_planted_predicate_is_found_where_it_was_planted() -> None:
    feats, labels, types = synthetic()
    table, skipped = fit_probes(feats, labels, types, relations=J, seed=0, untrained=None)
    row = table[
        (table["head"] == 0) & (table.relation == "2") & (table.predicate == "planted")
    ].iloc[0]
    assert row.accuracy > 0.97
    assert row.selectivity > 0.3
    assert row.control == pytest.approx(max(row.control_task, row.majority))
    elsewhere = table[(table.predicate == "planted") & (table["head"] == 1)]
    assert (elsewhere.selectivity.abs() < 0.08).all(), elsewhere
    whole = table[(table["head"] == 0) & (table.relation == "all") & (table.predicate == "planted")]
    assert whole.accuracy.iloc[0] > 0.95  # the whole vector contains relation 2


def test_noise_is_rejected() -> None:
    feats, labels, types = synthetic(1)
    table, _ = fit_probes(feats, labels, types, relations=J, seed=1, untrained=None)
    noise = table[table.predicate == "noise"]
    assert len(noise) == HEADS * (J + 1)
    assert noise.selectivity.abs().max() < 0.08, noise


def test_constant_predicate_is_skipped_never_scored() -> None:
    feats, labels, types = synthetic()
    table, skipped = fit_probes(feats, labels, types, relations=J, seed=0, untrained=None)
    assert "constant" not in set(table.predicate)
    assert skipped.predicate.tolist() == ["constant"]
    assert skipped.reason.iloc[0].startswith("constant: false in all 1200")


def test_untrained_columns_and_relation_names() -> None:
    feats, labels, types = synthetic()
    rng = np.random.default_rng(5)
    table, _ = fit_probes(
        feats, labels, types, relations=J, seed=0, untrained=rng.normal(size=feats.shape)
    )
    assert sorted(set(table.relation)) == ["0", "1", "2", "3", "all"]
    planted = table[(table["head"] == 0) & (table.relation == "2") & (table.predicate == "planted")]
    assert planted.untrained_selectivity.iloc[0] < 0.1  # random features know nothing
    assert table.untrained_accuracy.notna().all()


def test_one_episode_cannot_be_split() -> None:
    feats, labels, types = synthetic()
    one = StateLabels(labels.states.assign(episode=0), labels.names, labels.values)
    with pytest.raises(ConfigError, match="at least 2 episodes"):
        fit_probes(feats, one, types, relations=J)


def test_control_labels_keep_the_balance_and_are_functions_of_the_type() -> None:
    rng = np.random.default_rng(0)
    types = rng.integers(0, 300, size=5000)
    ctl = control_labels(types, 0.3, np.random.default_rng(1))
    assert abs(ctl.mean() - 0.3) < 0.02
    for t in np.unique(types)[:50]:
        assert len(set(ctl[types == t].tolist())) == 1


def test_state_types_group_identical_observations() -> None:
    obs = np.zeros((4, 2, 3, 3), dtype=np.uint8)
    obs[1, 0, 1, 1] = 1
    obs[3] = obs[1]
    assert state_types(obs).tolist() == [0, 1, 0, 1]


@pytest.mark.parametrize("d", [1, 6])
def test_batched_logistic_fits_agree_with_scikit_learn(d: int) -> None:
    from sklearn.linear_model import LogisticRegression

    rng = np.random.default_rng(d)
    X = rng.normal(size=(400, d))
    Y = X[:, :1].T * rng.normal(size=(5, 1)) + rng.normal(size=(5, 400)) > 0.2  # (5, n)
    w, b = logistic_fit(X, Y)
    for m in range(5):
        ref = LogisticRegression(C=1.0, tol=1e-10, max_iter=10_000).fit(X, Y[m])
        np.testing.assert_allclose(w[m], ref.coef_[0], atol=1e-4)
        assert b[m] == pytest.approx(ref.intercept_[0], abs=1e-4)
    X_te = rng.normal(size=(200, d))
    Y_te = X_te[:, 0][None] > 0
    Y_te = np.repeat(Y_te, 5, axis=0)
    acc = logistic_accuracy(X, Y, X_te, Y_te)
    for m in range(5):
        assert acc[m] == pytest.approx(sklearn_accuracy(X, Y[m], X_te, Y_te[m]), abs=0.011)
