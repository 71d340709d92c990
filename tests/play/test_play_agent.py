"""PrologAgent and score_strategy: fallbacks counted, strategy errors, eval's figures under eval's names."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from neurosym.agent.evaluation import score
from neurosym.envs.rgw_solver import Planner
from neurosym.errors import ConfigError, PrologError
from neurosym.play import PrologAgent, read_policy, score_strategy

ROOT = Path(__file__).resolve().parents[2]
RGW = ROOT / "neurosym" / "play" / "strategies" / "rgw_handwritten.pl"


def _policy(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "strategy.pl"
    path.write_text(text)
    return path


def test_the_report_has_evals_names_and_figures() -> None:
    report = score_strategy(RGW, "rgw2", 2).as_dict()
    planner = score(Planner(), "rgw2", 2).as_dict()
    assert set(planner) <= set(report)
    assert report["mean_return"] == pytest.approx(10.7) and report["optimal_rate"] == 1.0
    assert report["outcomes"] == {"terminal": 2} and report["fallback_steps"] == 0
    assert report["steps"] == sum([report["mean_length"]] * 2)


def test_the_hand_written_strategy_is_optimal_where_the_planner_is() -> None:
    """rgw-random seed 1000: the planner earns every optimal return (tests/agent/test_evaluation.py)."""
    report = score_strategy(RGW, "rgw-random", 12, seed=1000).as_dict()
    assert report["success_rate"] == 1.0 and report["sword_first_guarded"] == 1.0
    assert report["optimal_rate"] >= 0.9


def test_no_answer_of_goal_falls_back_to_the_default_goal(tmp_path: Path) -> None:
    """route.pl's default_goal/3 plays instead: the sword, the enemy, the terminal."""
    policy = _policy(tmp_path, "goal(_, 0, sword).\n")
    report = score_strategy(policy, "rgw2", 1).as_dict()
    assert report["fallbacks"] == {"no_goal": report["steps"] - 1}
    assert list(report["goals"]) == ["enemy", "sword", "terminal"]
    assert report["mean_return"] == pytest.approx(10.7) and report["outcomes"] == {"terminal": 1}


def test_a_state_seen_before_goes_to_the_default_goal(tmp_path: Path) -> None:
    """The goal flips with the parity of the agent's cell, so the agent steps back and forth
    between two cells until the second visit of a state hands the step to the default goal."""
    flip = _policy(
        tmp_path,
        "goal(E, T, O) :- at(E, T, agent, R, C), ( 0 is (R + C) mod 2 -> O = sword ; O = terminal ).\n",
    )
    report = score_strategy(flip, "rgw-random", 1, seed=12).as_dict()
    assert report["fallbacks"].get("loop", 0) > 0
    assert report["outcomes"] == {"terminal": 1}


def test_a_goal_off_the_map_counts_as_no_route(tmp_path: Path) -> None:
    policy = _policy(tmp_path, "goal(_, T, unicorn) :- T > 0.\ngoal(_, 0, sword).\n")
    report = score_strategy(policy, "rgw1", 1).as_dict()
    assert report["fallbacks"] == {"no_route": report["steps"] - 1}


def test_fallback_none_ends_the_episode_where_the_strategy_has_no_answer(tmp_path: Path) -> None:
    """goal/3 answers in state 0 only: the episode ends in state 1 as a failure, outcome
    no_goal; that step counts in its length, with reward 0 and no events (rgw2: no sword taken
    on the way), and what decided each step is counted."""
    policy = _policy(tmp_path, "goal(_, 0, sword).\n")
    report = score_strategy(policy, "rgw2", 2, fallback="none").as_dict()
    assert report["outcomes"] == {"no_goal": 2} and report["success_rate"] == 0.0
    assert report["mean_length"] == 2 and report["mean_return"] == 0.0
    assert report["optimal_rate"] == 0.0 and report["sword_first_guarded"] == 0.0
    assert report["fallback"] == "none" and report["fallbacks"] == {"no_goal": 2}
    assert report["deciders"] == {
        "strategy": 2, "default_goal": 0, "safe_step": 0, "up": 0, "none": 2,
    }  # fmt: skip
    assert report["decider_shares"]["none"] == 0.5


def test_fallback_none_ends_the_episode_where_the_goal_routes_nowhere(tmp_path: Path) -> None:
    policy = _policy(tmp_path, "goal(_, T, unicorn) :- T > 0.\ngoal(_, 0, sword).\n")
    report = score_strategy(policy, "rgw1", 1, fallback="none").as_dict()
    assert report["outcomes"] == {"no_route": 1} and report["mean_length"] == 2
    assert report["deciders"]["none"] == 1 and report["fallbacks"] == {"no_route": 1}


