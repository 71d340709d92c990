"""Count-based exploration bonus for A3C on maps where random play almost never scores.

Relational-Grid-World's Configuration-2 hides its +10 behind a teleport
reached only across a mountain, next to two pits: a uniformly random policy
reaches the terminal in about 0.2 % of its 100-step episodes, and plain A3C
learns to avoid the penalties (mountains, pits) long before it has seen enough
of the rare successes.

The bonus is ``beta / sqrt(n(s))`` for reaching observation ``s``, where n
counts every visit to ``s`` in this worker so far (Bellemare et al. 2016;
Tang et al. 2017, who hash observations), paid only the first time ``s`` is
reached within an episode (the episodic restriction of NGU, Badia et al.
2020, and NovelD, Zhang et al. 2021). The episodic part makes walking into
unseen ground pay and walking back not, which turns random dithering into
sweeping; the global count makes the bonus fade on ground that has become
familiar, so the final policy is driven by the environment's reward alone.

Observations are hashed by their raw bytes into a table of 2^22 counters
(collisions are rare at the few thousand observations of a fixed map); each
worker keeps its own. With ``half_life`` the counts decay (lazily, per slot),
so ground the agent has stopped visiting becomes novel again: once A3C has
settled on a route, a better one it has not tried lately (the sword) pays.
The bonus only enters the training loss; every reported return is the
environment's.
"""

from __future__ import annotations

import numpy as np


class CountBonus:
    """Per-worker visit counts of hashed observations, and the bonus for each step."""

    def __init__(
        self,
        beta: float,
        half_life: float | None = None,
        episodic: bool = True,
        table_bits: int = 22,
    ) -> None:
        self.beta = float(beta)
        self.half_life = half_life
        self.episodic = episodic
        self.mask = (1 << table_bits) - 1
        self.counts = np.zeros(1 << table_bits, dtype=np.float64)
        self.stamp = np.zeros(1 << table_bits, dtype=np.int64)  # step of each slot's last update
        self.t = 0  # steps so far: the clock of the decay
        self.seen: list[set[int]] = []  # per sub-env: slots reached in the current episode

    def _slots(self, obs: np.ndarray) -> np.ndarray:
        """(K,) table slot of each observation: Python's hash of its raw bytes, masked."""
        rows = np.ascontiguousarray(obs).reshape(obs.shape[0], -1)
        return np.fromiter(
            (hash(row.tobytes()) & self.mask for row in rows), dtype=np.int64, count=len(rows)
        )

    def __call__(self, obs: np.ndarray, valid: np.ndarray) -> np.ndarray:
        """(K,) float32 bonus for the observations reached this step.

        ``valid[i]`` False marks sub-env i's autoreset step: ``obs[i]`` is the
        first observation of a new episode, which starts a new episodic set.
        """
        idx = self._slots(obs)
        self.t += 1
        if self.half_life is not None:
            keys = np.unique(idx)
            self.counts[keys] *= 0.5 ** ((self.t - self.stamp[keys]) / self.half_life)
            self.stamp[keys] = self.t
        np.add.at(self.counts, idx[valid], 1.0)
        bonus = np.where(valid, self.beta / np.sqrt(np.maximum(self.counts[idx], 1.0)), 0.0)
        if self.episodic:
            if len(self.seen) != len(idx):
                self.seen = [set() for _ in idx]
            for i, key in enumerate(idx.tolist()):
                seen = self.seen[i]
                if not valid[i]:
                    seen.clear()
                    seen.add(key)
                elif key in seen:
                    bonus[i] = 0.0
                else:
                    seen.add(key)
        return bonus.astype(np.float32)
