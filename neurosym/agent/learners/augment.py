"""The grid's symmetries as data augmentation: rotate or mirror an observation, permute its actions.

Why: an RGW level turned a quarter or mirrored is another level of the same
generator, with the same rules, whose optimal actions are the originals'
turned the same way (moves are the four unit steps; walls, teleports,
mountains, pits, sword and enemy do not care about direction). Imitating
the planner on rgw-random, the Table 4 PrediNet fits nearly all of its
labelled states and picks optimal actions far less often on levels it never
saw (``experiments/imitation_capacity.py``): it memorises levels instead of
learning the rule. Each of the eight turned or mirrored copies of a state is
a state it has not seen, for free.

The action permutation is computed, not written down: an agent plane with
the agent at a cell and at the cell one step away is transformed with the
observation, and the step between the two transformed positions names the
new action.
"""

from __future__ import annotations

import functools

import numpy as np
import torch

from neurosym.envs.rgw_rules import ACTION_DELTAS

TRANSFORMS = tuple((k, flip) for flip in (False, True) for k in range(4))
"""(quarter turns, mirrored) of the dihedral group, the identity first"""


def transform_grid(x: torch.Tensor, k: int, flip: bool) -> torch.Tensor:
    """(..., H, W) turned k quarter turns (torch.rot90 over the last two axes) after an optional mirror."""
    if flip:
        x = torch.flip(x, dims=(-1,))
    return torch.rot90(x, k, dims=(-2, -1)) if k % 4 else x


@functools.cache
def action_permutation(k: int, flip: bool, height: int, width: int) -> tuple[int, ...]:
    """``perm[a]``: the action that does in the transformed grid what ``a`` does in the original."""
    if k % 2 and height != width:
        raise ValueError(f"a quarter turn needs a square grid, got {height} x {width}")
    r, c = height // 2, width // 2  # a cell with every neighbour on the grid
    perm = []
    for dr, dc in ACTION_DELTAS:
        grid = torch.zeros(2, height, width)
        grid[0, r, c] = 1.0
        grid[1, r + dr, c + dc] = 1.0
        out = transform_grid(grid, k, flip)
        (r0, c0), (r1, c1) = (np.argwhere(out[i].numpy())[0] for i in (0, 1))
        step = (int(r1 - r0), int(c1 - c0))
        perm.append([tuple(d) for d in ACTION_DELTAS.tolist()].index(step))
    return tuple(perm)


def augment_batch(
    obs: torch.Tensor, actions: torch.Tensor, generator: torch.Generator | None = None
) -> tuple[torch.Tensor, torch.Tensor]:
    """One random symmetry per batch: obs (B, C, H, W), actions (B, A, ...) per-action values or masks.

    Returns the transformed observations and the per-action columns moved to
    their transformed actions. Non-square grids draw only from the
    symmetries that keep their shape (mirror and half turn).
    """
    height, width = obs.shape[-2:]
    choices = [t for t in TRANSFORMS if height == width or t[0] % 2 == 0]
    k, flip = choices[int(torch.randint(len(choices), (1,), generator=generator))]
    if (k, flip) == (0, False):
        return obs, actions
    perm = action_permutation(k, flip, height, width)
    moved = torch.empty_like(actions)
    moved[:, list(perm)] = actions
    return transform_grid(obs, k, flip).contiguous(), moved
