"""The grid's symmetries: the planner's optimal actions turn with the level, and batches move their columns."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from neurosym.agent.learners.augment import (
    TRANSFORMS,
    action_permutation,
    augment_batch,
    transform_grid,
)
from neurosym.envs import make_batched
from neurosym.envs.rgw_solver import Plan


def test_quarter_turn_and_mirror_permutations() -> None:
    # actions: 0 up, 1 right, 2 down, 3 left; torch.rot90 turns counter-clockwise
    assert action_permutation(0, False, 10, 10) == (0, 1, 2, 3)
    assert action_permutation(1, False, 10, 10) == (3, 0, 1, 2)  # up becomes left
    assert action_permutation(0, True, 10, 10) == (0, 3, 2, 1)  # mirror: left <-> right
    assert sorted(action_permutation(3, True, 6, 6)) == [0, 1, 2, 3]
    with pytest.raises(ValueError, match="square grid"):
        action_permutation(1, False, 6, 8)


def test_the_planner_agrees_on_every_turned_or_mirrored_level() -> None:
    """The level turned is a level whose optimal actions are the original's turned (the exact search)."""
    venv = make_batched("rgw-random", 12, seed=7)
    venv.reset(seed=7)
    env = venv.unwrapped
    cells, starts = env.current_levels()
    H, W = env.height, env.width
    for i in range(len(cells)):
        start = int(starts[i])
        plan = Plan(cells[i], starts[i], H, W, env.rules)
        best, value = plan.action_set(0, start, 0, 100), plan.value(0, start, 0, 100)
        for k, flip in TRANSFORMS[1:]:
            grid = transform_grid(torch.from_numpy(cells[i].reshape(H, W).copy()), k, flip)
            marker = torch.zeros(H * W)
            marker[start] = 1
            moved_start = int(transform_grid(marker.view(H, W), k, flip).reshape(-1).argmax())
            turned = Plan(
                grid.contiguous().numpy().reshape(-1), np.array([moved_start]), H, W, env.rules
            )
            expected = np.empty_like(best)
            expected[list(action_permutation(k, flip, H, W))] = best
            assert np.array_equal(turned.action_set(0, moved_start, 0, 100), expected)
            assert turned.value(0, moved_start, 0, 100) == pytest.approx(value)


def test_augment_batch_moves_cells_and_columns_together() -> None:
    obs = torch.zeros(3, 2, 4, 4, dtype=torch.uint8)
    obs[:, 0, 0, 1] = 1  # an object at row 0, column 1
    sets = torch.tensor([[True, False, False, False]] * 3)  # "up"
    seen = set()
    for seed in range(40):
        out, moved = augment_batch(obs, sets, torch.Generator().manual_seed(seed))
        assert out.shape == obs.shape and moved.shape == sets.shape and moved.sum() == 3
        (r, c) = (int(x) for x in np.argwhere(out[0, 0].numpy())[0])
        seen.add(((r, c), int(moved[0].int().argmax())))
    assert len(seen) == 8  # all eight symmetries drawn, each a different (cell, action) pair
    # a non-square grid draws only mirrors and half turns
    wide = torch.zeros(2, 1, 3, 5)
    for seed in range(20):
        assert (
            augment_batch(wide, torch.eye(4)[:2], torch.Generator().manual_seed(seed))[0].shape
            == wide.shape
        )
