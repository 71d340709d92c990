"""A3C: the actor-critic loss and update, and the worker process.

Each of W worker processes steps K environments (K = 1 is the classic
algorithm with one env per worker; the same batched env code runs it) for
``n_steps`` steps with a local copy of the shared model, then computes the
loss on that rollout and writes its gradients into the shared model, where the
shared optimiser (:mod:`neurosym.agent.learners.optimizers`) applies them
without locks (Hogwild). Workers run one torch thread each.

The workers act without keeping a graph; the update runs the model once over
the stacked rollout (T * K observations), which is several times faster than
backpropagating through T small batches. Loss per update, over the valid
transitions of the rollout (the autoreset steps of the batched env are masked
out), summed over time and averaged over the K envs so that the gradient
scale does not grow with K::

    delta_t = s r_t + gamma * (0 if terminated_t else V(o_{t+1})) - V(o_t)
    A_t = delta_t + gamma * lambda * (0 if the episode ended at t else A_{t+1})
    loss = -sum log pi(a_t|o_t) A_t / rms(A) + value_coef * sum 0.5 (A_t)^2
           - entropy * sum H(pi(.|o_t))

with s = ``reward_scale``, the value regressed on A_t + V(o_t) (so the
value loss is 0.5 A_t^2 with V(o_t) kept in the graph), V after the
rollout's last step bootstrapping the tail, and rms(A) the worker's running
root-mean-square of the advantages when ``normalize_advantages`` is on
(:class:`~neurosym.agent.learners.returns.AdvantageScale` says why not
the usual per-batch normalisation). With lambda = 1, s = 1 and no
normalisation this is Table 4's n-step A3C: A_t = G_t - V(o_t) with G_t the
bootstrapped n-step return.
Truncated episodes (time limit) bootstrap from V of their final observation.
With ``sil > 0`` (:class:`~neurosym.agent.config.A3CConfig`) the self-imitation loss (:mod:`neurosym.agent.learners.sil`)
on a batch of M remembered transitions is added, scaled to T transitions.
"""

from __future__ import annotations

import dataclasses
import os

import torch
import torch.nn.functional as F

from neurosym.agent.config import TrainConfig
from neurosym.agent.learners.exploration import CountBonus
from neurosym.agent.learners.messages import LossStats
from neurosym.agent.learners.process import (
    LearnerContext,
    check_finite,
    learner_process,
    report_update,
)
from neurosym.agent.learners.returns import AdvantageScale, gae_advantages
from neurosym.agent.learners.sil import EpisodeMemory, SILBatch, sil_loss
from neurosym.agent.networks.adapters import adapter_class
from neurosym.agent.networks.model import ActorCritic
from neurosym.agent.rollout import Rollout, RolloutState, collect_rollout


