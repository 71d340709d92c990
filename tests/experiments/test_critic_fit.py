"""experiments/critic_fit.py: Monte-Carlo returns stop at each episode's end; unfinished tails are left out."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np

_spec = importlib.util.spec_from_file_location(
    "critic_fit", Path(__file__).resolve().parents[2] / "experiments" / "critic_fit.py"
)
critic_fit = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(critic_fit)


def test_mc_returns() -> None:
    # one env: an episode of 3 steps (ends at t = 2), then 2 steps of one that never ends
    rewards = np.array([[0.0], [1.0], [10.0], [5.0], [5.0]], np.float32)
    done = np.array([[False], [False], [True], [False], [False]])
    returns, known = critic_fit.mc_returns(rewards, done, gamma=0.5)
    assert known[:, 0].tolist() == [True, True, True, False, False]
    np.testing.assert_allclose(returns[:3, 0], [0 + 0.5 * 1 + 0.25 * 10, 1 + 0.5 * 10, 10])
