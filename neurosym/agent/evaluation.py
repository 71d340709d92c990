"""Evaluation episodes scored against their levels: optimal return, sword first, no detour.

:func:`play_scored` plays whole episodes with :func:`neurosym.agent.waves.run_waves`
(episode k from ``reset(seed=seed + k)``, in waves of at most ``batch`` sub-envs;
:func:`play_episodes` is the same without scores)
and keeps, per episode, what the level was and what the agent did about it.
On Relational-Grid-World envs every level reports its optimal return and its
kinds (``info["optimal_return"]``, ``info["guarded"]``, rgw_solver), so
:func:`level_scores` can say:

* ``optimal_rate``: share of episodes whose return reached the level's optimal
  return (the best any route earns within the step limit), within ``TOLERANCE``.
* ``sword_first_guarded``: share of episodes on guarded levels (every route to
  the terminal meets an enemy) in which the agent picked up the sword before it
  first met an enemy (``defeated``, ``hurt_by``, ``bumped`` or ``killed_by``
  the enemy), or picked it up and never met one.
* ``no_detour_decoy``: share of episodes on decoy levels (not guarded: the
  sword is not needed) that reached the terminal and lost no return to a
  detour: their return is at least the best return of the routes that never
  pick up the sword (same search, sword taken off the map). Taking the sword
  on the way and beating the decoy enemy for +1 is no loss; wandering off for
  it across mountains, or not finishing, is.
* ``sword_taken_decoy``: share of decoy-level episodes that picked up the sword.

A share whose episodes do not occur (no decoy level on rgw2) is None. The
level is a function of the reset seed, so evaluation seeds that training never
used are unseen levels of rgw-random.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from neurosym.agent.rollout import Finished, outcome_of
from neurosym.agent.waves import run_waves

TOLERANCE = 1e-6
"""returns this close to the optimal return count as optimal (float sums of -0.1 steps)"""


@dataclass
class ScoredEpisodes:
    """Per episode, in episode order: what happened and, on RGW, what the level was."""

    returns: list[float] = field(default_factory=list)
    lengths: list[int] = field(default_factory=list)
    outcomes: list[str] = field(default_factory=list)
    optimal_return: list[float] = field(default_factory=list)
    """the level's optimal return (NaN: not known, e.g. Box-World)"""
    guarded: list[bool] = field(default_factory=list)
    sword_first: list[bool] = field(default_factory=list)
    """picked up the sword before first meeting an enemy (or never met one)"""
    took_sword: list[bool] = field(default_factory=list)
    no_sword_best: list[float] = field(default_factory=list)
    """decoy levels: the best return without picking up the sword (NaN elsewhere)"""


def play_scored(
    act: Callable[[np.ndarray, Any], np.ndarray],
    make_venv: Callable[[int], Any],
    episodes: int,
    seed: int,
    batch: int = 64,
    max_steps: int = 100_000,
    levels: bool = True,
) -> ScoredEpisodes:
    """Play ``episodes`` episodes; ``act(obs, venv)`` gives the actions of a batch.

    ``act`` gets the batched env as well, so that a scripted policy (such as
    rgw_solver's planner in the tests) can read the state; it sees the whole
    batch every step (``act_on="all"`` of :func:`run_waves`). ``levels=False``
    skips the level-aware scoring (its no-sword search costs time at every
    reset): returns, lengths and outcomes only, as the trainer's evaluation wants.
    """
    out = ScoredEpisodes()
    venvs: dict[int, Any] = {}
    waves = run_waves(
        act, lambda n: venvs.setdefault(n, make_venv(n)), episodes, seed, batch,
        act_on="all", max_steps=max_steps,
    )  # fmt: skip
    for wave in waves:
        n, venv = wave.count, wave.venv
        outcome: list[str] = [""] * n
        scores = (
            _LevelTally(venv, wave.info, n) if levels and "optimal_return" in wave.info else None
        )
        for step in wave.steps():
            if scores is not None:
                scores.mark(step.info["events"], step.live, step.t)
            for i in step.ended.tolist():
                outcome[i] = outcome_of(venv, step.info, i, bool(step.truncated[i]))
        out.returns += wave.returns[:n].tolist()
        out.lengths += wave.lengths[:n].tolist()
        out.outcomes += outcome
        if scores is not None:
            scores.add_to(out)
        else:
            out.optimal_return += [float("nan")] * n
            out.guarded += [False] * n
            out.took_sword += [False] * n
            out.sword_first += [False] * n
            out.no_sword_best += [float("nan")] * n
    return out


