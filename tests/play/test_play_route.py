"""rules/route.pl from Python: the hand-made states of its plunit file, and routes on real levels."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from neurosym.play import PrologAgent, score_strategy
from neurosym.prolog.knowledge_base import KnowledgeBase

ROOT = Path(__file__).resolve().parents[2]
FACTS = ROOT / "rules" / "tests" / "route_facts.pl"


@pytest.mark.parametrize(
    ("episode", "t", "goal", "answer"),
    [
        (0, 0, "sword", ("down", 8)),  # around the mountain
        (0, 0, "terminal", ("down", 7)),  # past the pit and the teleport end
        (2, 1, "terminal", ("right", 3)),  # holding the sword: through the enemy
        (3, 1, "lock_red", ("right", 6)),  # around the loose key and the box
    ],
)
def test_route_through_janus(episode: int, t: int, goal: str, answer: tuple) -> None:
    with KnowledgeBase(None, rules=[FACTS, "route"]) as kb:
        rows = kb.query("route(E, T, G, A, C)", E=episode, T=t, G=goal)
    assert [(r["A"], r["C"]) for r in rows] == [answer]


def test_no_route_past_an_unarmed_enemy() -> None:
    with KnowledgeBase(None, rules=[FACTS, "route"]) as kb:
        assert kb.query("route(2, 0, terminal, A)") == []


HOSTILE = (
    ":- dynamic route_pl_memo_/4, memo_/5, moves_/5, searched_/6, grid_/6.\n"
    "route_pl_memo_(0, 0, terminal, found(jump_into_pit, 1)).\n"
    "route_pl_memo_(0, 0, sword, none).\n"
    "memo_(user, 0, 0, terminal, found(left, 1)).\n"
    "moves_(0, 0, user, 0-0, t(terminal, 1, t, t)).\n"
    "searched_(0, user, 1, 0, [], cells(0, 1, 1)).\n"
    "grid_(0, user, 1, 1, adj([]), cells(wall)).\n"
    ":- dynamic searched_/5, grid_/4, cache_key_/2.\n"
    "searched_(0, 1, 0, [], cells(0, 1, 1)).\n"
    "grid_(0, 1, 1, cells(wall)).\n"
    "cache_key_(routes, nowhere).\n"
)
"""facts named like route.pl's caches (the one it once kept in the loading module, the ones
of module route_pl_cache it once kept, and module route's own): planted answers"""


DATA_KB = (
    ":- dynamic object/2, at/5, grid/3.\n"
    "object(terminal, terminal).\n"
    "grid(0, 1, 3).\n"
    "at(0, 0, agent, 0, 0).\n"
    "at(0, 0, terminal, 0, 2).\n"
)
"""a KB as neurosym extract writes one: the agent, then an empty cell, then the terminal"""


@pytest.mark.parametrize("hostile", [False, True])
def test_kb_facts_cannot_change_a_route(
    neurosym_main, swipl: Path, tmp_path: Path, hostile: bool
) -> None:
    """A KB holding facts named like route.pl's private cache answers as one without them:
    a fact KB through neurosym query, and route.plt's states in plain swipl (kb.pl, route.pl)."""
    kb = tmp_path / "kb.pl"
    kb.write_text(DATA_KB + (HOSTILE if hostile else ""))
    goal = "route(0, 0, terminal, A, C), route_moves(0, 0, terminal, D)"
    proc = neurosym_main("query", "--kb", kb, "--rules", "route", goal, "--csv")
    assert (proc.returncode, proc.stdout.split()) == (0, ["A,C,D", "right,2,2"]), proc.stderr
    code = tmp_path / "states.pl"
    code.write_text(FACTS.read_text() + (HOSTILE if hostile else ""))
    shown = (
        "forall((member(G, [terminal, sword]), route(0, 0, G, A, C), route_moves(0, 0, G, D)), "
        "writeln(G-A-C-D))"
    )
    plain = subprocess.run(
        [str(swipl), "-q", "-g", shown, "-t", "halt", str(code), str(ROOT / "rules" / "route.pl")],
        capture_output=True, text=True, timeout=60, check=False,
    )  # fmt: skip
    assert (plain.returncode, plain.stdout) == (0, "terminal-down-7-7\nsword-down-8-4\n"), (
        plain.stderr
    )


def _only(tmp_path: Path, body: str) -> Path:
    path = tmp_path / "strategy.pl"
    path.write_text(f"%! features: world\n{body}\n")
    return path


@pytest.mark.parametrize(("env", "seed"), [("rgw2", 0), ("rgw-random", 12), ("rgw-random", 13)])
def test_following_the_route_reaches_the_sword_and_nothing_else(
    tmp_path: Path, env: str, seed: int
) -> None:
    """Going for the sword only: the first event of the episode is picking it up."""
    policy = _only(tmp_path, "goal(_, _, sword).")
    with PrologAgent(policy) as agent:
        venv = agent.make_venv(env, 1, seed)
        obs, _ = venv.reset(seed=[seed])
        events: list[tuple[str, ...]] = []
        for _ in range(40):
            obs, _r, _term, _trunc, info = venv.step(agent.act(obs, venv))
            events.append(venv.decode_info(info, 0)["events"])
            if "picked(sword)" in events[-1]:
                break
        venv.close()
    assert events[-1] == ("picked(sword)",)
    assert not any(events[:-1]) or set().union(*events[:-1]) <= {"crossed(mountain)"}


def test_box_world_key_then_lock(tmp_path: Path) -> None:
    report = score_strategy(ROOT / "neurosym" / "play" / "strategies" / "boxworld_handwritten.pl", "bw3", 4, seed=5).as_dict()
    assert report["success_rate"] == 1.0 and report["fallback_steps"] == 0
    assert report["mean_return"] == 12.0  # two boxes on the way (+1 each) and the gem (+10)
