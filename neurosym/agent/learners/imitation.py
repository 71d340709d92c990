"""Imitation of the env's optimal planner (DAgger): ``neurosym train --algo imitate``.

Why: on rgw-random neither RL learner gets far beyond uniformly random
success (docs/results.md). The levels carry an exact planner (:class:`rgw_solver.Plan`,
the search that gives each level its optimal return), so the network can be
taught what to do and has to find, from the pixels, what the planner reads
from the state: where the sword, the enemy, the door and the terminal are and
what stands between them.

DAgger (Ross et al., 2011): the learner's own sampled actions drive the
episodes (with the planner's action instead, per step and sub-env, with a
probability that falls linearly from 1 to 0 over ``dagger_beta_frames``),
every visited state is labelled with the planner's optimal actions, and the
network is fitted on a buffer of the latest labelled states. Labels are the
*set* of optimal actions (:meth:`Plan.action_set`); the loss is
``-log sum_{a optimal} p(a)``, so equal routes are not told apart by an
arbitrary tie-break. With ``safe_coef`` C > 0 the loss adds
``C * -log sum_{a safe} p(a)``, the set of every action that gives no return
up (the planner's regret 0): it weighs only the states where an episode can
miss its optimum, which the fastest-route loss weighs like any other. The
critic is fitted to the planner's best return still to earn (times
``reward_scale``), so that a later RL run can start from it.

With ``attend_coef`` C > 0 (RGW and Box-World, PrediNet) the loss adds ``C * -log a(target)``:
PrediNet head 0's second attention on the cell of the next key object on the
planner's route (:meth:`Planner.next_contacts`; Box-World's fewest-boxes route,
:class:`boxworld_solver.RouteTargets`, whose first attention is also taught the held key
when that object is the lock it opens). Under the fact bottleneck
(``ModelConfig.relation_bits``) the policy sees only what the heads attend and
the bits between them, so this names its current goal in its own facts
(``attends/8`` of head 0, argument 2), as a concept-bottleneck model is taught
its concepts; without the term the heads attend what serves the actions, which
a reader of the KB cannot name.

With ``teacher`` (:mod:`neurosym.agent.learners.teacher`) a trained agent labels the
states instead: its action probabilities (the loss is the KL from them) and its value; its
sampled actions are the expert's. Any family, Box-World too.

Started and reporting as every learner (:mod:`neurosym.agent.learners.process`);
one process, no torchrun. The planners: RGW's (:mod:`neurosym.envs.rgw_solver`) and
Minigrid DoorKey's (:mod:`neurosym.envs.minigrid_solver`); Box-World has none here (a
teacher labels it; its route search gives only the attention targets).
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np
import torch

from neurosym.agent.config import TrainConfig
from neurosym.agent.learners import distributed
from neurosym.agent.learners.augment import augment_batch
from neurosym.agent.learners.messages import LossStats, Stopped
from neurosym.agent.learners.optimizers import copy_into_shared, private_copy
from neurosym.agent.learners.planner_loss import optimal_set_nll
from neurosym.agent.learners.process import (
    LearnerContext,
    check_finite,
    learner_process,
    report_update,
)
from neurosym.agent.learners.teacher import Teacher, load_teacher
from neurosym.agent.networks.hooks import cache
from neurosym.agent.networks.model import ActorCritic
from neurosym.agent.rollout import EpisodeTracker, Finished, select_actions


class LabelBuffer:
    """A ring of the latest labelled states: observations, action targets (the planner's
    optimal set as 1s and 0s, or a teacher's probabilities), safe action sets, values."""

    def __init__(
        self, capacity: int, obs_shape: tuple[int, ...], obs_dtype: np.dtype, n_actions: int = 4
    ) -> None:
        self.obs = np.zeros((capacity, *obs_shape), dtype=obs_dtype)
        self.policy = np.zeros((capacity, n_actions), dtype=np.float32)
        self.safe = np.ones((capacity, n_actions), dtype=bool)
        self.values = np.zeros(capacity, dtype=np.float32)
        self.targets = np.full((capacity, 2), -1, dtype=np.int16)  # head 0's cells, -1 none
        self.size = 0
        self._next = 0

    def add(
        self,
        obs: np.ndarray,
        policy: np.ndarray,
        values: np.ndarray,
        safe: np.ndarray | None = None,
        targets: np.ndarray | None = None,
    ) -> None:
        """Append states; ``policy`` (n, A): an optimal set (bool) or probabilities; ``safe``
        (n, A) bool: actions that give no return up (default: all); ``targets`` (n, 2) the
        cells head 0's two arguments are taught (``attention_targets``; default: -1, none)."""
        if safe is None:
            safe = np.ones(policy.shape, dtype=bool)
        if targets is None:
            targets = np.full((len(obs), 2), -1, dtype=np.int16)
        for start in range(0, len(obs), len(self.obs)):  # a batch larger than the ring wraps
            o, m, v, s, g = (
                x[start : start + len(self.obs)] for x in (obs, policy, values, safe, targets)
            )
            idx = (self._next + np.arange(len(o))) % len(self.obs)
            self.obs[idx], self.policy[idx], self.values[idx], self.safe[idx] = o, m, v, s
            self.targets[idx] = g
            self._next = int((self._next + len(o)) % len(self.obs))
            self.size = min(self.size + len(o), len(self.obs))

    def sample(
        self, n: int, rng: np.random.Generator
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor, torch.Tensor, torch.Tensor]:
        """``n`` states drawn uniformly: obs, action targets, values, safe sets, target cells."""
        idx = rng.integers(0, self.size, n)
        return (
            torch.from_numpy(self.obs[idx]),
            torch.from_numpy(self.policy[idx]),
            torch.from_numpy(self.values[idx]),
            torch.from_numpy(self.safe[idx]),
            torch.from_numpy(self.targets[idx].astype(np.int64)),
        )


def imitation_loss(logits: torch.Tensor, optimal: torch.Tensor) -> torch.Tensor:
    """Mean of ``-log sum_{a in optimal} softmax(logits)_a`` over the batch; (B, A) and (B, A) bool."""
    return optimal_set_nll(logits, optimal).mean()


def distill_loss(logits: torch.Tensor, probs: torch.Tensor) -> torch.Tensor:
    """Mean KL(probs || softmax(logits)) over the batch: the teacher's probabilities (B, A)."""
    logq = torch.log(probs.clamp_min(1e-8))
    return (probs * (logq - torch.log_softmax(logits, dim=-1))).sum(-1).mean()


def planner_choice(optimal: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """(n,) one of each row's optimal actions (an (n, A) bool set), drawn uniformly."""
    return (rng.random(optimal.shape) * optimal).argmax(axis=1)


def expert_share(frames: int, beta_frames: int) -> float:
    """DAgger's beta: the chance that a step follows the planner, 1 at the start, 0 after ``beta_frames``."""
    if beta_frames <= 0:
        return 0.0
    return max(0.0, 1.0 - frames / beta_frames)


def attention_target_nll(logits: torch.Tensor, targets: torch.Tensor) -> torch.Tensor:
    """Mean of ``-log softmax(logits)[b, targets[b]]`` over the rows with a target; (B, N)
    attention scores, (B,) long with -1 for none (0 when no row has one)."""
    has = targets >= 0
    if not has.any():
        return logits.sum() * 0.0
    logp = torch.log_softmax(logits[has], dim=-1)
    return -logp.gather(1, targets[has, None]).mean()


def augment_with_targets(
    obs: torch.Tensor, sets: torch.Tensor, targets: torch.Tensor, generator: torch.Generator | None
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """:func:`augment_batch` that moves each row's target cells ((B, K), -1: none) with its
    level: each column rides along as one more observation plane."""
    B, C, H, W = obs.shape
    K = targets.shape[1]
    planes = torch.zeros(B, K, H * W, dtype=obs.dtype)
    rows, cols = (targets >= 0).nonzero(as_tuple=True)
    planes[rows, cols, targets[rows, cols]] = 1
    turned, sets = augment_batch(torch.cat([obs, planes.view(B, K, H, W)], dim=1), sets, generator)
    flat = turned[:, C:].reshape(B, K, -1)
    return turned[:, :C].contiguous(), sets, torch.where(targets >= 0, flat.argmax(-1), -1)


def imitation_update(
    model: ActorCritic,
    optimizer: torch.optim.Optimizer,
    buffer: LabelBuffer,
    config: TrainConfig,
    rng: np.random.Generator,
    device: torch.device,
    generator: torch.Generator | None = None,
) -> LossStats:
    """``dagger_steps`` minibatches of ``dagger_batch`` labelled states from the buffer."""
    totals = np.zeros(4)
    # the attention target's loss reads the scores the forward computed (the hook point)
    names = ["scores"] if config.imitate.attend_coef else []
    with cache(model.relational, names) as seen:
        for _ in range(config.imitate.dagger_steps):
            totals += _imitation_step(
                model, optimizer, buffer, config, rng, device, generator, seen
            )
    return LossStats(*(totals / config.imitate.dagger_steps).tolist())


def _imitation_step(
    model: ActorCritic,
    optimizer: torch.optim.Optimizer,
    buffer: LabelBuffer,
    config: TrainConfig,
    rng: np.random.Generator,
    device: torch.device,
    generator: torch.Generator | None,
    seen: dict[str, torch.Tensor],
) -> list[float]:
    """One minibatch's gradient step: policy, safe, attention and value losses."""
    obs, policy, values, safe, targets = buffer.sample(config.imitate.dagger_batch, rng)
    if config.imitate.augment:  # the level turned or mirrored; the return still to earn is the same
        obs, moved, targets = augment_with_targets(
            obs, torch.stack((policy, safe.float()), dim=-1), targets, generator
        )
        policy, safe = moved[..., 0], moved[..., 1] > 0
    obs, policy, values = obs.to(device), policy.to(device), values.to(device)
    logits, value = model(obs)
    if config.imitate.teacher:
        policy_loss = distill_loss(logits, policy)
    else:
        policy_loss = imitation_loss(logits, policy > 0)
    if config.imitate.safe_coef:
        policy_loss = policy_loss + config.imitate.safe_coef * imitation_loss(
            logits, safe.to(device)
        )
    if config.imitate.attend_coef:  # head 0's arguments on the route's cells
        scores = seen["scores"][:, [0, model.relational.heads]]  # head 0's first and second
        targets = targets.to(device)
        nll = attention_target_nll(scores[:, 0], targets[:, 0])
        nll = nll + attention_target_nll(scores[:, 1], targets[:, 1])
        policy_loss = policy_loss + config.imitate.attend_coef * nll
    value_loss = 0.5 * (value - values * config.reward_scale).pow(2).mean()
    loss = policy_loss + config.value_coef * value_loss
    optimizer.zero_grad(set_to_none=True)
    loss.backward()
    norm = torch.nn.utils.clip_grad_norm_(model.parameters(), config.grad_clip)
    check_finite(norm, loss)
    optimizer.step()
    with torch.no_grad():
        logp = torch.log_softmax(logits, dim=-1)
        entropy = -(logp.exp() * logp).sum(-1).mean()
    return [policy_loss.item(), value_loss.item(), entropy.item(), float(norm)]


def planner_for(env_name: str) -> Any:
    """The optimal planner of an env's family (RGW's, or Minigrid DoorKey's); Box-World's
    route search, which gives attention targets only."""
    from neurosym.envs.registration import env_family

    family = env_family(env_name)
    if family == "boxworld":
        from neurosym.envs.boxworld_solver import RouteTargets

        return RouteTargets()
    if family == "minigrid":
        from neurosym.envs.minigrid_solver import DoorKeyPlanner as MinigridPlanner

        return MinigridPlanner()
    from neurosym.envs.rgw_solver import Planner

    return Planner()


def _teacher(ctx: LearnerContext, venv: Any, device: torch.device) -> Teacher | None:
    """The run's teacher (``ImitationConfig.teacher``), None when the planner labels."""
    spec = ctx.train_config.imitate.teacher
    if not spec:
        return None
    shape = tuple(int(v) for v in venv.single_observation_space.shape)
    return load_teacher(spec, ctx.env_name, shape, int(venv.single_action_space.n), device)


def imitation_learner(ctx: LearnerContext) -> None:
    """The DAgger learner process: labelled rollouts and updates until ``ctx.stop`` is set.

    Beta goes on from ``ctx.frames0``, the frames trained before a resume.
    """
    torch.set_num_threads(max(1, len(os.sched_getaffinity(0))))
    with learner_process(ctx.queue, ctx.rank):
        from neurosym.envs import make_batched

        config = ctx.train_config
        dev = distributed.learner_device(ctx.device, distributed.World())
        torch.manual_seed(ctx.env_seed)
        generator = torch.Generator().manual_seed(ctx.env_seed)
        rng = np.random.default_rng(ctx.env_seed)
        local, local_opt = private_copy(ctx.shared, ctx.optimizer, config, dev)
        venv = make_batched(ctx.env_name, config.envs, seed=ctx.env_seed, **ctx.env_kwargs)
        obs, _ = venv.reset(seed=ctx.env_seed)
        attend = config.imitate.attend_coef > 0  # route targets only where the loss reads them
        teacher = _teacher(ctx, venv, dev)
        planner = planner_for(ctx.env_name) if teacher is None or attend else None
        tracker = EpisodeTracker(venv.num_envs)
        n_actions = int(venv.single_action_space.n)
        buffer = LabelBuffer(config.imitate.dagger_buffer, obs.shape[1:], obs.dtype, n_actions)
        safe_loss = config.imitate.safe_coef > 0  # regrets only where the loss reads them
        frames = ctx.frames0
        parent = os.getppid()
        while not ctx.stop.is_set() and os.getppid() == parent:
            finished = Finished.empty()
            beta = expert_share(frames, config.imitate.dagger_beta_frames)
            steps = 0
            for _ in range(config.n_steps):
                if teacher is None:
                    policy, values, regret = planner.labels(venv, regret=safe_loss)
                    expert = planner_choice(policy, rng)
                else:
                    (policy, values), regret = teacher.labels(obs), None
                    expert = select_actions(torch.from_numpy(policy).log(), False, generator).numpy()
                targets = planner.attention_targets(venv) if attend else None
                with torch.no_grad():
                    logits, _ = local(torch.from_numpy(obs).to(dev))
                mine = select_actions(logits.cpu(), greedy=False, generator=generator).numpy()
                follow = rng.random(len(mine)) < beta
                actions = np.where(follow, expert, mine)
                real = ~tracker.pending  # an autoreset step's observation is the last one's end
                safe = None if regret is None else regret[real] <= 0
                buffer.add(
                    obs[real],
                    policy[real],
                    values[real],
                    safe,
                    None if targets is None else targets[real],
                )
                obs, reward, terminated, truncated, info = venv.step(actions)
                obs = np.ascontiguousarray(obs)
                valid, done = tracker.step(venv, reward, terminated, truncated, info)
                finished.extend(done)
                steps += int(valid.sum())
            stats = imitation_update(local, local_opt, buffer, config, rng, dev, generator)
            copy_into_shared(local, local_opt, ctx.shared, ctx.optimizer)
            frames += steps
            report_update(ctx, steps, finished, stats)
        ctx.queue.put(Stopped(ctx.rank))  # one process: no ranks to compare
