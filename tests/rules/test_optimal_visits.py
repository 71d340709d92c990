"""optimal_visits/2: each RGW level's optimal visit order from the env's own solver.

The order is the level's, not rgw2's: rgw1 and rgw2 share one route (the teleport is
the shortcut on both), a held-out map asks for another, procedural levels for theirs.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from neurosym.envs import make_batched
from neurosym.envs.rgw_solver import optimal_visit_orders
from neurosym.prolog.knowledge_base import KnowledgeBase

REPO = Path(__file__).resolve().parents[2]
RGW2_ROUTE = ("sword", "teleport", "enemy", "terminal")

# A held-out 10 x 10 map: the terminal behind a wall with one gap at (7, 8); the sword far
# down the left, the enemy beside the gap. Sword (9 steps), enemy (6), terminal (6) earns
# 11; the terminal alone earns 10. The teleport leads nowhere useful (no end near a goal).
HELD_OUT = """\
A.........
..........
.........O
....WWWWWW
....W....T
....W.....
....W.....
O...WWWW.W
.S.....E..
..........
"""


def orders(env: str, seeds: list[int], n: int = 4, **kwargs: object) -> list:
    venv = make_batched(env, n, seed=seeds[0], **kwargs)
    try:
        return optimal_visit_orders(venv, seeds)
    finally:
        venv.close()


@pytest.mark.parametrize("env", ["rgw1", "rgw2"])
def test_the_thesis_maps_take_the_teleport_shortcut(env: str) -> None:
    assert orders(env, [0, 1, 2], n=2) == [RGW2_ROUTE] * 3  # two waves of two sub-envs


def test_a_held_out_map_gets_its_own_order(tmp_path: Path) -> None:
    path = tmp_path / "held_out.txt"
    path.write_text(HELD_OUT)
    assert orders("rgw2", [0, 1], map=str(path)) == [("sword", "enemy", "terminal")] * 2


def test_procedural_levels_get_orders_that_fit_their_kinds() -> None:
    """Every solved level ends at the terminal; a guarded one fetches the sword before the
    enemy, one that needs the teleport takes it; the orders differ between levels."""
    seeds = list(range(3_000_000_000, 3_000_000_012))
    venv = make_batched("rgw-random", 12, seed=seeds[0])
    try:
        got = optimal_visit_orders(venv, seeds)
        _, info = venv.reset(seed=seeds)
        kinds = {k: np.asarray(info[k]) for k in ("guarded", "needs_teleport", "optimal_return")}
    finally:
        venv.close()
    assert all(np.isfinite(kinds["optimal_return"]))
    for i, order in enumerate(got):
        assert order is not None and order[-1] == "terminal", (i, order)
        if kinds["guarded"][i]:
            assert order.index("sword") < order.index("enemy") < order.index("terminal"), order
        if kinds["needs_teleport"][i]:
            assert "teleport" in order, order
    assert len(set(got)) > 1, got
    assert kinds["guarded"].any() and not kinds["guarded"].all()


def test_an_unsolvable_level_has_no_order() -> None:
    """With the sword removed a guarded level cannot be won: no optimal return, no order."""
    seeds = list(range(0, 6))
    venv = make_batched("rgw-random", 6, seed=0, edit="remove_sword")
    try:
        got = optimal_visit_orders(venv, seeds)
        _, info = venv.reset(seed=seeds)
    finally:
        venv.close()
    solved = np.isfinite(np.asarray(info["optimal_return"]))
    assert [o is not None for o in got] == solved.tolist()
    assert not solved.all()


def test_extract_on_a_held_out_map_writes_and_compares_the_order(
    neurosym_main, tmp_path: Path
) -> None:
    """The CLI: random actions on the held-out map; the KB holds the map's order for every
    episode, optimal_order/1 answers exactly the episodes that visited in it, and the report
    prints the levels' order and what the comparison counts."""
    path = tmp_path / "held_out.txt"
    path.write_text(HELD_OUT)
    out = tmp_path / "kb"
    proc = neurosym_main(
        "extract", "--checkpoint", REPO / "checkpoints" / "rgw1-mhdpa.pt", "--env", "rgw1",
        "--map", path, "--episodes", "3", "--actions", "random", "--out", out,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    text = " ".join(proc.stdout.split())
    assert "levels' optimal orders (most common) │ [sword,enemy,terminal] x3" in text
    assert "level's optimal order followed │ 0 of 3 episodes of solved levels" in text
    with KnowledgeBase(out / "kb.pl", rules=["rgw"]) as kb:
        assert kb.query("optimal_visits(E, O)") == [
            {"E": e, "O": ("sword", "enemy", "terminal")} for e in range(3)
        ]
        visits = {r["E"]: r["O"] for r in kb.query("visit_order(E, O)")}
        followed = [r["E"] for r in kb.query("optimal_order(E)")]
    assert followed == [e for e, o in visits.items() if o == ("sword", "enemy", "terminal")]


def test_extract_on_procedural_levels_records_each_levels_order(
    neurosym_main, tmp_path: Path
) -> None:
    out = tmp_path / "kb"
    seed = 3_000_000_000
    proc = neurosym_main(
        "extract", "--checkpoint", REPO / "checkpoints" / "rgw-random-predinet-cellkeys.pt",
        "--episodes", "4", "--seed", seed, "--out", out,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    expected = orders("rgw-random", [seed + k for k in range(4)], num_mountains=12)
    with KnowledgeBase(out / "kb.pl", rules=["rgw"]) as kb:
        got = {r["E"]: r["O"] for r in kb.query("optimal_visit_order(E, O)")}
        visits = {r["E"]: r["O"] for r in kb.query("visit_order(E, O)")}
        followed = [r["E"] for r in kb.query("optimal_order(E)")]
    assert got == dict(enumerate(expected))
    assert followed == [e for e in range(4) if visits[e] == got[e]]


def test_box_world_kbs_have_no_optimal_visits(small_agent, tmp_path: Path) -> None:
    """Box-World's chain to the gem is read from the map by rules/boxworld.pl
    (solution_chain/2, followed_solution/1): no optimal_visits/2 facts."""
    from neurosym.facts.tables import extract_facts
    from neurosym.record.recorder import record

    rec = record(small_agent("bw1", "predinet"), "bw1", episodes=2, seed=0, actions="random")
    assert rec.optimal.empty
    path = extract_facts(rec).to_prolog(tmp_path / "kb.pl")
    with KnowledgeBase(path) as kb:
        assert kb.count("optimal_visits(_, _)") == 0  # declared dynamic, no facts
