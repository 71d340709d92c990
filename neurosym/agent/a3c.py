"""A3C: the actor-critic update, shared optimisers (Adam, RMSprop), and the worker process.

Each of W worker processes steps K environments (K = 1 is the classic
algorithm with one env per worker; the same batched env code runs it) for
``n_steps`` steps with a local copy of the shared model, then computes the
loss on that rollout and writes its gradients into the shared model, where a
:class:`SharedRMSprop` (statistics in shared memory too) applies them without
locks (Hogwild). Workers run one torch thread each.

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
(:class:`AdvantageScale` says why not the usual per-batch normalisation). With lambda = 1, s = 1 and no normalisation this is Table 4's n-step
A3C: A_t = G_t - V(o_t) with G_t the bootstrapped n-step return.
Truncated episodes (time limit) bootstrap from V of their final observation.
With ``config.sil > 0`` the self-imitation loss (:mod:`neurosym.agent.sil`)
on a batch of M remembered transitions is added, scaled to T transitions.
With ``config.planner_coef = c > 0`` (RGW), ``c * sum -log pi(optimal set|o_t)``
over the rollout's valid transitions is added (per env, like the rest): the
env planner's optimal actions in each visited state, as DAgger labels them.
"""

from __future__ import annotations

import contextlib
import math
import os
import signal
import traceback
from collections.abc import Callable, Iterable, Iterator
from typing import Any, NamedTuple

import torch
import torch.nn.functional as F

from neurosym.agent.allocator import keep_freed_memory
from neurosym.agent.config import ModelConfig, TrainConfig
from neurosym.agent.exploration import CountBonus
from neurosym.agent.model import ActorCritic
from neurosym.agent.planner_loss import optimal_set_nll
from neurosym.agent.rollout import Finished, Rollout, RolloutState, collect_rollout
from neurosym.agent.sil import EpisodeMemory, SILBatch, sil_loss


class _SharedState:
    """Optimiser statistics created up front (torch makes them lazily, per process) so that
    :meth:`share_memory` can move them to shared memory before the workers start."""

    STATE_KEYS: tuple[str, ...] = ()
    """the per-parameter statistics besides ``step``"""

    def _init_state(self) -> None:
        for group in self.param_groups:  # type: ignore[attr-defined]
            for p in group["params"]:
                state = self.state[p]  # type: ignore[attr-defined]
                if not state:
                    state["step"] = torch.zeros(())
                    for key in self.STATE_KEYS:
                        state[key] = torch.zeros_like(p, memory_format=torch.preserve_format)

    def share_memory(self):  # returns self, for chaining
        """Move the statistics to shared memory (call again after load_state_dict)."""
        for state in self.state.values():  # type: ignore[attr-defined]
            for value in state.values():
                value.share_memory_()
        return self


class SharedAdam(_SharedState, torch.optim.Adam):
    """Adam whose moment estimates are created eagerly and can live in shared memory.

    The usual optimiser of A3C implementations (e.g. ikostrikov's pytorch-a3c):
    its per-weight step is about ``lr`` whatever the gradient's size, so the
    encoder and attention layers, whose gradients start 1e-8..1e-6, move as
    fast as the policy head (bench/diagnose.py measured the sizes).
    """

    STATE_KEYS = ("exp_avg", "exp_avg_sq")

    def __init__(self, params: Iterable[torch.nn.Parameter], lr: float, eps: float) -> None:
        super().__init__(params, lr=lr, eps=eps, foreach=False)
        self._init_state()

    def set_hyperparameters(self, lr: float, eps: float) -> None:
        for group in self.param_groups:
            group.update(lr=lr, eps=eps)


class SharedRMSprop(_SharedState, torch.optim.RMSprop):
    """RMSprop without momentum whose statistics are created eagerly and can live in shared memory.

    torch's RMSprop creates its state lazily on the first step, inside each
    process; here the state exists up front so that :meth:`share_memory`
    can move it to shared memory before the workers start.
    """

    STATE_KEYS = ("square_avg",)

    def __init__(
        self, params: Iterable[torch.nn.Parameter], lr: float, alpha: float, eps: float
    ) -> None:
        super().__init__(
            params, lr=lr, alpha=alpha, eps=eps, momentum=0.0, centered=False, foreach=False
        )
        self._init_state()

    def set_hyperparameters(self, lr: float, alpha: float, eps: float) -> None:
        """Apply settings after loading a state dict (which carries the old ones)."""
        for group in self.param_groups:
            group.update(lr=lr, alpha=alpha, eps=eps)


SharedOptimizer = SharedAdam | SharedRMSprop


def shared_optimizer(params: Iterable[torch.nn.Parameter], config: TrainConfig) -> SharedOptimizer:
    """The optimiser ``config.optimizer`` names, with its statistics created up front."""
    if config.optimizer == "adam":
        return SharedAdam(params, config.lr, config.adam_eps)
    return SharedRMSprop(params, config.lr, config.rms_alpha, config.rms_eps)


