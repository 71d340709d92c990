"""Count-based exploration bonus: intrinsic reward beta / sqrt(n(s)) for reaching observation s.

Relational-Grid-World's Configuration-2 hides its +10 behind a teleport
reached only across a mountain, next to two pits: a uniformly random policy
reaches the terminal in about 0.2 % of its 100-step episodes, and plain A3C
learns to avoid the penalties (mountains, pits) long before it has seen enough
of the rare successes. A visit-count bonus (Bellemare et al. 2016; Tang et al.
2017, "#Exploration", which hashes observations) pays for reaching rarely seen
observations and decays as they become familiar, so the final policy is driven
by the environment's reward alone.

Observations are hashed by their raw bytes (a random multiplicative hash of
the 64-bit words, mod 2^64) into a table of 2^22 counters; each worker keeps
its own. Collisions are rare at the few thousand observations of a fixed map. The bonus only enters the
training loss; every reported return is the environment's.
"""

from __future__ import annotations

import numpy as np


class CountBonus:
    """Per-worker visit counts of hashed observations and the resulting bonus."""

    def __init__(self, beta: float, seed: int = 0, table_bits: int = 22) -> None:
        self.beta = float(beta)
        self.seed = seed
        self.mult: np.ndarray | None = (
            None  # odd random multipliers, one per 64-bit word of an observation
        )
        self.shift = np.uint64(64 - table_bits)
        self.counts = np.zeros(2**table_bits, dtype=np.int64)

    def __call__(self, obs: np.ndarray, valid: np.ndarray) -> np.ndarray:
        """(K,) float32 bonus for the observations reached this step; counts the valid ones."""
        flat = np.ascontiguousarray(obs).reshape(obs.shape[0], -1).view(np.uint8)  # (K, bytes)
        pad = -flat.shape[1] % 8
        if pad:
            flat = np.pad(flat, ((0, 0), (0, pad)))
        words = flat.view(np.uint64)  # (K, words)
        if self.mult is None:
            rng = np.random.default_rng(self.seed)
            self.mult = rng.integers(1, 2**63, size=words.shape[1], dtype=np.uint64) | np.uint64(1)
        h = (words * self.mult).sum(axis=1, dtype=np.uint64)  # (K,) wraps mod 2^64
        idx = (h >> self.shift).astype(np.int64)
        np.add.at(self.counts, idx[valid], 1)
        bonus = self.beta / np.sqrt(np.maximum(self.counts[idx], 1))
        return np.where(valid, bonus, 0.0).astype(np.float32)
