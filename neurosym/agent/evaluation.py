"""Evaluation episodes scored against their levels: optimal return, sword first, no detour.

:func:`play_scored` plays whole episodes with :func:`neurosym.agent.play.play_waves`
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

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from neurosym.agent.play import play_waves
from neurosym.agent.rollout import Finished, outcome_of

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
    batch every step (``act_on="all"`` of :func:`play_waves`). ``levels=False``
    skips the level-aware scoring (its no-sword search costs time at every
    reset): returns, lengths and outcomes only, as the trainer's evaluation wants.
    """
    out = ScoredEpisodes()
    venvs: dict[int, Any] = {}
    waves = play_waves(
        act, lambda n: venvs.setdefault(n, make_venv(n)), episodes, seed, batch,
        act_on="all", max_steps=max_steps,
    )  # fmt: skip
    for wave in waves:
        n, venv = wave.count, wave.venv
        outcome: list[str] = [""] * n
        scores = (
            _LevelScores(venv, wave.info, n) if levels and "optimal_return" in wave.info else None
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


class _LevelScores:
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


def level_scores(done: ScoredEpisodes) -> dict[str, Any]:
    """The level-aware figures of :func:`play_scored`'s episodes (module docstring)."""
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
