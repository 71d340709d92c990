"""PPO: the synchronous learner beside A3C (``neurosym train --algo ppo``).

One learner process steps ``envs`` batched environments for ``n_steps``
steps with the current weights (the same :func:`collect_rollout` as the A3C
workers, recording the behaviour policy's logits and values), computes GAE
advantages (the same :func:`gae_advantages`), then makes ``ppo_epochs``
passes over the rollout's valid transitions in ``ppo_minibatches`` shuffled
minibatches (exactly that many, so that every rank of a distributed run
takes the same number of steps), each a clipped-surrogate step (Schulman et
al. 2017)::

    ratio = pi(a|o) / pi_old(a|o)
    loss  = -mean(min(ratio A, clip(ratio, 1 - eps, 1 + eps) A))
            + value_coef * mean(0.5 (V(o) - (A_old + V_old(o)))^2) - entropy * mean(H)

with A normalised when ``normalize_advantages``: per minibatch (``ppo_advantages``
"minibatch", as SB3 and CleanRL do) or per rollout by a running RMS kept across
updates ("running", :class:`~neurosym.agent.learners.returns.AdvantageScale`). It writes
straight into the trainer's shared model with the trainer's optimiser and
reports to the trainer through the same queue messages as an A3C worker, so
evaluation, metrics, checkpoints, resume and stopping are one code path for
both learners. It uses all the torch threads the machine has (its share of
them under torchrun): one process does all the work.

The learner trains a private copy of the model on its device (``--device``)
with its own optimiser, and after every update copies the weights and the
optimiser's statistics into the trainer's shared ones, which the trainer
evaluates and checkpoints: one code path for the CPU and a GPU. Under
torchrun the copy is wrapped in ``DistributedDataParallel`` and the learners
of all ranks form the process group (:mod:`neurosym.agent.learners.distributed`).
"""

from __future__ import annotations

import os
from typing import NamedTuple

import torch
import torch.nn.functional as F

from neurosym.agent.config import TrainConfig
from neurosym.agent.learners import distributed
from neurosym.agent.learners.exploration import CountBonus
from neurosym.agent.learners.messages import LossStats, Stopped
from neurosym.agent.learners.optimizers import copy_into_shared, private_copy
from neurosym.agent.learners.process import (
    LearnerContext,
    check_finite,
    learner_process,
    report_update,
)
from neurosym.agent.learners.returns import AdvantageScale, explained_variance, gae_advantages
from neurosym.agent.rollout import Finished, Rollout, RolloutState, collect_rollout


class _Batch(NamedTuple):
    """A rollout's valid transitions, flattened: M of them (``b_*`` as in CleanRL)."""

    obs: torch.Tensor  # (M, C, H, W)
    actions: torch.Tensor  # (M,)
    logp: torch.Tensor  # (M,) the acting policy's log-probability of each action
    advantages: torch.Tensor  # (M,)
    returns: torch.Tensor  # (M,) the value's targets


def _flatten(
    core: torch.nn.Module, rollout: Rollout, config: TrainConfig, device: torch.device
) -> tuple[_Batch, torch.Tensor]:
    """The rollout's valid transitions with their GAE advantages; also the acting values (M,)."""
    assert rollout.logits is not None and rollout.values is not None, "record the rollout"
    with torch.no_grad():
        _, last_value = core(rollout.last_obs.to(device))  # (K,)
    values = rollout.values.to(device)  # (T, K)
    next_values = torch.cat([values[1:], last_value.unsqueeze(0)])  # (T, K)
    advantages = gae_advantages(
        rollout.rewards.to(device) * config.reward_scale,
        values,
        rollout.terminated.to(device),
        rollout.truncated.to(device),
        next_values,
        config.gamma,
        config.gae_lambda,
    )  # (T, K)
    valid = rollout.valid.flatten().to(device)  # (T * K,)
    b_obs = rollout.obs.to(device).flatten(0, 1)[valid]  # (M, C, H, W)
    b_actions = rollout.actions.to(device).flatten()[valid]  # (M,)
    b_logp = F.log_softmax(rollout.logits.to(device), dim=-1).flatten(0, 1)[valid]  # (M, A)
    b_logp = b_logp.gather(-1, b_actions.unsqueeze(-1)).squeeze(-1)  # (M,)
    b_adv = advantages.flatten()[valid]  # (M,)
    b_values = values.flatten()[valid]  # (M,)
    return _Batch(b_obs, b_actions, b_logp, b_adv, b_adv + b_values), b_values


