"""PPO: the synchronous learner beside A3C (``neurosym train --algo ppo``).

One learner process steps ``envs`` batched environments for ``n_steps``
steps with the current weights (the same :func:`collect_rollout` as the A3C
workers, recording the behaviour policy's logits and values), computes GAE
advantages (the same :func:`gae_advantages`), then makes ``ppo_epochs``
passes over the rollout's valid transitions in ``ppo_minibatches`` shuffled
minibatches, each a clipped-surrogate step (Schulman et al. 2017)::

    ratio = pi(a|o) / pi_old(a|o)
    loss  = -mean(min(ratio A, clip(ratio, 1 - eps, 1 + eps) A))
            + value_coef * mean(0.5 (V(o) - (A_old + V_old(o)))^2) - entropy * mean(H)

with A normalised per minibatch when ``normalize_advantages``. It writes
straight into the trainer's shared model with the trainer's optimiser and
reports to the trainer through the same queue messages as an A3C worker, so
evaluation, metrics, checkpoints, resume and stopping are one code path for
both learners. It uses all the torch threads the machine has: one process
does all the work.
"""

from __future__ import annotations

import os
import signal
import traceback
from typing import Any

import torch
import torch.nn.functional as F

from neurosym.agent.a3c import LossStats, gae_advantages
from neurosym.agent.config import ModelConfig, TrainConfig
from neurosym.agent.exploration import CountBonus
from neurosym.agent.model import ActorCritic
from neurosym.agent.rollout import Rollout, RolloutState, collect_rollout


def ppo_update(
    model: ActorCritic,
    optimizer: torch.optim.Optimizer,
    rollout: Rollout,
    config: TrainConfig,
    generator: torch.Generator,
) -> LossStats:
    """Epochs of clipped-surrogate minibatch steps on one rollout; the mean loss parts."""
    assert rollout.logits is not None and rollout.values is not None, "record the rollout"
    with torch.no_grad():
        _, last_value = model(rollout.last_obs)  # (K,)
    values = rollout.values  # (T, K)
    next_values = torch.cat([values[1:], last_value.unsqueeze(0)])  # (T, K)
    advantages = gae_advantages(
        rollout.rewards * config.reward_scale,
        values,
        rollout.terminated,
        rollout.truncated,
        next_values,
        config.gamma,
        config.gae_lambda,
    )  # (T, K)
    valid = rollout.valid.flatten()  # (T * K,)
    b_obs = rollout.obs.flatten(0, 1)[valid]  # (M, C, H, W)
    b_actions = rollout.actions.flatten()[valid]  # (M,)
    b_logp = F.log_softmax(rollout.logits, dim=-1).flatten(0, 1)[valid]  # (M, A)
    b_logp = b_logp.gather(-1, b_actions.unsqueeze(-1)).squeeze(-1)  # (M,)
    b_adv = advantages.flatten()[valid]  # (M,)
    b_returns = b_adv + values.flatten()[valid]  # (M,)
    M = b_obs.shape[0]
    size = max(1, M // config.ppo_minibatches)
    totals = torch.zeros(4)
    steps = 0
    for _ in range(config.ppo_epochs):
        order = torch.randperm(M, generator=generator)
        for start in range(0, M - size + 1, size):
            mb = order[start : start + size]
            logits, value = model(b_obs[mb])  # (m, A), (m,)
            logp_all = F.log_softmax(logits, dim=-1)
            logp = logp_all.gather(-1, b_actions[mb].unsqueeze(-1)).squeeze(-1)
            entropy = -(logp_all.exp() * logp_all).sum(-1).mean()
            adv = b_adv[mb]
            if config.normalize_advantages and adv.numel() > 1:
                adv = (adv - adv.mean()) / (adv.std() + 1e-8)
            ratio = (logp - b_logp[mb]).exp()
            clipped = ratio.clamp(1.0 - config.clip_range, 1.0 + config.clip_range)
            policy_loss = -torch.min(ratio * adv, clipped * adv).mean()
            value_loss = 0.5 * (value - b_returns[mb]).pow(2).mean()
            loss = policy_loss + config.value_coef * value_loss - config.entropy * entropy
            optimizer.zero_grad(set_to_none=True)
            loss.backward()
            norm = torch.nn.utils.clip_grad_norm_(model.parameters(), config.grad_clip)
            optimizer.step()
            totals += torch.stack(
                [policy_loss.detach(), value_loss.detach(), entropy.detach(), norm.detach()]
            )
            steps += 1
    mean = (totals / max(steps, 1)).tolist()
    return LossStats(*mean)


def ppo_learner(
    rank: int,
    shared: ActorCritic,
    optimizer: torch.optim.Optimizer,
    model_config: ModelConfig,
    train_config: TrainConfig,
    env_name: str,
    env_kwargs: dict[str, Any],
    env_seed: int,
    stop: Any,
    queue: Any,
) -> None:
    """The PPO learner process: rollouts and updates on ``shared`` until ``stop`` is set.

    Same signature and messages as :func:`neurosym.agent.a3c.worker`.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    torch.set_num_threads(max(1, len(os.sched_getaffinity(0))))
    try:
        from neurosym.envs import make_batched

        torch.manual_seed(env_seed)
        generator = torch.Generator().manual_seed(env_seed)
        venv = make_batched(env_name, train_config.envs, seed=env_seed, **env_kwargs)
        state = RolloutState(venv, env_seed)
        bonus = None
        if train_config.explore > 0:
            bonus = CountBonus(train_config.explore, half_life=train_config.explore_half_life)
        parent = os.getppid()
        while not stop.is_set() and os.getppid() == parent:
            rollout, finished = collect_rollout(
                shared, state, train_config.n_steps, generator, bonus, record=True
            )
            stats = ppo_update(shared, optimizer, rollout, train_config, generator)
            queue.put(
                (
                    "update",
                    rank,
                    int(rollout.valid.sum()),
                    finished.returns,
                    finished.lengths,
                    finished.outcomes,
                    tuple(stats),
                )
            )
    except BaseException:  # noqa: BLE001 - reported to the parent, which raises it
        queue.put(("error", rank, traceback.format_exc()))
