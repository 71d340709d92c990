"""The one play loop: waves of seeded episodes, who the policy sees, idle sub-envs, the step limit."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from neurosym.agent.waves import EpisodeTooLong, SingleAsBatch, run_waves
from neurosym.errors import ConfigError


class CountdownVenv:
    """Sub-env i's episode lasts ``seed % 3 + 1`` steps (``forever``: never ends), reward = action + 1.

    The observation of a sub-env is its reset seed, so a test sees which episode the policy acted on.
    """

    def __init__(self, num_envs: int, forever: bool = False) -> None:
        self.num_envs, self.forever = num_envs, forever
        self.seeds = np.zeros(num_envs, dtype=np.int64)
        self.left = np.zeros(num_envs, dtype=np.int64)
        self.stepped: list[np.ndarray] = []

    def reset(self, seed: list[int]) -> tuple[np.ndarray, dict[str, Any]]:
        assert len(seed) == self.num_envs
        self.seeds = np.asarray(seed, dtype=np.int64)
        self.left = self.seeds % 3 + 1
        return self.seeds.copy(), {}

    def step(self, actions: np.ndarray) -> tuple[np.ndarray, ...]:
        self.stepped.append(actions.copy())
        self.left -= 1
        done = (self.left == 0) & (not self.forever)
        return self.seeds.copy(), actions + 1.0, done, np.zeros(self.num_envs, bool), {}


def _play(venv: CountdownVenv, act_on: str, episodes: int, batch: int) -> tuple[dict, list]:
    seen: list[list[int]] = []

    def act(obs: np.ndarray, _venv: Any) -> np.ndarray:
        seen.append(obs.tolist())
        return np.ones(len(obs), dtype=np.int64)

    result: dict[int, tuple[float, int]] = {}
    for wave in run_waves(act, lambda _n: venv, episodes, 100, batch, act_on=act_on):
        for step in wave.steps():
            assert (step.episodes == wave.first + step.live).all()
        for i in range(wave.count):
            result[wave.first + i] = (float(wave.returns[i]), int(wave.lengths[i]))
    return result, seen


def test_episode_k_plays_seed_plus_k_and_only_live_steps_count() -> None:
    result, _ = _play(CountdownVenv(3), "all", episodes=5, batch=3)
    # seed 100 + k lasts (100 + k) % 3 + 1 steps, each worth action 1 + 1 = 2
    assert result == {k: (2.0 * ((100 + k) % 3 + 1), (100 + k) % 3 + 1) for k in range(5)}


def test_act_on_live_shows_the_policy_only_running_episodes() -> None:
    venv = CountdownVenv(3)
    _, seen = _play(venv, "live", episodes=5, batch=3)
    # wave 1 (seeds 100..102 last 2, 3, 1 steps), wave 2 (seeds 103, 104 live; 105 idle)
    assert seen == [[100, 101, 102], [100, 101], [101], [103, 104], [103, 104], [104]]
    assert venv.stepped[1].tolist() == [1, 1, 0]  # the ended sub-env steps "up"


def test_act_on_all_shows_the_policy_the_whole_batch() -> None:
    _, seen = _play(CountdownVenv(3), "all", episodes=5, batch=3)
    assert seen == [[100, 101, 102]] * 3 + [[103, 104, 105]] * 3


def test_an_endless_episode_is_an_error_unless_the_caller_stops_at_the_limit() -> None:
    act = lambda obs, _venv: np.zeros(len(obs), dtype=np.int64)  # noqa: E731
    waves = run_waves(act, lambda n: CountdownVenv(n, forever=True), 2, 0, 2, max_steps=4)
    with pytest.raises(ConfigError, match="episode 0 ran 4 steps without ending"):
        for wave in waves:
            list(wave.steps())
    assert issubclass(EpisodeTooLong, ConfigError)
    stopped = run_waves(
        act, lambda n: CountdownVenv(n, forever=True), 2, 0, 2, max_steps=4, stop_at_limit=True
    )
    assert [len(list(wave.steps())) for wave in stopped] == [4]


def test_a_single_env_plays_as_the_same_episode_as_in_a_batch() -> None:
    from neurosym.envs import make, make_batched

    rng_actions = np.random.default_rng(0).integers(0, 4, size=500)
    act = lambda obs, _venv: rng_actions[: len(obs)]  # noqa: E731

    def lengths(venv_for: Any, episodes: int) -> list[tuple[float, int]]:
        out = []
        for wave in run_waves(act, venv_for, episodes, 7, 1, act_on="live"):
            list(wave.steps())
            out.append((float(wave.returns[0]), int(wave.lengths[0])))
        return out

    single = lengths(lambda _n: SingleAsBatch(make("rgw2")), 2)
    batched = lengths(lambda n: make_batched("rgw2", n), 2)
    assert single == batched and all(n > 0 for _, n in single)


def test_act_on_must_be_live_or_all() -> None:
    with pytest.raises(ValueError, match="act_on must be 'live' or 'all', got 'some'"):
        next(run_waves(lambda o, v: o, lambda n: CountdownVenv(n), 1, 0, 1, act_on="some"))