def test_deciders_with_the_default_fallback(tmp_path: Path) -> None:
    """The same strategy under the default fallback: default_goal/3 decides from state 1 on."""
    policy = _policy(tmp_path, "goal(_, 0, sword).\n")
    report = score_strategy(policy, "rgw2", 1).as_dict()
    steps = report["steps"]
    assert report["deciders"] == {
        "strategy": 1, "default_goal": steps - 1, "safe_step": 0, "up": 0, "none": 0,
    }  # fmt: skip
    assert sum(report["decider_shares"].values()) == pytest.approx(1.0)


def test_an_unknown_fallback_is_refused() -> None:
    with pytest.raises(ConfigError, match="fallback must be one of default, none, got 'never'"):
        PrologAgent(RGW, fallback="never")


@pytest.mark.parametrize(
    ("policy", "env", "causes"),
    [
        (RGW, "bw2", "no_route 34"),  # an RGW strategy on Box-World: its objects are not there
        (None, "rgw2", "no_goal 42"),  # goal/3 never answers
    ],
)
def test_a_strategy_that_never_chose_is_refused(
    tmp_path: Path, policy: Path | None, env: str, causes: str
) -> None:
    """Every step a fallback: the figures would be route.pl's default strategy's, not its own."""
    policy = policy or _policy(tmp_path, "goal(_, _, _) :- fail.\n")
    with pytest.raises(ConfigError) as info:
        score_strategy(policy, env, 2)
    assert str(info.value) == (
        f"{policy} chose no object it could reach in any of the {causes.split()[1]} steps on "
        f"{env} (fallbacks: {causes}); is it a strategy for another env (its goal/3 names "
        "objects this env's levels do not hold)?"
    )


def test_a_strategy_that_raises_stops_with_one_line(tmp_path: Path) -> None:
    policy = _policy(tmp_path, "goal(E, T, O) :- O is E / T.\n")
    with pytest.raises(PrologError, match=r"strategy\.pl: .*(evaluable|zero|Arithmetic)") as info:
        score_strategy(policy, "rgw2", 1)
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
        ("goal(_, _, terminal) :- \n", "strategy.pl:1: Syntax error: Unexpected end of file"),
    ],
)
def test_bad_strategy_files(tmp_path: Path, text: str, message: str) -> None:
    with pytest.raises((ConfigError, PrologError), match=re.escape(message)):
        PrologAgent(_policy(tmp_path, text))


def test_features_line() -> None:
    assert read_policy(RGW).features == "world"
    with pytest.raises(ConfigError, match="no such policy file"):
        read_policy("no/such.pl")


@pytest.mark.parametrize(
    ("text", "line", "message"),
    [
        (
            "goal(_, _, terminal).\n:- halt.\n",
            2,
            "the directive :- halt would run when the strategy loads; a strategy file holds "
            "goal/3 and its helpers as clauses, and its directives may only be dynamic, "
            "discontiguous or use_module(library(Name))",
        ),
        (
            ":- initialization(shell('true')).\n",
            1,
            "the directive :- initialization shell(true) would run when the strategy loads; a "
            "strategy file holds goal/3 and its helpers as clauses, and its directives may only "
            "be dynamic, discontiguous or use_module(library(Name))",
        ),
        (
            ":- use_module(library('../../tmp/x')).\n",
            1,
            "the directive :- use_module(library('../../tmp/x')) would run when the strategy "
            "loads; a strategy file holds goal/3 and its helpers as clauses, and its directives "
            "may only be dynamic, discontiguous or use_module(library(Name))",
        ),
        (
            "goal(_, _, terminal) :- halt.\n",
            1,
            "it names halt/0; a strategy may not end the process, run programs, load code or "
            "change files",
        ),
        (
            "goal(_, _, O) :- findall(x, call(shell, ls), _), O = terminal.\n",
            1,
            "it names shell/0; a strategy may not end the process, run programs, load code or "
            "change files",
        ),
        (
            "goal(_, _, terminal).\nroute(_, _, _, jump).\n",
            2,
            "a clause for route/4, which module route (rules/route.pl) exports; a strategy calls "
            "route's predicates (default_goal/3, route/4, route/5, route_distance/4, "
            "route_exists/3, route_forget/1, route_moves/4, route_moves/5, safe_step/3) and may "
            "not redefine them",
        ),
        (
            "term_expansion(a, (:- halt)).\na.\n",
            1,
            "a clause for term_expansion/2, which SWI-Prolog calls while it loads files; a "
            "strategy may not define it",
        ),
        (
            "system:goal(_, _, terminal).\n",
            1,
            "a clause for system:goal/3; a strategy defines its predicates where it "
            "is loaded, not in another module",
        ),
    ],
)
def test_a_strategy_file_cannot_run_code_as_it_loads(
    tmp_path: Path, text: str, line: int, message: str
) -> None:
    """Directives, load hooks, other modules' and route.pl's predicates, process-level calls:
    refused with one line naming file and line before anything of the file runs."""
    policy = _policy(tmp_path, text)
    with pytest.raises(ConfigError) as info:
        PrologAgent(policy)
    assert str(info.value) == f"{policy}:{line}: {message}"