def a3c_loss(
    model: torch.nn.Module,
    rollout: Rollout,
    config: TrainConfig,
    sil_batch: SILBatch | None = None,
    scale: AdvantageScale | None = None,
) -> tuple[torch.Tensor, LossStats]:
    """The scalar loss of one rollout (plus self-imitation on ``sil_batch``) and its parts.

    With ``config.normalize_advantages`` the advantages are divided by
    ``scale``'s running RMS (a worker keeps one; without it, this rollout's RMS).

    The model runs once over what it has not seen with a graph: the rollout's
    T * K observations (unless acting kept their graph), the last observation
    of each env and the self-imitation batch.
    """
    T, K = rollout.actions.shape
    kept = rollout.logits is not None and rollout.logits.requires_grad
    parts = [] if kept else [rollout.obs.flatten(0, 1)]
    parts.append(rollout.last_obs)
    if sil_batch is not None:
        parts.append(sil_batch.obs)
    # acting's recorded queries are the first T * K rows' (same weights, same observations)
    reuse = {} if kept or rollout.queries is None else {"queries": rollout.queries}
    logits_all, values_all = model(torch.cat(parts), **reuse)  # ([T*K +] K [+ M], A), (.., )
    n = 0 if kept else T * K  # rows of the rollout itself in this pass
    if kept:
        logits, values = rollout.logits, rollout.values  # (T, K, A), (T, K)
    else:
        logits = logits_all[:n].view(T, K, -1)  # (T, K, A)
        values = values_all[:n].view(T, K)  # (T, K)
    next_values = torch.cat([values[1:], values_all[n : n + K].unsqueeze(0)]).detach()  # (T, K)
    advantages = gae_advantages(
        rollout.rewards * config.reward_scale,
        values.detach(),
        rollout.terminated,
        rollout.truncated,
        next_values,
        config.gamma,
        config.gae_lambda,
    )  # (T, K)
    returns = advantages + values.detach()  # (T, K) the value's targets
    mask = rollout.valid.to(torch.float32)  # (T, K)
    logp = F.log_softmax(logits, dim=-1)  # (T, K, A)
    logp_a = logp.gather(-1, rollout.actions.unsqueeze(-1)).squeeze(-1)  # (T, K)
    entropy = -(logp.exp() * logp).sum(-1)  # (T, K)
    if config.normalize_advantages:
        advantages = (scale or AdvantageScale())(advantages, mask)
    policy_loss = -(logp_a * advantages * mask).sum() / K
    value_loss = 0.5 * ((returns - values).pow(2) * mask).sum() / K
    entropy_sum = (entropy * mask).sum() / K
    loss = policy_loss + config.value_coef * value_loss - config.entropy * entropy_sum
    if sil_batch is not None:
        M = sil_batch.actions.shape[0]
        scaled = sil_batch._replace(returns=sil_batch.returns * config.reward_scale)
        sil = sil_loss(logits_all[n + K :], values_all[n + K :], scaled, config.value_coef)
        loss = loss + config.a3c.sil * sil * (T / M)
    numbers = torch.stack([policy_loss, value_loss, entropy_sum]).tolist()
    return loss, LossStats(numbers[0], numbers[1], numbers[2], grad_norm=0.0)


def apply_update(
    local: torch.nn.Module,
    shared: torch.nn.Module,
    optimizer: torch.optim.Optimizer,
    loss: torch.Tensor,
    clip: float,
) -> float:
    """Backpropagate on the local model, hand its gradients to the shared one, step; the gradient norm."""
    local.zero_grad(set_to_none=True)
    loss.backward()
    norm = torch.nn.utils.clip_grad_norm_(local.parameters(), clip)
    check_finite(norm, loss)  # a NaN step would reach every worker through the shared weights
    for shared_p, local_p in zip(shared.parameters(), local.parameters(), strict=True):
        shared_p.grad = local_p.grad
    optimizer.step()
    return float(norm)


def worker(ctx: LearnerContext) -> None:
    """One A3C worker: rollouts and updates of the shared model until ``ctx.stop`` is set."""
    torch.set_num_threads(1)
    with learner_process(ctx.queue, ctx.rank):
        from neurosym.envs import make_batched

        config, shared = ctx.train_config, ctx.shared
        torch.manual_seed(ctx.env_seed)
        generator = torch.Generator().manual_seed(ctx.env_seed)
        venv = make_batched(ctx.env_name, config.envs, seed=ctx.env_seed, **ctx.env_kwargs)
        local = ActorCritic(ctx.model_config)
        state = RolloutState(venv, ctx.env_seed)
        bonus = None
        if config.explore > 0:
            bonus = CountBonus(config.explore, half_life=config.explore_half_life)
        memory = None
        if config.a3c.sil > 0:
            memory = EpisodeMemory(config.envs, config.gamma, config.a3c.sil_episodes)
        # the module's adapter says from how many envs keeping each acting step's graph beats
        # a second forward over the rollout (MHDPA: 8; never for PrediNet)
        from_envs = adapter_class(ctx.model_config.module).keep_graph_envs
        keep_graph = from_envs is not None and config.envs >= from_envs
        scale = AdvantageScale()
        parent = os.getppid()
        while not ctx.stop.is_set() and os.getppid() == parent:  # also stop if the parent died
            local.load_state_dict(shared.state_dict())
            rollout, finished = collect_rollout(
                local, state, config.n_steps, generator, bonus, memory, keep_graph
            )
            batch = memory.sample(config.n_steps, generator) if memory is not None else None
            loss, stats = a3c_loss(local, rollout, config, batch, scale)
            norm = apply_update(local, shared, ctx.optimizer, loss, config.grad_clip)
            frames = int(rollout.valid.sum())
            report_update(ctx, frames, finished, dataclasses.replace(stats, grad_norm=norm))