def ppo_update(
    model: torch.nn.Module,
    optimizer: torch.optim.Optimizer,
    rollout: Rollout,
    config: TrainConfig,
    generator: torch.Generator,
    scale: AdvantageScale | None = None,
) -> LossStats:
    """Epochs of clipped-surrogate minibatch steps on one rollout; the mean loss parts.

    ``model`` may be wrapped in DistributedDataParallel; the rollout's CPU
    tensors are moved to the model's device. ``scale``: the learner's running
    RMS for ``ppo_advantages == "running"`` (a fresh one if None).
    """
    core = getattr(model, "module", model)
    device = next(core.parameters()).device
    batch, b_values = _flatten(core, rollout, config, device)
    explained = explained_variance(b_values, batch.returns)
    if config.normalize_advantages and config.ppo.ppo_advantages == "running":
        scale = scale if scale is not None else AdvantageScale()
        # the returns keep the raw advantages
        batch = batch._replace(
            advantages=scale(batch.advantages, torch.ones_like(batch.advantages))
        )
    M = batch.obs.shape[0]
    totals = torch.zeros(6)
    steps = 0
    for _ in range(config.ppo.ppo_epochs):
        order = torch.randperm(M, generator=generator).to(device)
        for mb in order.tensor_split(config.ppo.ppo_minibatches):
            # an empty minibatch (fewer transitions than minibatches) still takes its step with
            # weight 0, so that every rank of a distributed run makes the same collectives
            weight = 1.0 if mb.numel() else 0.0
            totals += _minibatch_step(model, optimizer, batch, mb if mb.numel() else order[:1],
                                      weight, config)  # fmt: skip
            steps += 1
    mean = (totals / max(steps, 1)).tolist()
    return LossStats(*mean, explained_variance=explained)


def _minibatch_step(
    model: torch.nn.Module,
    optimizer: torch.optim.Optimizer,
    batch: _Batch,
    mb: torch.Tensor,
    weight: float,
    config: TrainConfig,
) -> torch.Tensor:
    """One clipped-surrogate step on minibatch ``mb``; its (6,) loss parts on the CPU."""
    clip = config.ppo.clip_range
    logits, value = model(batch.obs[mb])  # (m, A), (m,)
    logp_all = F.log_softmax(logits, dim=-1)
    logp = logp_all.gather(-1, batch.actions[mb].unsqueeze(-1)).squeeze(-1)
    entropy = -(logp_all.exp() * logp_all).sum(-1).mean()
    adv = batch.advantages[mb]
    per_minibatch = config.normalize_advantages and config.ppo.ppo_advantages == "minibatch"
    if per_minibatch and adv.numel() > 1:
        adv = (adv - adv.mean()) / (adv.std() + 1e-8)
    log_ratio = logp - batch.logp[mb]
    ratio = log_ratio.exp()
    clipped = ratio.clamp(1.0 - clip, 1.0 + clip)
    policy_loss = -torch.min(ratio * adv, clipped * adv).mean()
    value_loss = 0.5 * (value - batch.returns[mb]).pow(2).mean()
    loss = policy_loss + config.value_coef * value_loss - config.entropy * entropy
    optimizer.zero_grad(set_to_none=True)
    (loss * weight).backward()
    norm = torch.nn.utils.clip_grad_norm_(model.parameters(), config.grad_clip)
    check_finite(norm, loss)  # the same on every rank: DDP averaged the gradients
    optimizer.step()
    with torch.no_grad():
        # Schulman's low-variance estimator of KL(old || new), as SB3 and CleanRL log it
        approx_kl = ((ratio - 1.0) - log_ratio).mean()
        clip_fraction = ((ratio - 1.0).abs() > clip).float().mean()
    parts = [policy_loss.detach(), value_loss.detach(), entropy.detach(), norm.detach()]
    return torch.stack([*parts, approx_kl, clip_fraction]).cpu()


