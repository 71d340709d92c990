"""Self-imitation (Oh et al. 2018, "Self-Imitation Learning"): replay the best episodes so far.

On Relational-Grid-World Configuration-2 a random policy reaches the terminal
in about 0.2 % of its episodes; plain A3C sees such an episode, nudges the
policy a little, and the lesson is washed out by the thousands of episodes
that end in a pit or a timeout. Self-imitation keeps the transitions of the
best episodes a worker has played and adds, at every update, the loss

    -log pi(a|s) * max(R - V(s), 0) + 0.5 * value_coef * max(R - V(s), 0)^2

on a sample of them, R being the discounted return that followed (a, s) in
that episode. Only transitions that did better than the critic expects
teach anything, so the term fades once the policy reproduces them.

Each worker keeps the ``capacity`` highest-return episodes it has finished
(equal returns: the shorter, then the newer one wins), so a better route (the
sword before the enemy, 10.7 instead of 8.9) displaces a worse one, and among
routes of equal return the direct ones displace those that dither. Only episodes with a positive
return are kept: imitating the "safe" episodes that merely avoided every
penalty (return 0) teaches the agent to stop exploring.
"""

from __future__ import annotations

import heapq
import itertools
from typing import NamedTuple

import numpy as np
import torch
import torch.nn.functional as F


class SILBatch(NamedTuple):
    obs: torch.Tensor  # (M, C, H, W) uint8
    actions: torch.Tensor  # (M,) int64
    returns: torch.Tensor  # (M,) float32


class EpisodeMemory:
    """The current episode of every sub-env, and the best finished episodes."""

    def __init__(self, n_envs: int, gamma: float, capacity: int = 32) -> None:
        self.gamma = gamma
        self.capacity = capacity
        self.current: list[list[tuple[np.ndarray, int, float]]] = [[] for _ in range(n_envs)]
        # min-heap of (key, obs, actions, returns-to-go); key = (return, -length, order)
        self.best: list[tuple[tuple[float, int, int], np.ndarray, np.ndarray, np.ndarray]] = []
        self.order = itertools.count()
        self._flat: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    def step(
        self,
        obs: np.ndarray,
        actions: np.ndarray,
        rewards: np.ndarray,
        valid: np.ndarray,
        done: np.ndarray,
    ) -> None:
        """One env step: obs the observations acted on, rewards the env's; done marks episode ends."""
        for i in np.flatnonzero(valid).tolist():
            self.current[i].append((obs[i], int(actions[i]), float(rewards[i])))
            if done[i]:
                self._finish(i)

    def _finish(self, i: int) -> None:
        steps, self.current[i] = self.current[i], []
        rewards = np.array([r for _, _, r in steps], dtype=np.float64)
        ret = round(float(rewards.sum()), 6)
        key = (ret, -len(steps), next(self.order))
        if ret <= 0 or len(self.best) >= self.capacity and key < self.best[0][0]:
            return
        returns = np.empty_like(rewards)
        g = 0.0
        for t in range(len(rewards) - 1, -1, -1):
            g = rewards[t] + self.gamma * g
            returns[t] = g
        entry = (
            key,
            np.stack([o for o, _, _ in steps]),
            np.array([a for _, a, _ in steps]),
            returns,
        )
        if len(self.best) >= self.capacity:
            heapq.heapreplace(self.best, entry)
        else:
            heapq.heappush(self.best, entry)
        self._flat = None

    def __len__(self) -> int:
        return sum(len(e[2]) for e in self.best)

    def sample(self, m: int, generator: torch.Generator | None = None) -> SILBatch | None:
        """m transitions drawn uniformly from the stored episodes (None while empty)."""
        if not self.best:
            return None
        if self._flat is None:
            self._flat = (
                np.concatenate([e[1] for e in self.best]),
                np.concatenate([e[2] for e in self.best]),
                np.concatenate([e[3] for e in self.best]).astype(np.float32),
            )
        obs, actions, returns = self._flat
        idx = torch.randint(0, len(actions), (m,), generator=generator).numpy()
        return SILBatch(
            torch.from_numpy(obs[idx]),
            torch.from_numpy(actions[idx]),
            torch.from_numpy(returns[idx]),
        )


def sil_loss(
    logits: torch.Tensor, values: torch.Tensor, batch: SILBatch, value_coef: float
) -> torch.Tensor:
    """Self-imitation loss summed over the batch, from the model's (M, A) logits and (M,) values on it.

    Only better-than-expected transitions (R > V) count.
    """
    logp_a = (
        F.log_softmax(logits, dim=-1).gather(-1, batch.actions.unsqueeze(-1)).squeeze(-1)
    )  # (M,)
    gap = (batch.returns - values).clamp(min=0.0)  # (M,)
    return -(logp_a * gap.detach()).sum() + 0.5 * value_coef * gap.pow(2).sum()
