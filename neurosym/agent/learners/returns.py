"""Returns and advantages of a rollout, and how well a critic explains them.

Shapes are (T, K): T steps of K envs. ``next_values[t]`` is V(o_{t+1}); a
terminated step bootstraps from 0, a truncated one (time limit) from V of its
final observation::

    delta_t = r_t + gamma * (0 if terminated_t else V(o_{t+1})) - V(o_t)
    A_t = delta_t + gamma * lambda * (0 if the episode ended at t else A_{t+1})

With lambda = 1 the advantages are the bootstrapped n-step returns minus V.
"""

from __future__ import annotations

import torch


def n_step_returns(
    rewards: torch.Tensor,
    terminated: torch.Tensor,
    truncated: torch.Tensor,
    next_values: torch.Tensor,
    gamma: float,
) -> torch.Tensor:
    """(T, K) bootstrapped n-step returns G_t."""
    T = rewards.shape[0]
    returns = torch.empty_like(rewards)
    G = next_values[-1]  # (K,) V of the observation after the last step
    for t in range(T - 1, -1, -1):
        after = torch.where(truncated[t], next_values[t], G)
        G = rewards[t] + gamma * torch.where(terminated[t], 0.0, after)
        returns[t] = G
    return returns


def gae_advantages(
    rewards: torch.Tensor,
    values: torch.Tensor,
    terminated: torch.Tensor,
    truncated: torch.Tensor,
    next_values: torch.Tensor,
    gamma: float,
    lam: float,
) -> torch.Tensor:
    """(T, K) generalised advantage estimates; with ``lam = 1``, ``n_step_returns(...) - values``."""
    T = rewards.shape[0]
    advantages = torch.empty_like(rewards)
    A = torch.zeros_like(rewards[0])  # (K,) advantage after the rollout's last step
    for t in range(T - 1, -1, -1):
        bootstrap = torch.where(terminated[t], 0.0, next_values[t])
        delta = rewards[t] + gamma * bootstrap - values[t]
        ended = terminated[t] | truncated[t]
        A = delta + gamma * lam * torch.where(ended, 0.0, A)
        advantages[t] = A
    return advantages


def explained_variance(predicted: torch.Tensor, target: torch.Tensor) -> float:
    """How much of ``target``'s variance ``predicted`` explains (SB3's figure for a critic):
    1 - Var(target - predicted) / Var(target); NaN when the targets do not vary.
    """
    if target.numel() < 2:
        return float("nan")
    var = target.var()
    if var <= 0:
        return float("nan")
    return float(1.0 - (target - predicted).var() / var)


class AdvantageScale:
    """Divides advantages by a running root-mean-square of the advantages seen so far.

    Why not the usual per-batch normalisation (subtract the mean, divide by the
    std)? An A3C update sees one small rollout, and on sparse-reward levels
    most rollouts hold no reward at all: their advantages are the critic's
    small errors, and centring and scaling them per rollout turns that noise
    into full-sized policy steps with a random sign. A running RMS keeps each
    advantage's sign and the rollouts' relative sizes, and still keeps the
    actor's gradient independent of the rewards' scale.
    """

    def __init__(self, decay: float = 0.99) -> None:
        self.decay = decay
        self.mean_square: float | None = None

    def __call__(self, advantages: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
        n = float(mask.sum())
        if n > 0:
            batch = float((advantages.detach().pow(2) * mask).sum()) / n
            if self.mean_square is None:
                self.mean_square = batch
            else:
                self.mean_square = self.decay * self.mean_square + (1 - self.decay) * batch
        rms = (self.mean_square or 0.0) ** 0.5
        return advantages / (rms + 1e-8)
