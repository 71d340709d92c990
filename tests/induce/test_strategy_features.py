"""Every feature's Prolog definition (in the learned file) agrees with its Python column, pair by pair."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from strategy_kbs import nearest_key_kb, write_kb

from neurosym.induce.strategy import induce_strategy, table
from neurosym.induce.strategy_data import load_trace
from neurosym.induce.strategy_features import BACKGROUND, world_features
from neurosym.induce.strategy_route import PROLOG, shortcuts, trace_routes
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
def test_features_agree_on_recorded_kbs(neurosym_main, monkeypatch, tmp_path: Path, checkpoint: str, env: str) -> None:  # type: ignore[no-untyped-def]
    monkeypatch.chdir(Path(__file__).resolve().parents[2])  # checkpoints/ as from the repository
    r = neurosym_main(
        "extract", "--checkpoint", f"checkpoints/{checkpoint}.pt", "--env", env,
        "--episodes", 4, "--seed", 3_000_000_000, "--out", tmp_path / "kb", "--quiet",
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    kb = tmp_path / "kb" / "kb.pl"
    s = induce_strategy(kb, "both", holdout=kb)
    assert check_features_agree(kb, s.write(tmp_path / "s.pl"), "both") > 20


TELEPORT_MAP = [
    "kb_meta(env,'rgw-random').", "object(agent,agent).", "object(teleport_1,teleport).",
    "object(teleport_2,teleport).", "object(terminal,terminal).", "object(sword,sword).",
    "grid(0,3,5).", "terrain(0,wall,0,2).", "terrain(0,wall,1,2).", "terrain(0,wall,2,2).",
    "terrain(0,mountain,1,0).",
    "at(0,0,agent,2,0).", "at(0,0,sword,1,1).", "at(0,0,teleport_1,0,1).",
    "at(0,0,teleport_2,2,3).", "at(0,0,terminal,0,4).", "step(0,0,up,0.0).",
]  # fmt: skip
"""      c0 c1 c2 c3 c4
  r0   .  X  W  .  T      a wall column; the teleport's ends X on either side, the sword S
  r1   M  S  W  .  .      in the way to the left one, a mountain M
  r2   A  .  W  X  ."""


def test_route_features_on_a_teleport_map(tmp_path: Path) -> None:
    """Route lengths (route.pl's route_moves/5: the sword and a mountain are crossed, a wall
    column is not) and the teleport shortcut they make, in the Python columns and in the file."""
    kb = write_kb(tmp_path / "kb.pl", TELEPORT_MAP)
    trace = load_trace(kb)
    routes = trace_routes(trace)
    assert {o: routes.length(0, 0, o) for o in ("sword", "teleport_1", "teleport_2", "terminal")} == {
        "sword": 2, "teleport_1": 3, "teleport_2": 999, "terminal": 999,
    }  # fmt: skip
    assert routes.after[(0, 0, "teleport_2", "terminal")] == 3
    kinds = {"sword": "sword", "teleport_1": "teleport", "teleport_2": "teleport", "terminal": "terminal"}
    assert shortcuts(routes, (0, 0), list(kinds), kinds) == {"teleport_1": {"terminal"}}
    pairs = trace.at[trace.at["O"] != "agent"].reset_index(drop=True)
    names, x = world_features(trace, pairs)
    column = {f.name: x[:, j] for j, f in enumerate(names)}
    assert dict(zip(pairs["O"], column["teleport_shortcut=terminal"], strict=True)) == {
        "sword": 0, "teleport_1": 1, "teleport_2": 0, "terminal": 0,
    }  # fmt: skip
    with KnowledgeBase(kb, rules=["route"]) as prolog:
        prolog.load_rules(_features_file(tmp_path))
        assert prolog.query("teleport_shortcut(0, 0, O, terminal)") == [{"O": "teleport_1"}]
        assert prolog.query("route_length(0, 0, sword, D)") == [{"D": 2}]


def _features_file(tmp_path: Path) -> Path:
    """The feature predicates a learned file carries, as a file of their own."""
    path = tmp_path / "features.pl"
    path.write_text(BACKGROUND + PROLOG)
    return path