def set_optimizer_hyperparameters(optimizer: SharedOptimizer, config: TrainConfig) -> None:
    """Apply ``config``'s settings after loading a state dict (which carries the old ones)."""
    if isinstance(optimizer, SharedAdam):
        optimizer.set_hyperparameters(config.lr, config.adam_eps)
    else:
        optimizer.set_hyperparameters(config.lr, config.rms_alpha, config.rms_eps)


class LossStats(NamedTuple):
    """Per-update diagnostics (per env, summed over time).

    ``approx_kl``, ``clip_fraction`` and ``explained_variance`` are PPO's (NaN
    for the other learners), as SB3 and CleanRL log them: how far each
    minibatch step moved the policy from the one that acted, and how much of
    the rollout's returns' variance the acting critic's values explained (1:
    all, 0: no better than their mean), the first things to read when a PPO
    run does not learn.
    """

    policy_loss: float
    value_loss: float
    entropy: float
    grad_norm: float
    approx_kl: float = math.nan
    clip_fraction: float = math.nan
    explained_variance: float = math.nan


def n_step_returns(
    rewards: torch.Tensor,
    terminated: torch.Tensor,
    truncated: torch.Tensor,
    next_values: torch.Tensor,
    gamma: float,
) -> torch.Tensor:
    """(T, K) bootstrapped n-step returns G_t; next_values[t] = V(o_{t+1}) (see the module docstring)."""
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
    """(T, K) generalised advantage estimates; next_values[t] = V(o_{t+1}) (module docstring).

    With ``lam = 1`` this is ``n_step_returns(...) - values``.
    """
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


class AdvantageScale:
    """Divides advantages by a running root-mean-square of the advantages seen so far.

    Why not the usual per-batch normalisation (subtract the mean, divide by the
    std)? An A3C update sees one small rollout (K envs x 40 steps), and on
    sparse-reward levels most rollouts hold no reward at all: their advantages
    are the critic's small errors, and centring and scaling them per rollout
    turns that noise into full-sized policy steps with a random sign (measured
    on bw1: the policy drifted to a deterministic one whose success fell from
    the random 20 % to 0.4 % within 500 k frames). A running RMS keeps each
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


def a3c_loss(
    model: torch.nn.Module,
    rollout: Rollout,
    config: TrainConfig,
    sil_batch: SILBatch | None = None,
    scale: AdvantageScale | None = None,
    critic_only: bool = False,
) -> tuple[torch.Tensor, LossStats]:
    """The scalar loss of one rollout (plus self-imitation on ``sil_batch``) and its parts.

    With ``config.normalize_advantages`` the advantages are divided by
    ``scale``'s running RMS (a worker keeps one; without it, this rollout's RMS).
    ``critic_only`` (``config.critic_warmup``): the loss is the value loss
    alone; the other parts are still reported.

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
    if critic_only:
        loss = config.value_coef * value_loss
    else:
        loss = policy_loss + config.value_coef * value_loss - config.entropy * entropy_sum
    if config.planner_coef > 0 and not critic_only:
        if rollout.optimal is None:
            raise ValueError("planner_coef > 0 needs a rollout collected with the planner's labels")
        nll = optimal_set_nll(logits, rollout.optimal)  # (T, K)
        loss = loss + config.planner_coef * (nll * mask).sum() / K
    if sil_batch is not None and not critic_only:
        M = sil_batch.actions.shape[0]
        scaled = sil_batch._replace(returns=sil_batch.returns * config.reward_scale)
        sil = sil_loss(logits_all[n + K :], values_all[n + K :], scaled, config.value_coef)
        loss = loss + config.sil * sil * (T / M)
    numbers = torch.stack([policy_loss, value_loss, entropy_sum]).tolist()
    return loss, LossStats(numbers[0], numbers[1], numbers[2], 0.0)


def apply_update(
    local: torch.nn.Module,
    shared: torch.nn.Module,
    optimizer: torch.optim.Optimizer,
    loss: torch.Tensor,
    clip: float,
    only_prefix: str | None = None,
) -> float:
    """Backpropagate on the local model, hand its gradients to the shared one, step; the gradient norm.

    ``only_prefix`` (e.g. ``"value."``): only parameters whose names start with
    it get a gradient; the optimiser leaves every other weight, and its
    statistics, as they are.
    """
    local.zero_grad(set_to_none=True)
    loss.backward()
    if only_prefix is not None:
        for name, p in local.named_parameters():
            if not name.startswith(only_prefix):
                p.grad = None
    norm = torch.nn.utils.clip_grad_norm_(local.parameters(), clip)
    for shared_p, local_p in zip(shared.parameters(), local.parameters(), strict=True):
        shared_p.grad = local_p.grad
    optimizer.step()
    return float(norm)


