"""Batched acting shared by training, evaluation and recording.

* :func:`select_actions`: greedy or sampled actions from logits, for a batch.
* :class:`EpisodeTracker`: returns, lengths and outcomes of the episodes that
  end in a batched env with gymnasium's next-step autoreset (the step after an
  episode ends is not a real transition; ``valid`` says which are).
* :func:`collect_rollout`: n steps of K envs acted without a graph; the A3C
  update runs the model once over the stacked rollout.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
import torch

SUCCESS_OUTCOMES = ("terminal", "gem", "goal", "mission")
"""Outcomes that count as solving an episode (RGW terminal, Box-World gem, Minigrid goal or
mission)."""


def select_actions(
    logits: torch.Tensor, greedy: bool, generator: torch.Generator | None = None
) -> torch.Tensor:
    """(B,) int64 actions: argmax, or one draw per row from softmax(logits) with ``generator``."""
    if greedy:
        return logits.argmax(dim=-1)
    probs = torch.softmax(logits.detach().float(), dim=-1)  # (B, A)
    u = torch.rand(probs.shape[0], 1, generator=generator)  # (B, 1)
    # inverse CDF; the clamp guards against cumsum ending a hair below u
    return (probs.cumsum(-1) < u).sum(-1).clamp_(max=probs.shape[-1] - 1)


def outcome_of(venv: Any, info: dict[str, Any], i: int, truncated: bool) -> str:
    """Outcome name of sub-env i's episode that ended on this step."""
    quick = getattr(venv, "episode_outcome", None)  # the outcome alone: no objects decoded
    if quick is not None:
        outcome = quick(info, i)
    else:
        decode = getattr(venv, "decode_info", None)
        outcome = decode(info, i).get("outcome") if decode is not None else None
    return str(outcome) if outcome else ("timeout" if truncated else "terminal")


@dataclass
class Finished:
    """Episodes that ended: one entry per episode."""

    returns: list[float]
    lengths: list[int]
    outcomes: list[str]

    @classmethod
    def empty(cls) -> Finished:
        return cls([], [], [])

    def extend(self, other: Finished) -> None:
        self.returns += other.returns
        self.lengths += other.lengths
        self.outcomes += other.outcomes

    def __len__(self) -> int:
        return len(self.returns)


class EpisodeTracker:
    """Running return and length per sub-env of a next-step-autoreset batched env."""

    def __init__(self, n: int) -> None:
        self.ret = np.zeros(n, dtype=np.float64)
        self.length = np.zeros(n, dtype=np.int64)
        self.pending = np.zeros(
            n, dtype=bool
        )  # True: the next step is an autoreset, not a transition

    def step(
        self,
        venv: Any,
        reward: np.ndarray,
        terminated: np.ndarray,
        truncated: np.ndarray,
        info: dict[str, Any],
    ) -> tuple[np.ndarray, Finished]:
        """Account one env step; (valid mask of this step's transitions, episodes that ended)."""
        valid = ~self.pending
        self.ret += np.where(valid, reward, 0.0)
        self.length += valid
        done = (terminated | truncated) & valid
        finished = Finished.empty()
        for i in np.flatnonzero(done).tolist():
            finished.returns.append(float(self.ret[i]))
            finished.lengths.append(int(self.length[i]))
            finished.outcomes.append(outcome_of(venv, info, i, bool(truncated[i])))
        self.ret[done] = 0.0
        self.length[done] = 0
        self.pending = done
        return valid, finished


class Rollout(NamedTuple):
    """n steps of K envs; tensors are (T, K) unless noted."""

    obs: torch.Tensor
    """(T, K, C, H, W) uint8: the observation each action was taken in (on the acting
    device when that is a GPU, else on the CPU)"""
    last_obs: torch.Tensor
    """(K, C, H, W) uint8: the observation after the last step (the bootstrap)"""
    actions: torch.Tensor
    rewards: torch.Tensor
    """the training rewards: the env's plus any exploration bonus"""
    terminated: torch.Tensor
    truncated: torch.Tensor
    valid: torch.Tensor
    """False for the autoreset steps that are not transitions"""
    logits: torch.Tensor | None = None
    """(T, K, A) the acting logits: with the model's graph when acting kept it (A3C), without
    when only recorded (PPO's behaviour policy); None when neither (the update recomputes)"""
    values: torch.Tensor | None = None
    """(T, K) the acting values, likewise"""
    queries: Any | None = None
    """what the model kept of its acting forwards (``ActorCritic.recording``: PrediNet's
    queries), for an update that runs the model over ``obs`` again with the same weights"""


