"""PrologAgent and play_policy: fallbacks counted, strategy errors, eval's figures under eval's names."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from neurosym.agent.cli_eval import score
from neurosym.envs.rgw_solver import Planner
from neurosym.errors import ConfigError, PrologError
from neurosym.play import PrologAgent, play_policy, read_policy

ROOT = Path(__file__).resolve().parents[2]
RGW = ROOT / "examples" / "play" / "rgw_strategy.pl"


def _policy(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "strategy.pl"
    path.write_text(text)
    return path


def test_the_report_has_evals_names_and_figures() -> None:
    report = play_policy(RGW, "rgw2", 2)
    planner = score(Planner(), "rgw2", 2)
    assert set(planner) <= set(report)
    assert report["mean_return"] == pytest.approx(10.7) and report["optimal_rate"] == 1.0
    assert report["outcomes"] == {"terminal": 2} and report["fallback_steps"] == 0
    assert report["steps"] == sum([report["mean_length"]] * 2)


def test_the_hand_written_strategy_is_optimal_where_the_planner_is() -> None:
    """rgw-random seed 1000: the planner earns every optimal return (tests/agent/test_evaluation.py)."""
    report = play_policy(RGW, "rgw-random", 12, seed=1000)
    assert report["success_rate"] == 1.0 and report["sword_first_guarded"] == 1.0
    assert report["optimal_rate"] >= 0.9


def test_no_answer_of_goal_falls_back_to_the_default_goal(tmp_path: Path) -> None:
    """route.pl's default_goal/3 plays instead: the sword, the enemy, the terminal."""
    policy = _policy(tmp_path, "goal(_, _, _) :- fail.\n")
    report = play_policy(policy, "rgw2", 1)
    assert report["fallbacks"] == {"no_goal": report["steps"]}
    assert list(report["goals"]) == ["enemy", "sword", "terminal"]
    assert report["mean_return"] == pytest.approx(10.7) and report["outcomes"] == {"terminal": 1}


def test_a_state_seen_before_goes_to_the_default_goal(tmp_path: Path) -> None:
    """The goal flips with the parity of the agent's cell, so the agent steps back and forth
    between two cells until the second visit of a state hands the step to the default goal."""
    flip = _policy(
        tmp_path,
        "goal(E, T, O) :- at(E, T, agent, R, C), ( 0 is (R + C) mod 2 -> O = sword ; O = terminal ).\n",
    )
    report = play_policy(flip, "rgw-random", 1, seed=12)
    assert report["fallbacks"].get("loop", 0) > 0
    assert report["outcomes"] == {"terminal": 1}


def test_a_goal_off_the_map_counts_as_no_route(tmp_path: Path) -> None:
    policy = _policy(tmp_path, "goal(_, _, unicorn).\n")
    report = play_policy(policy, "rgw1", 1)
    assert report["fallbacks"] == {"no_route": report["steps"]}


def test_a_strategy_that_raises_stops_with_one_line(tmp_path: Path) -> None:
    policy = _policy(tmp_path, "goal(E, T, O) :- O is E / T.\n")
    with pytest.raises(PrologError, match=r"strategy\.pl: .*(evaluable|zero|Arithmetic)") as info:
        play_policy(policy, "rgw2", 1)
    assert "\n" not in str(info.value)


def test_a_strategy_that_loops_is_stopped(tmp_path: Path) -> None:
    policy = _policy(tmp_path, "goal(E, T, O) :- goal(E, T, O).\n")
    with PrologAgent(policy, inference_limit=10_000) as agent:
        venv = agent.make_venv("rgw2", 1, 0)
        obs, _ = venv.reset(seed=[0])
        with pytest.raises(PrologError, match="more than 10,000 inferences"):
            agent.act(obs, venv)
        venv.close()


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("foo(1).\n", "defines no goal/3"),
        (
            "%! features: relations\ngoal(_, _, terminal).\n",
            "give the agent they came from (--checkpoint)",
        ),
        (
            "%! features: pixels\ngoal(_, _, terminal).\n",
            "'%! features: pixels' is not one of world, relations, both",
        ),
        ("goal(_, _, terminal) :- \n", "cannot load"),
    ],
)
def test_bad_strategy_files(tmp_path: Path, text: str, message: str) -> None:
    with pytest.raises((ConfigError, PrologError), match=re.escape(message)):
        PrologAgent(_policy(tmp_path, text))


def test_features_line() -> None:
    assert read_policy(RGW).features == "world"
    with pytest.raises(ConfigError, match="no such policy file"):
        read_policy("no/such.pl")