def report_update(queue: Any, rank: int, frames: int, finished: Finished, stats: LossStats) -> None:
    """The ``("update", ...)`` message a learner sends the trainer after each update."""
    queue.put(
        (
            "update",
            rank,
            frames,
            finished.returns,
            finished.lengths,
            finished.outcomes,
            tuple(stats),
        )
    )


@contextlib.contextmanager
def learner_process(
    queue: Any, rank: int, cleanup: Callable[[], None] | None = None
) -> Iterator[None]:
    """What every learner process does around its work (A3C worker, PPO, imitation).

    Freed memory stays in the process for the next update's tensors
    (:mod:`neurosym.agent.allocator`: page faults cost a quarter of an update
    otherwise); Ctrl-C is the parent's business (SIGINT ignored); the process dies with
    its trainer (:func:`distributed.die_with_parent`); any exception becomes
    an ``("error", rank, traceback)`` message; the queue is flushed before
    ``cleanup`` runs (leaving a gloo group whose peer has gone can block while
    holding the GIL, which would starve the queue's feeder thread).
    """
    from neurosym.agent import distributed

    keep_freed_memory()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    distributed.die_with_parent()
    try:
        yield
    except BaseException:  # noqa: BLE001 - reported to the parent, which raises it
        queue.put(("error", rank, traceback.format_exc()))
    finally:
        with contextlib.suppress(Exception):
            queue.close()
            queue.join_thread()
        if cleanup is not None:
            # a peer that died leaves nothing to say goodbye to
            with contextlib.suppress(Exception):
                cleanup()


def planner_labels() -> Callable[[Any], Any]:
    """``venv -> (K, 4) bool``: the RGW planner's optimal actions in each sub-env's state
    (plans cached per level, as DAgger's)."""
    from neurosym.envs.rgw_solver import Planner

    planner = Planner()
    return lambda venv: planner.action_sets(venv)[0]


def worker(
    rank: int,
    shared: ActorCritic,
    optimizer: SharedOptimizer,
    model_config: ModelConfig,
    train_config: TrainConfig,
    env_name: str,
    env_kwargs: dict[str, Any],
    env_seed: int,
    stop: Any,
    queue: Any,
    frames0: int = 0,
) -> None:
    """One A3C worker: rollouts and updates until ``stop`` is set; reports to ``queue``.

    ``frames0``: frames the run had trained before this session; the worker
    does its share (1 / W) of what is left of ``train_config.critic_warmup``
    with the value head alone.

    Messages: ``("update", rank, frames, returns, lengths, outcomes, LossStats tuple)``
    per update, ``("error", rank, traceback text)`` if anything fails.
    Ctrl-C is the parent's business: the worker ignores SIGINT.
    """
    torch.set_num_threads(1)
    with learner_process(queue, rank):
        from neurosym.envs import make_batched

        torch.manual_seed(env_seed)
        generator = torch.Generator().manual_seed(env_seed)
        venv = make_batched(env_name, train_config.envs, seed=env_seed, **env_kwargs)
        local = ActorCritic(model_config)
        state = RolloutState(venv, env_seed)
        bonus = None
        if train_config.explore > 0:
            bonus = CountBonus(train_config.explore, half_life=train_config.explore_half_life)
        memory = None
        if train_config.sil > 0:
            memory = EpisodeMemory(train_config.envs, train_config.gamma, train_config.sil_episodes)
        # MHDPA's cost is per-sample attention, cheapest in small batches: with
        # K = 32 keeping each acting step's graph beat a second forward over the
        # rollout by 45 % (one worker), at K = 8 it was 4 % ahead (W = 2), at
        # K <= 4 it lost (K = 1: 456 against 676 frames/s, one worker)
        keep_graph = model_config.module == "mhdpa" and train_config.envs >= 8
        labels = planner_labels() if train_config.planner_coef > 0 else None
        scale = AdvantageScale()
        warmup = -(-max(0, train_config.critic_warmup - frames0) // train_config.workers)
        frames = 0
        parent = os.getppid()
        while not stop.is_set() and os.getppid() == parent:  # also stop if the parent died
            local.load_state_dict(shared.state_dict())
            rollout, finished = collect_rollout(
                local,
                state,
                train_config.n_steps,
                generator,
                bonus,
                memory,
                keep_graph,
                labels=labels,
            )
            batch = memory.sample(train_config.n_steps, generator) if memory is not None else None
            warming = frames < warmup
            loss, stats = a3c_loss(local, rollout, train_config, batch, scale, critic_only=warming)
            norm = apply_update(
                local,
                shared,
                optimizer,
                loss,
                train_config.grad_clip,
                only_prefix="value." if warming else None,
            )
            n = int(rollout.valid.sum())
            frames += n
            report_update(queue, rank, n, finished, stats._replace(grad_norm=norm))
