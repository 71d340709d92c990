"""Every feature's Prolog definition (in the learned file) agrees with its Python column, pair by pair."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from strategy_kbs import nearest_key_kb

from neurosym.induce.strategy import induce_strategy, table
from neurosym.induce.strategy_data import load_trace
from neurosym.prolog.knowledge_base import KnowledgeBase


def check_features_agree(kb: Path, strategy_file: Path, features: str) -> int:
    """Compare each feature on every labelled pair of ``kb``; return how many features were checked."""
    names, tab = table(load_trace(kb), features)
    pairs = list(zip(tab.pairs["E"], tab.pairs["T"], tab.pairs["O"], strict=True))
    with KnowledgeBase(kb, rules=["route", strategy_file]) as prolog:
        for j, f in enumerate(names):
            if f.numeric:
                rows = prolog.query(f"goal_candidate(E, T, O), {f.goal}")
                got = {(r["E"], r["T"], r["O"]): float(r["V"]) for r in rows}
                want = {p: float(v) for p, v in zip(pairs, tab.x[:, j], strict=True)}
                assert {p: got.get(p) for p in pairs} == want, f.name
            else:
                rows = prolog.query(f"goal_candidate(E, T, O), once({f.goal})")
                got_set = {(r["E"], r["T"], r["O"]) for r in rows}
                want_set = {p for p, v in zip(pairs, tab.x[:, j], strict=True) if v == 1}
                assert got_set & set(pairs) == want_set, f.name
    return len(names)


def test_features_agree_on_a_generated_kb(tmp_path: Path) -> None:
    kb = nearest_key_kb(tmp_path / "kb.pl", 8, seed=5)
    s = induce_strategy(kb, "both", holdout=kb)
    path = s.write(tmp_path / "s.pl")
    assert check_features_agree(kb, path, "both") > 10
    assert np.isfinite(s.fidelity)


@pytest.mark.expensive
@pytest.mark.parametrize(("checkpoint", "env"), [("rgw-random-predinet-cellkeys", "rgw-random"), ("rgw-random-mhdpa", "rgw-random"), ("bw2-predinet", "bw2")])
def test_features_agree_on_recorded_kbs(run_neurosym, tmp_path: Path, checkpoint: str, env: str) -> None:  # type: ignore[no-untyped-def]
    r = run_neurosym(
        "extract", "--checkpoint", f"checkpoints/{checkpoint}.pt", "--env", env,
        "--episodes", 4, "--seed", 3_000_000_000, "--out", tmp_path / "kb", "--quiet",
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    kb = tmp_path / "kb" / "kb.pl"
    s = induce_strategy(kb, "both", holdout=kb)
    assert check_features_agree(kb, s.write(tmp_path / "s.pl"), "both") > 20
