"""Level-aware evaluation: optimal_rate, sword_first_guarded, no_detour_decoy; one agent, many maps."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from neurosym.agent.agent import load_agent
from neurosym.agent.evaluation import ScoredEpisodes, evaluate, level_scores, score
from neurosym.envs.rgw_solver import Planner
from neurosym.errors import CheckpointError

ROOT = Path(__file__).resolve().parents[2]
RGW2_PREDINET = ROOT / "checkpoints" / "rgw2-predinet.pt"


@pytest.mark.parametrize("kwargs", [{}, {"enemy": "end"}, {"max_steps": 18}])
def test_the_planner_earns_every_optimal_return(kwargs: dict) -> None:
    scores = score(Planner(), "rgw-random", 48, seed=1000, env_kwargs=kwargs)
    assert scores.levels.optimal_rate == 1.0
    assert scores.levels.guarded_episodes + scores.levels.decoy_episodes == 48
    assert scores.levels.guarded_episodes > 5 and scores.levels.decoy_episodes > 5
    if "max_steps" not in kwargs:  # with room enough, the optimal route always finishes
        assert scores.success_rate == 1.0
        assert scores.levels.sword_first_guarded == 1.0 and scores.levels.no_detour_decoy == 1.0


def test_the_planner_on_the_shipped_maps() -> None:
    for env, best in (("rgw2", 10.7), ("rgw1", 11.0)):
        scores = score(Planner(), env, 3)
        assert scores.levels.optimal_rate == 1.0 and round(scores.mean_return, 9) == best
        assert scores.levels.mean_optimal_return == pytest.approx(best)
        assert scores.levels.sword_first_guarded == 1.0 and scores.levels.no_detour_decoy is None


def test_random_actions_are_rarely_optimal() -> None:
    rng = np.random.default_rng(0)
    scores = score(lambda obs, _venv: rng.integers(0, 4, len(obs)), "rgw-random", 120, seed=5)
    assert scores.levels.optimal_rate < 0.1
    assert scores.levels.sword_first_guarded < 0.5


def episodes(**columns) -> ScoredEpisodes:
    n = len(columns["returns"])
    base = {
        "lengths": [10] * n,
        "outcomes": ["terminal"] * n,
        "guarded": [False] * n,
        "sword_first": [False] * n,
        "took_sword": [False] * n,
        "no_sword_best": [float("nan")] * n,
    }
    return ScoredEpisodes(**{**base, **columns})


def test_the_definitions_on_hand_made_episodes() -> None:
    done = episodes(
        returns=[10.7, 10.6999999999, 9.7, 11.0, 9.8, 10.0, -1.0],
        optimal_return=[10.7, 10.7, 10.7, 11.0, 11.0, 11.0, 11.0],
        outcomes=["terminal"] * 6 + ["pit"],
        guarded=[True, True, True, False, False, False, False],
        sword_first=[True, True, False, True, True, False, False],
        took_sword=[True, True, True, True, True, False, False],
        no_sword_best=[float("nan")] * 3 + [10.0, 10.0, 10.0, 10.0],
    )
    got = level_scores(done)
    assert got["optimal_rate"] == pytest.approx(3 / 7)  # 10.7, 10.7 within 1e-6, 11.0
    assert got["guarded_episodes"] == 3 and got["decoy_episodes"] == 4
    assert got["sword_first_guarded"] == pytest.approx(2 / 3)
    # decoys: 11.0 (sword, +1: no loss), 9.8 (a detour lost 0.2), 10.0 (no sword), pit
    assert got["no_detour_decoy"] == pytest.approx(2 / 4)
    assert got["sword_taken_decoy"] == pytest.approx(2 / 4)
    assert level_scores(episodes(returns=[1.0], optimal_return=[float("nan")])) == {}


def test_one_agent_many_maps(tmp_path: Path) -> None:
    agent = load_agent(RGW2_PREDINET)
    on_rgw1 = evaluate(agent, "rgw1", 2)
    assert on_rgw1.env == "rgw1" and on_rgw1.scores.success_rate == 1.0
    assert on_rgw1.scores.levels.optimal_rate == 1.0  # it walks rgw2's route, which is rgw1's best too
    on_random = evaluate(agent, "rgw-random", 4, seed=77)
    assert on_random.episodes == 4 and on_random.scores.levels.optimal_rate is not None
    user_map = tmp_path / "mine.txt"
    user_map.write_text(Path(ROOT / "neurosym/envs/maps/rgw1.txt").read_text())
    mine = evaluate(agent, "rgw2", 1, env_kwargs={"map": str(user_map)})
    assert mine.env_kwargs == {"map": str(user_map)} and mine.scores.mean_return == 11.0
    with pytest.raises(CheckpointError, match="bw1 is a boxworld environment"):
        evaluate(agent, "bw1", 1)
    small = tmp_path / "small.txt"
    small.write_text("AES\n..T\n")
    with pytest.raises(CheckpointError, match=r"rgw2 \(map=.*\) gives \(9, 2, 3\)"):
        evaluate(agent, "rgw2", 1, env_kwargs={"map": str(small)})


def test_eval_cli_on_other_envs(run_neurosym, neurosym_main, tmp_path: Path) -> None:
    proc = run_neurosym(
        "eval", "--checkpoint", RGW2_PREDINET, "--env", "rgw-random", "--episodes", "3", "--json"
    )
    assert proc.returncode == 0, proc.stderr
    report = json.loads(proc.stdout)
    assert report["env"] == "rgw-random"
    for key in ("optimal_rate", "sword_first_guarded", "no_detour_decoy", "success_rate"):
        assert key in report
    mine = tmp_path / "mine.txt"
    mine.write_text(Path(ROOT / "neurosym/envs/maps/rgw2.txt").read_text())
    proc = neurosym_main("eval", "--checkpoint", RGW2_PREDINET, "--map", mine, "--episodes", "1")
    assert proc.returncode == 0, proc.stderr
    assert "optimal      100.0 %" in proc.stdout


def test_plot_on_another_env() -> None:
    from neurosym.viz.episode import episode_figure

    fig = episode_figure(load_agent(RGW2_PREDINET), "rgw-random", frames=2, max_steps=3)
    assert fig.axes


def test_the_typed_result_is_what_eval_json_prints(neurosym_main) -> None:
    """Evaluation.as_dict() is eval --json's object, key for key and in its order."""
    import json

    proc = neurosym_main("eval", "--checkpoint", str(RGW2_PREDINET), "--episodes", "2", "--json")
    assert proc.returncode == 0, proc.stderr
    printed = json.loads(proc.stdout)
    got = evaluate(load_agent(RGW2_PREDINET), episodes=2)
    assert list(got.as_dict()) == list(printed)
    assert got.as_dict() | {"checkpoint": printed["checkpoint"]} == printed
    assert got.scores.levels is not None and got.scores.outcomes == printed["outcomes"]
    on_boxworld = score(lambda obs, _venv: np.zeros(len(obs), dtype=np.int64), "bw1", 1)
    assert on_boxworld.levels is None and "optimal_rate" not in on_boxworld.as_dict()