class _LevelTally:
    """One wave's RGW level facts (optimal return, guarded, best without the sword) and sword timing."""

    def __init__(self, venv: Any, info: dict[str, Any], n: int) -> None:
        self.optimal = np.asarray(info["optimal_return"], dtype=float).copy()
        self.guarded = np.asarray(info["guarded"], dtype=bool).copy()
        self.no_sword = _no_sword_best(venv, ~self.guarded)
        self.sword_t = np.full(n, -1, dtype=np.int64)
        self.enemy_t = np.full(n, -1, dtype=np.int64)

    def mark(self, events: np.ndarray, live: np.ndarray, t: int) -> None:
        """Note the live episodes' first sword pick-up and first enemy met at step t."""
        mask = np.zeros(len(self.sword_t), dtype=bool)
        mask[live] = True
        _mark_events(events, mask, t, self.sword_t, self.enemy_t)

    def add_to(self, out: ScoredEpisodes) -> None:
        """Append the wave's per-episode level figures to ``out``."""
        picked = self.sword_t >= 0
        out.optimal_return += self.optimal.tolist()
        out.guarded += self.guarded.tolist()
        out.took_sword += picked.tolist()
        out.sword_first += (picked & ((self.enemy_t < 0) | (self.sword_t < self.enemy_t))).tolist()
        out.no_sword_best += self.no_sword.tolist()


def play_episodes(
    act: Callable[[np.ndarray], np.ndarray],
    make_venv: Callable[[int], Any],
    episodes: int,
    seed: int,
    batch: int = 64,
    max_steps: int = 100_000,
) -> Finished:
    """Play ``episodes`` whole episodes in waves of at most ``batch`` sub-envs.

    Episode k is played from ``reset(seed=seed + k)``. ``act`` maps a batch of
    observations to actions; ``make_venv(n)`` builds a batched env of n.
    Results are in episode order: :func:`play_scored` without its level scores.
    """
    done = play_scored(
        lambda obs, _venv: act(obs), make_venv, episodes, seed, batch, max_steps, levels=False
    )
    return Finished(done.returns, done.lengths, done.outcomes)


def _mark_events(
    events: np.ndarray, live: np.ndarray, t: int, sword_t: np.ndarray, enemy_t: np.ndarray
) -> None:
    """Record the step of the first picked(sword) and of the first meeting with an enemy."""
    from neurosym.envs import rgw_rules as R

    ev = np.asarray(events)
    met = R.EV_DEFEATED | R.EV_HURT | R.EV_BUMP_ENEMY | R.EV_KILLED
    first_sword = live & (sword_t < 0) & ((ev & R.EV_PICKED) != 0)
    first_enemy = live & (enemy_t < 0) & ((ev & met) != 0)
    sword_t[first_sword] = t
    enemy_t[first_enemy] = t


def _no_sword_best(venv: Any, rows: np.ndarray) -> np.ndarray:
    """(n,) best return without the sword of each sub-env's current level where ``rows`` (else NaN)."""
    from neurosym.envs import rgw_rules as R
    from neurosym.envs.rgw_solver import solve_levels

    env = getattr(venv, "unwrapped", venv)
    best = np.full(len(rows), np.nan)
    if not rows.any():
        return best
    cells, starts = env.current_levels()
    cells = np.where(cells[rows] == R.SWORD, np.uint8(R.EMPTY), cells[rows])
    best[rows] = solve_levels(cells, starts[rows], env.height, env.width, env.rules).optimal_return
    return best


def _share(mask: np.ndarray, of: np.ndarray) -> float | None:
    """Share of ``mask`` among the episodes in ``of``; None when there are none."""
    return float(mask[of].mean()) if of.any() else None


@dataclass(frozen=True)
class LevelScores:
    """The level-aware figures (module docstring); on envs whose levels report their optimum."""

    optimal_rate: float | None
    mean_optimal_return: float
    guarded_episodes: int
    sword_first_guarded: float | None
    decoy_episodes: int
    no_detour_decoy: float | None
    sword_taken_decoy: float | None


@dataclass(frozen=True)
class Scores:
    """The figures of played episodes: what ``neurosym eval`` and ``neurosym play`` report."""

    mean_return: float
    std_return: float
    min_return: float
    max_return: float
    success_rate: float
    mean_length: float
    outcomes: dict[str, int]
    """episodes per outcome, by outcome name"""
    levels: LevelScores | None = None
    """None on envs whose levels do not report their optimum (Box-World)"""

    def as_dict(self) -> dict[str, Any]:
        """Plain values under ``--json``'s names, in its order (level figures flattened in)."""
        return {
            "mean_return": self.mean_return,
            "std_return": self.std_return,
            "min_return": self.min_return,
            "max_return": self.max_return,
            "success_rate": self.success_rate,
            **(asdict(self.levels) if self.levels is not None else {}),
            "mean_length": self.mean_length,
            "outcomes": dict(self.outcomes),
        }


