"""Box-World's one-hot observation: planes per object type and colour, the held key included."""

from __future__ import annotations

import numpy as np
import pytest

from neurosym.envs import make, make_batched
from neurosym.envs.boxworld_entities import (
    AGENT,
    COLOUR_INDEX,
    GEM,
    HELD,
    KEY,
    LOCK,
    NUM_PLANES,
    ONEHOT,
    TYPE_PLANES,
    WALL,
)
from neurosym.envs.boxworld_solver import nearest_interaction
from neurosym.errors import ConfigError


def test_planes_of_each_code() -> None:
    assert NUM_PLANES == 26 and TYPE_PLANES == ("wall", "agent", "gem", "key", "lock", "held")
    assert ONEHOT[0].sum() == 0  # empty sets nothing
    assert np.flatnonzero(ONEHOT[WALL]).tolist() == [0]
    assert np.flatnonzero(ONEHOT[AGENT]).tolist() == [1]
    assert np.flatnonzero(ONEHOT[GEM]).tolist() == [2]
    red = COLOUR_INDEX["red"]
    assert np.flatnonzero(ONEHOT[KEY + red]).tolist() == [3, 6 + red]
    assert np.flatnonzero(ONEHOT[LOCK + red]).tolist() == [4, 6 + red]
    assert np.flatnonzero(ONEHOT[HELD + red]).tolist() == [5, 6 + red]


def test_single_and_batched_onehot_follow_the_entity_grid() -> None:
    """Driven by the scripted explorer, so keys are picked, held and boxes opened."""
    n = 6
    venv = make_batched("bw3", n, seed=11, obs_mode="onehot")
    singles = [make("bw3", obs_mode="onehot") for _ in range(n)]
    obs, _ = venv.reset(seed=11)
    for i, env in enumerate(singles):
        o, _ = env.reset(seed=11 + i)
        assert np.array_equal(o, obs[i])
    assert obs.shape == (n, 26, 14, 14) and obs.dtype == np.uint8
    assert venv.single_observation_space.shape == (26, 14, 14) and venv.obs_scale == 1.0
    rng = np.random.default_rng(0)
    held_seen = 0
    ended = np.zeros(n, bool)  # single envs are compared until their first episode ends
    for t in range(400):
        grids = venv.entity_grid()
        state = venv._state
        actions = np.array(
            [
                nearest_interaction(grids[i].reshape(-1), int(state.agent[i]), int(state.held[i]))
                if rng.random() < 0.8
                else None
                for i in range(n)
            ],
            dtype=object,
        )
        actions = np.array([rng.integers(4) if a is None else a for a in actions], np.int64)
        obs, _, terminated, truncated, _ = venv.step(actions)
        expected = ONEHOT[venv.entity_grid().reshape(n, -1)].transpose(0, 2, 1).reshape(obs.shape)
        assert np.array_equal(obs, expected), f"[{t}] one-hot planes differ from the entity grid"
        held_seen += int(obs[:, 5, 0, 0].sum())
        for i, env in enumerate(singles):
            if not ended[i]:
                o, *_ = env.step(int(actions[i]))
                assert np.array_equal(o, obs[i]), f"[{t}] env {i}: single and batched differ"
        ended |= terminated | truncated
    assert held_seen > 0, "the explorer never held a key"


def test_rgb_stays_available_and_bad_mode_is_one_line() -> None:
    env = make("bw1")
    obs, _ = env.reset(seed=0)
    assert obs.shape == (3, 14, 14) and env.unwrapped.obs_scale == pytest.approx(1 / 255)
    with pytest.raises(ConfigError, match="obs_mode 'grey' is not one of rgb, onehot"):
        make("bw1", obs_mode="grey")