@pytest.mark.parametrize(
    ("text", "stop"),
    [
        ("goal(_, _, terminal) :- atom_concat(ha, lt, G), call(G).\n", "halt/0"),
        ("goal(_, _, terminal) :- atom_concat(ab, ort, G), call(G).\n", "abort/0"),
        ("goal(_, _, terminal) :- atom_concat(ha, lt, G), call(system:G).\n", "halt"),
    ],
)
def test_a_strategy_that_ends_the_process_at_run_time_is_an_error(
    run_neurosym, tmp_path: Path, text: str, stop: str
) -> None:
    """halt and abort built at run time: one line and status 1, never a silent exit 0."""
    policy = _policy(tmp_path, text)
    proc = run_neurosym("play", "--policy", policy, "--env", "rgw2", "--episodes", "1")
    assert (proc.returncode, proc.stdout) == (1, ""), proc.stderr
    assert proc.stderr.startswith(f"neurosym play: error: {policy}: ")
    assert stop in proc.stderr and len(proc.stderr.splitlines()) == 1


@pytest.mark.parametrize(
    ("facts", "message"),
    [
        ("object(agent, agent).\n", "holds no threshold/2 facts, which say when a relation "
         "holds: --kb must be the KB the strategy was learned from, as neurosym extract writes it"),
        ("threshold(a, 0.5).\n", ": threshold(a, 0.5) is not threshold(J, V) with J a relation "
         "index (0 to 65535) and V a number >= 0, as neurosym extract writes it"),
        ("threshold(0, f(x)).\n", ": threshold(0, f(x)) is not threshold(J, V)"),
        ("threshold(20000000, 0.5).\n", ": threshold(20000000, 0.5) is not threshold(J, V)"),
    ],
)  # fmt: skip
def test_kb_thresholds_are_checked(tmp_path: Path, facts: str, message: str) -> None:
    from neurosym.play.evaluate import kb_thresholds

    kb = tmp_path / "kb.pl"
    kb.write_text(facts)
    with pytest.raises(ConfigError) as info:
        kb_thresholds(kb)
    assert str(info.value).startswith(f"{kb}{' ' if message[0] != ':' else ''}{message}")


def test_a_file_name_that_is_not_utf8_is_refused(tmp_path: Path) -> None:
    import os

    name = os.fsdecode(os.fsencode(str(tmp_path)) + b"/bad\xff.pl")
    Path(name).write_text("goal(_, _, terminal).\n")
    with pytest.raises(ConfigError) as info:
        score_strategy(name, "rgw2", 1)
    assert str(info.value) == (
        f"--policy {name!r}: the file name is not UTF-8, which SWI-Prolog needs; rename the file"
    )


def test_a_strategy_may_define_library_predicate_names(tmp_path: Path) -> None:
    """As learned strategies do (reachable/3 is also library(ugraphs)'s): checking the file
    autoloads nothing that would then clash with its clauses."""
    policy = _policy(
        tmp_path,
        ":- use_module(library(lists)).\n"
        "reachable(E, T, O) :- route_exists(E, T, O).\n"
        "goal(E, T, O) :- member(O, [sword, terminal]), reachable(E, T, O).\n",
    )
    report = score_strategy(policy, "rgw2", 1).as_dict()
    assert report["fallback_steps"] == 0 and report["outcomes"] == {"terminal": 1}


def test_the_typed_result_is_what_play_json_prints(neurosym_main) -> None:
    """score_strategy's StrategyPlay: eval's Scores, deciders that count every step, and
    as_dict() is play --json's object but for the speed."""
    import json

    played = score_strategy(RGW, "rgw2", 1)
    assert played.scores.success_rate == 1.0 and played.scores.levels is not None
    assert sum(played.deciders.values()) == played.steps == 21
    proc = neurosym_main("play", "--policy", RGW, "--env", "rgw2", "--episodes", "1", "--json")
    assert proc.returncode == 0, proc.stderr
    printed = json.loads(proc.stdout)
    mine = played.as_dict()
    assert list(mine) == list(printed)
    assert {k: v for k, v in mine.items() if k != "steps_per_s"} == {
        k: v for k, v in printed.items() if k != "steps_per_s"
    }