def scores_of(done: ScoredEpisodes) -> Scores:
    """The :class:`Scores` of :func:`play_scored`'s episodes."""
    from neurosym.agent.rollout import SUCCESS_OUTCOMES

    returns = np.asarray(done.returns, dtype=float)
    levels = level_scores(done)
    return Scores(
        mean_return=float(returns.mean()),
        std_return=float(returns.std()),
        min_return=float(returns.min()),
        max_return=float(returns.max()),
        success_rate=float(np.mean([o in SUCCESS_OUTCOMES for o in done.outcomes])),
        mean_length=float(np.mean(done.lengths)),
        outcomes=dict(sorted(Counter(done.outcomes).items())),
        levels=LevelScores(**levels) if levels else None,
    )


def level_scores(done: ScoredEpisodes) -> dict[str, Any]:
    """The level-aware figures of :func:`play_scored`'s episodes (module docstring); {} where
    no level reports its optimum."""
    returns = np.asarray(done.returns, dtype=float)
    optimal = np.asarray(done.optimal_return, dtype=float)
    known = ~np.isnan(optimal)
    if not known.any():
        return {}
    guarded = np.asarray(done.guarded, dtype=bool)
    decoy = known & ~guarded
    reached = np.asarray([o == "terminal" for o in done.outcomes])
    no_sword = np.asarray(done.no_sword_best, dtype=float)
    no_detour = reached & (returns >= np.nan_to_num(no_sword, nan=np.inf) - TOLERANCE)
    return {
        "optimal_rate": _share(returns >= optimal - TOLERANCE, known),
        "mean_optimal_return": float(optimal[known].mean()),
        "guarded_episodes": int((known & guarded).sum()),
        "sword_first_guarded": _share(np.asarray(done.sword_first, dtype=bool), known & guarded),
        "decoy_episodes": int(decoy.sum()),
        "no_detour_decoy": _share(no_detour, decoy),
        "sword_taken_decoy": _share(np.asarray(done.took_sword, dtype=bool), decoy),
    }


@dataclass(frozen=True)
class Evaluation:
    """An agent's :func:`evaluate`: what was played, and its :class:`Scores`."""

    checkpoint: str | None
    env: str
    env_kwargs: dict[str, Any]
    module: str
    episodes: int
    greedy: bool
    seed: int
    scores: Scores
    trained_frames: int | None

    def as_dict(self) -> dict[str, Any]:
        """Plain values: what ``neurosym eval --json`` prints, in its order."""
        return {
            "checkpoint": self.checkpoint,
            "env": self.env,
            "env_kwargs": self.env_kwargs,
            "module": self.module,
            "episodes": self.episodes,
            "greedy": self.greedy,
            "seed": self.seed,
            **self.scores.as_dict(),
            "trained_frames": self.trained_frames,
        }


def evaluate(
    agent: Any,
    env: str | None = None,
    episodes: int = 100,
    greedy: bool = True,
    seed: int = 0,
    env_kwargs: dict[str, Any] | None = None,
) -> Evaluation:
    """Play ``episodes`` episodes of ``agent`` (episode k from ``reset(seed=seed + k)``).

    ``env``: any env of the agent's family with its observation shape
    (default: its own); ``env_kwargs``: options on top (e.g. ``{"map": path}``).
    ``greedy=False`` samples actions with a torch generator seeded with ``seed``.
    """
    import torch

    from neurosym.agent.agent import env_for
    from neurosym.errors import ConfigError
    from neurosym.seeds import check_seed

    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
        raise ConfigError(f"--episodes must be a positive integer, got {episodes!r}")
    check_seed(seed, episodes)
    env, kwargs = env_for(agent, env, env_kwargs)
    generator = None if greedy else torch.Generator().manual_seed(seed)
    scores = score(
        lambda obs, _venv: agent.act(obs, greedy=greedy, generator=generator)[0],
        env,
        episodes,
        seed,
        kwargs,
    )
    return Evaluation(
        checkpoint=agent.path,
        env=env,
        env_kwargs=kwargs,
        module=agent.config.module,
        episodes=episodes,
        greedy=greedy,
        seed=seed,
        scores=scores,
        trained_frames=agent.meta.get("frames"),
    )


def score(
    act: Any, env: str, episodes: int, seed: int = 0, env_kwargs: dict[str, Any] | None = None
) -> Scores:
    """Play and score ``episodes`` episodes of a policy ``act(obs, venv) -> actions`` on ``env``.

    Any policy, e.g. a scripted one in tests; the env is made batched with ``env_kwargs``.
    """
    from neurosym.envs import make_batched

    done = play_scored(
        act,
        lambda n: make_batched(env, n, seed=seed, **dict(env_kwargs or {})),
        episodes,
        seed,
    )
    return scores_of(done)