def ppo_learner(ctx: LearnerContext) -> None:
    """The PPO learner process: rollouts and updates until ``ctx.stop`` is set (here or on any rank).

    Ends with a :class:`~neurosym.agent.learners.messages.Stopped` carrying
    every rank's parameter digest (rank 0; identical when the ranks agree).
    Under torchrun only rank 0 reports updates, with the frames and episodes
    of every rank.
    """
    world = distributed.world_from_env()
    threads = len(os.sched_getaffinity(0)) // max(world.local_size, 1)
    torch.set_num_threads(max(1, threads))
    with learner_process(ctx.queue, ctx.rank, cleanup=distributed.leave_group):
        from neurosym.envs import make_batched

        config = ctx.train_config
        dev = distributed.learner_device(ctx.device, world)
        torch.manual_seed(ctx.env_seed)
        generator = torch.Generator().manual_seed(ctx.env_seed)
        local, local_opt = private_copy(ctx.shared, ctx.optimizer, config, dev)
        model: torch.nn.Module = local
        if world.distributed:
            model = _join_group(ctx, local, local_opt, dev)
        venv = make_batched(ctx.env_name, config.envs, seed=ctx.env_seed, **ctx.env_kwargs)
        state = RolloutState(venv, ctx.env_seed)
        scale = AdvantageScale()  # used when ppo_advantages is "running"
        bonus = None
        if config.explore > 0:
            bonus = CountBonus(config.explore, half_life=config.explore_half_life)
        parent = os.getppid()
        while True:
            halt = ctx.stop.is_set() or os.getppid() != parent
            if world.distributed:
                halt = distributed.any_rank(halt, dev)
            if halt:
                break
            rollout, finished = collect_rollout(
                local, state, config.n_steps, generator, bonus, record=True, device=dev
            )
            stats = ppo_update(model, local_opt, rollout, config, generator, scale)
            copy_into_shared(local, local_opt, ctx.shared, ctx.optimizer)
            frames = int(rollout.valid.sum())
            if world.distributed:
                gathered = _gather_episodes(frames, finished)
                if gathered is None:
                    continue
                frames, finished = gathered
            report_update(ctx, frames, finished, stats)
        digests = [distributed.parameter_digest(local)]
        if world.distributed:
            digests = distributed.gather_to_leader(digests[0]) or digests
        ctx.queue.put(Stopped(ctx.rank, tuple(digests)))


def _join_group(
    ctx: LearnerContext,
    local: torch.nn.Module,
    local_opt: torch.optim.Optimizer,
    dev: torch.device,
) -> torch.nn.Module:
    """Join the torchrun process group; the DDP-wrapped model, started from rank 0's weights."""
    from torch.nn.parallel import DistributedDataParallel

    distributed.init_group(dev)
    distributed.check_same_config(ctx.model_config, ctx.train_config, ctx.env_name, ctx.env_kwargs)
    # DDP starts every rank from rank 0's weights; the statistics follow
    model = DistributedDataParallel(local, device_ids=[dev.index] if dev.type == "cuda" else None)
    distributed.broadcast_optimizer_state(local_opt)
    copy_into_shared(local, local_opt, ctx.shared, ctx.optimizer)
    return model


def _gather_episodes(frames: int, finished: Finished) -> tuple[int, Finished] | None:
    """Every rank's frames and finished episodes, on rank 0 (None on the others)."""
    every = distributed.gather_to_leader(
        (frames, finished.returns, finished.lengths, finished.outcomes)
    )
    if every is None:
        return None
    total = Finished.empty()
    for _, returns, lengths, outcomes in every:
        total.extend(Finished(returns, lengths, outcomes))
    return sum(e[0] for e in every), total