class RolloutState:
    """What a worker carries from one rollout to the next: env, current observation, episode tracker."""

    def __init__(self, venv: Any, seed: int) -> None:
        self.venv = venv
        obs, _ = venv.reset(seed=seed)
        self.obs = np.ascontiguousarray(obs)
        self.tracker = EpisodeTracker(venv.num_envs)


def collect_rollout(
    model: torch.nn.Module,
    state: RolloutState,
    n_steps: int,
    generator: torch.Generator | None,
    bonus: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None,
    memory: Any | None = None,
    keep_graph: bool = False,
    record: bool = False,
    device: torch.device | None = None,
) -> tuple[Rollout, Finished]:
    """Act ``n_steps`` steps in every sub-env with sampled actions.

    By default no graph is kept and the update runs the model once more over
    the whole rollout: one batched forward and backward instead of T small
    ones (PrediNet's big weight-gradient products want big batches).
    ``keep_graph`` keeps each step's graph instead and saves that second
    forward (MHDPA with many envs: its cost is per-sample attention, cheapest
    in small batches).
    ``bonus(next_obs, valid) -> (K,)`` adds an intrinsic reward to the
    rollout's rewards (the training signal); the finished episodes' returns
    are the environment's own. ``memory`` (an ``sil.EpisodeMemory``) is fed
    every transition, with the environment's rewards. ``record`` keeps the
    acting logits and values without a graph (PPO's behaviour policy).
    ``device``: where the model lives (observations go there, actions are
    drawn on the CPU so that the generator's stream is the same on any device);
    the recorded logits and values stay there, and on a GPU the observations
    too (the update reads them there: no second copy of the whole rollout
    through the host); the rest of the rollout is on the CPU.
    """
    on_device = device is not None and device.type != "cpu"
    venv, tracker = state.venv, state.tracker
    obs_t, actions_t, rewards, terms, truncs, valids = [], [], [], [], [], []
    logits_t, values_t = [], []
    finished = Finished.empty()
    # no graph kept and nothing recorded: the update will run the model over these
    # observations again, and may take back what the model remembers of acting
    reuse = not keep_graph and not record and hasattr(model, "recording")
    with model.recording() if reuse else contextlib.nullcontext() as queries:
        for _ in range(n_steps):
            with torch.set_grad_enabled(keep_graph):
                obs_in = torch.from_numpy(state.obs)
                if device is not None:
                    obs_in = obs_in.to(device)
                logits, value = model(obs_in)  # (K, A), (K,)
            if keep_graph or record:
                logits_t.append(logits)
                values_t.append(value)
            acting = logits if device is None else logits.detach().cpu()
            actions = select_actions(acting, greedy=False, generator=generator).numpy()
            obs, reward, terminated, truncated, info = venv.step(actions)
            valid, done = tracker.step(venv, reward, terminated, truncated, info)
            finished.extend(done)
            if memory is not None:
                memory.step(state.obs, actions, reward, valid, terminated | truncated)
            if bonus is not None:
                reward = reward + bonus(obs, valid)
            obs_t.append(obs_in if on_device else state.obs)
            actions_t.append(actions)
            rewards.append(reward)
            terms.append(terminated)
            truncs.append(truncated)
            valids.append(valid)
            state.obs = np.ascontiguousarray(obs)
    rollout = Rollout(
        obs=torch.stack(obs_t) if on_device else torch.from_numpy(np.stack(obs_t)),
        last_obs=torch.from_numpy(state.obs),
        actions=torch.from_numpy(np.stack(actions_t).astype(np.int64)),
        rewards=torch.from_numpy(np.stack(rewards).astype(np.float32)),
        terminated=torch.from_numpy(np.stack(terms)),
        truncated=torch.from_numpy(np.stack(truncs)),
        valid=torch.from_numpy(np.stack(valids)),
        logits=torch.stack(logits_t) if logits_t else None,
        values=torch.stack(values_t) if values_t else None,
        queries=queries,
    )
    return rollout, finished
