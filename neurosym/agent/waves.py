"""Whole episodes played in waves on a batched env: the one play loop.

Evaluation (:mod:`neurosym.agent.evaluation`), recording
(:mod:`neurosym.record.recorder`) and the live viewer (:mod:`neurosym.viz.live`)
all play episodes the same way: episode k from ``reset(seed=seed + k)``, in
waves of at most ``batch`` sub-envs reset together, each wave stepped until
every episode in it has ended. :func:`run_waves` does that and hands the
caller each wave (after its reset) and each step, so the callers keep only
what they record.

Sub-envs beyond a wave's episodes, and sub-envs whose episode has ended, are
idle: they keep stepping (the env autoresets them) and nothing about them is
reported. Who the policy sees is the caller's choice, because with sampled
actions it decides how the random draws are shared out and so the episodes:
``act_on="all"`` gives the policy the whole batch every step, ``"live"`` only
the live sub-envs (idle ones step action 0, "up").
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from neurosym.errors import ConfigError

Act = Callable[[np.ndarray, Any], Any]
"""``act(obs, venv)``: actions (B,) for the observations (B, ...) of a batch."""


class EpisodeTooLong(ConfigError):
    """An episode ran ``max_steps`` steps without ending: the env has no time limit."""

    def __init__(self, episode: int, steps: int) -> None:
        super().__init__(
            f"episode {episode} ran {steps} steps without ending; the env has no time limit"
        )
        self.episode, self.steps = episode, steps


@dataclass
class Step:
    """One step of a wave, as the env answered it.

    ``live`` holds the sub-envs whose episode ran before the step (every
    per-step figure the callers keep is about them), ``ended`` those of them
    whose episode ended on this step. ``obs`` is what the policy acted on.
    """

    t: int
    """the step's index in the wave (all of a wave's episodes start together, so also each episode's t)"""
    live: np.ndarray
    episodes: np.ndarray
    """(len(live),) the episode number each live sub-env plays"""
    obs: np.ndarray
    actions: np.ndarray
    """(n,) int64 actions of the whole batch"""
    reward: np.ndarray
    terminated: np.ndarray
    truncated: np.ndarray
    info: Any
    ended: np.ndarray


@dataclass
class Wave:
    """One reset of the batched env: sub-env i plays episode ``first + i`` for i < ``count``.

    Iterate :meth:`steps` to play it. ``returns`` and ``lengths`` (per sub-env)
    add up the live sub-envs' rewards and steps as it goes.
    """

    first: int
    count: int
    venv: Any
    obs: np.ndarray
    info: Any
    act: Act
    act_on: Literal["live", "all"]
    max_steps: int
    stop_at_limit: bool

    def __post_init__(self) -> None:
        n = len(self.obs)
        self.live_mask = np.zeros(n, dtype=bool)
        self.live_mask[: self.count] = True
        self.returns = np.zeros(n, dtype=np.float64)
        self.lengths = np.zeros(n, dtype=np.int64)

    def steps(self) -> Iterator[Step]:
        """Step until every episode of the wave ended (or ``max_steps`` with ``stop_at_limit``).

        Raises :class:`EpisodeTooLong` when an episode is still running after
        ``max_steps`` steps, unless ``stop_at_limit`` (a caller that wants only
        a prefix of the episode, such as a picture of its first steps).
        """
        obs, n = self.obs, len(self.obs)
        for t in range(self.max_steps):
            live = np.flatnonzero(self.live_mask)
            if not live.size:
                return
            actions = self._actions(obs, live, n)
            acted_on = obs
            obs, reward, terminated, truncated, info = self.venv.step(actions)
            self.returns += np.where(self.live_mask, reward, 0.0)
            self.lengths += self.live_mask
            ended_mask = self.live_mask & (terminated | truncated)
            self.live_mask &= ~ended_mask
            yield Step(
                t, live, self.first + live, acted_on, actions, reward, terminated,
                truncated, info, np.flatnonzero(ended_mask),
            )  # fmt: skip
        if self.live_mask.any() and not self.stop_at_limit:
            raise EpisodeTooLong(
                self.first + int(np.flatnonzero(self.live_mask)[0]), self.max_steps
            )

    def _actions(self, obs: np.ndarray, live: np.ndarray, n: int) -> np.ndarray:
        """(n,) int64 actions: the policy on the whole batch, or on the live sub-envs only."""
        if self.act_on == "all" or live.size == n:
            return np.asarray(self.act(obs, self.venv), dtype=np.int64)
        actions = np.zeros(n, dtype=np.int64)  # idle sub-envs step "up"
        actions[live] = np.asarray(self.act(obs[live], self.venv))
        return actions


def run_waves(
    act: Act,
    venv_for: Callable[[int], Any],
    episodes: int,
    seed: int,
    batch: int,
    *,
    act_on: Literal["live", "all"] = "all",
    max_steps: int = 100_000,
    stop_at_limit: bool = False,
) -> Iterator[Wave]:
    """The waves that play ``episodes`` episodes, episode k from ``reset(seed=seed + k)``.

    ``venv_for(count)`` gives the batched env of a wave of ``count`` episodes
    (at most ``batch``); it may have more sub-envs than that (a fixed-size env
    reused for every wave), which are reset with the next seeds and stay idle.
    Each wave is yielded right after its reset; iterate its :meth:`Wave.steps`
    before asking for the next wave.
    """
    if act_on not in ("live", "all"):
        raise ValueError(f"act_on must be 'live' or 'all', got {act_on!r}")
    for first in range(0, episodes, batch):
        count = min(batch, episodes - first)
        venv = venv_for(count)
        n = int(getattr(venv, "num_envs", count))
        obs, info = venv.reset(seed=[seed + first + i for i in range(n)])
        yield Wave(first, count, venv, obs, info, act, act_on, max_steps, stop_at_limit)


class SingleAsBatch:
    """A single gymnasium env seen as a batch of one, so that :func:`run_waves` can play it.

    Observations and step results get a batch axis of 1; ``info`` is passed
    through as the env gives it (one episode's dict, not batched).
    """

    num_envs = 1

    def __init__(self, env: Any) -> None:
        self.env = env

    def reset(self, seed: list[int]) -> tuple[np.ndarray, Any]:
        obs, info = self.env.reset(seed=seed[0])
        return np.asarray(obs)[None], info

    def step(
        self, actions: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, Any]:
        obs, reward, terminated, truncated, info = self.env.step(int(actions[0]))
        return (
            np.asarray(obs)[None],
            np.asarray([reward], dtype=np.float64),
            np.asarray([bool(terminated)]),
            np.asarray([bool(truncated)]),
            info,
        )
