"""Strategies learned from real recorded KBs: goal/3's first answer in swipl equals Python's choice."""

from __future__ import annotations

from pathlib import Path

import pytest
from test_strategy_learn import _prolog_choices

from neurosym.induce.strategy import induce_strategy
from neurosym.induce.strategy_data import load_trace


@pytest.mark.expensive
@pytest.mark.parametrize(
    ("checkpoint", "env", "features"),
    [
        ("rgw-random-predinet-cellkeys", "rgw-random", "both"),
        ("rgw-random-mhdpa", "rgw-random", "relations"),
        ("bw2-predinet", "bw2", "world"),
    ],
)
def test_real_kb_round_trip(neurosym_main, monkeypatch, swipl: Path, tmp_path: Path, checkpoint: str, env: str, features: str) -> None:  # type: ignore[no-untyped-def]
    monkeypatch.chdir(Path(__file__).resolve().parents[2])  # checkpoints/ as from the repository
    kbs = []
    for part, seed, episodes in (("train", 2_000_000_000, 8), ("test", 3_000_000_000, 4)):
        r = neurosym_main(
            "extract", "--checkpoint", f"checkpoints/{checkpoint}.pt", "--env", env,
            "--episodes", episodes, "--seed", seed, "--out", tmp_path / part, "--quiet",
        )  # fmt: skip
        assert r.returncode == 0, r.stderr
        kbs.append(tmp_path / part / "kb.pl")
    s = induce_strategy(kbs[0], features, holdout=kbs[1])
    path = s.write(tmp_path / "strategy.pl")
    prolog = _prolog_choices(swipl, kbs[1], path)
    python = s.predict(load_trace(kbs[1]))
    assert len(python) > 0
    for e, t, choice in zip(python["E"], python["T"], python["Choice"], strict=True):
        assert prolog[(e, t)] == choice, f"[{e},{t}]"
