"""The batched envs' quick ``episode_outcome`` agrees with the full ``decode_info``."""

from __future__ import annotations

import numpy as np
import pytest

from neurosym.envs import make_batched


@pytest.mark.parametrize(
    ("name", "options", "kinds"),
    [("bw2", {"max_steps": 12}, 1), ("rgw2", {"max_steps": 12}, 1),
     ("rgw-random", {"max_steps": 12, "enemy": "end"}, 2)],  # fmt: skip
)
def test_episode_outcome_is_decode_infos_outcome(name: str, options: dict, kinds: int) -> None:
    env = make_batched(name, 16, seed=5, **options)
    env.reset()
    actions = np.random.default_rng(1).integers(0, 4, (60, 16))
    seen = set()
    for row in actions:
        _, _, terminated, truncated, info = env.step(row)
        for i in range(16):
            outcome = env.episode_outcome(info, i)
            assert outcome == env.decode_info(info, i)["outcome"]
            if terminated[i] or truncated[i]:
                seen.add(outcome)
    assert "timeout" in seen and len(seen) >= kinds  # RGW: pits or enemies end some too
