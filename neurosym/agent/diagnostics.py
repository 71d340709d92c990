"""Does the network see its input, and where do the gradients go?

Two questions decide whether A3C can learn at all, and both are cheap to ask
of a fresh (or trained) model on a batch of observations:

* :func:`input_signal`: do the policy logits and the value vary across
  observations (their standard deviation over the batch), and is the
  attention anything but uniform (the largest weight against 1/N, the entropy
  against log N)? A network whose logits vary by 1e-8 cannot prefer one
  action in one state and another elsewhere, whatever the learner does.
* :func:`gradient_report`: the gradient norm of each layer under the actor's
  loss and under the critic's loss separately, on one rollout. When the
  critic's gradient on the shared layers is orders of magnitude above the
  actor's, the shared layers learn to predict value and nothing else.

* :func:`signal_after_ppo_updates`: the same figures after each of the first
  PPO updates. A fresh network that sees its input can stop seeing it in one
  update: PrediNet's scene queries are a 5,096-input layer on bw1, Adam moves
  each weight by about lr whatever its gradient's size, and the attention
  saturates on fixed cells (``fixed_cell_share`` near 1).

``experiments/diagnose.py`` prints both for every env family and module, for the
model switches and learner settings of a preset, so a change to either is
judged by these figures before and after.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import torch
import torch.nn.functional as F

from neurosym.agent.config import TrainConfig
from neurosym.agent.learners.optimizers import shared_optimizer
from neurosym.agent.learners.ppo import ppo_update
from neurosym.agent.learners.returns import AdvantageScale
from neurosym.agent.networks.model import ActorCritic
from neurosym.agent.rollout import RolloutState, collect_rollout


def random_observations(env: str, n: int, seed: int = 0, **env_kwargs: Any) -> np.ndarray:
    """(n, C, H, W) observations met by uniformly random actions: 16 envs, n / 16 steps each."""
    from neurosym.envs import make_batched

    k = min(16, n)
    venv = make_batched(env, k, seed=seed, **env_kwargs)
    obs, _ = venv.reset(seed=seed)
    rng = np.random.default_rng(seed)
    out = [obs.copy()]
    while sum(len(o) for o in out) < n:
        obs, *_ = venv.step(rng.integers(0, 4, size=k))
        out.append(obs.copy())
    venv.close()
    return np.concatenate(out)[:n]


@torch.no_grad()
def input_signal(model: ActorCritic, obs: np.ndarray) -> dict[str, Any]:
    """Spread of logits, value and attention over a batch of observations."""
    logits, value, intro = model(torch.from_numpy(obs), introspect=True)
    n = model.config.n_entities
    weights = (
        torch.stack([intro.attention1, intro.attention2])  # (2, B, H, N)
        if hasattr(intro, "attention1")
        else intro.attention  # (B, H, N, N)
    )
    p = weights.clamp_min(1e-30)
    entropy = -(p * p.log()).sum(-1)  # per query
    probs = torch.softmax(logits, dim=-1)
    report = {
        "logit_std": float(logits.std(dim=0).mean()),
        "value_std": float(value.std()),
        "policy_max_prob": float(probs.max(dim=-1).values.mean()),
        "attention_max": float(weights.max(dim=-1).values.mean()),
        "attention_uniform": 1.0 / n,
        "attention_entropy_ratio": float(entropy.mean() / math.log(n)),
    }
    if hasattr(intro, "attention1"):
        report["fixed_cell_share"] = fixed_cell_share(weights)
    return report


def fixed_cell_share(attention: torch.Tensor) -> list[float]:
    """Per PrediNet attention (both of every head): the share of observations whose most
    attended cell is that attention's most common one. 1.0 is attention by position (the
    same cell whatever the scene), about 1/B attention that follows the scene. Telling only
    when the attention is peaked (``attention_max`` well above 1/N): a near-uniform
    attention's argmax is decided by small position-dependent terms.

    ``attention``: (2, B, H, N), attention1 and attention2 stacked."""
    top = attention.argmax(dim=-1)  # (2, B, H)
    top = top.permute(0, 2, 1).reshape(-1, top.shape[1])  # (2H, B): a1 heads, then a2 heads
    return [float(torch.bincount(row).max()) / row.numel() for row in top]


def gradient_report(
    model: ActorCritic,
    obs: torch.Tensor,
    actions: torch.Tensor,
    returns: torch.Tensor,
    normalize_advantages: bool = False,
) -> dict[str, dict[str, float]]:
    """Per-parameter-group gradient norms of the actor's and the critic's loss, separately.

    ``obs`` (B, C, H, W), ``actions`` (B,), ``returns`` (B,) targets. The
    groups are the model's top-level parts (encoder, relational, body, policy,
    value); each reports ``actor``, ``critic`` and ``per_weight`` (the actor's
    mean absolute gradient per weight, the size an optimiser's epsilon meets).
    """
    logits, value = model(obs)
    advantages = (returns - value).detach()
    if normalize_advantages:
        advantages = (advantages - advantages.mean()) / (advantages.std() + 1e-8)
    logp = F.log_softmax(logits, dim=-1).gather(-1, actions.unsqueeze(-1)).squeeze(-1)
    losses = {
        "actor": -(logp * advantages).mean(),
        "critic": 0.5 * (returns - value).pow(2).mean(),
    }
    report: dict[str, dict[str, float]] = {}
    for name, loss in losses.items():
        grads = torch.autograd.grad(
            loss,
            list(model.parameters()),
            retain_graph=True,
            allow_unused=True,
            materialize_grads=True,
        )
        by_group: dict[str, list[torch.Tensor]] = {}
        for (pname, _), g in zip(model.named_parameters(), grads, strict=True):
            by_group.setdefault(pname.split(".")[0], []).append(g.flatten())
        for group, parts in by_group.items():
            flat = torch.cat(parts)
            entry = report.setdefault(group, {})
            entry[name] = float(flat.norm())
            if name == "actor":
                entry["per_weight"] = float(flat.abs().mean())
    return report


def signal_after_ppo_updates(
    model: ActorCritic,
    env: str,
    probe: np.ndarray,
    updates: int,
    seed: int = 0,
    envs: int = 16,
    n_steps: int = 32,
    **env_kwargs: Any,
) -> list[dict[str, Any]]:
    """:func:`input_signal` on ``probe`` after each of ``updates`` PPO updates of ``model`` (in
    place) on its own rollouts, with the family's PPO settings but ``envs`` x ``n_steps``
    rollouts and 2 passes (8 Adam steps per update)."""
    from neurosym.envs import env_family, make_batched

    train = TrainConfig.for_family(
        env_family(env), algo="ppo", envs=envs, n_steps=n_steps, ppo_epochs=2
    )
    optimizer = shared_optimizer(model.parameters(), train)
    state = RolloutState(make_batched(env, envs, seed=seed, **env_kwargs), seed)
    generator = torch.Generator().manual_seed(seed)
    scale = AdvantageScale()
    figures = []
    for _ in range(updates):
        rollout, _ = collect_rollout(model, state, n_steps, generator, None, record=True)
        ppo_update(model, optimizer, rollout, train, generator, scale)
        figures.append(input_signal(model, probe))
    return figures
