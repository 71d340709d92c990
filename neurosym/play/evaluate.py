"""Play and score a strategy file: the figures of ``neurosym eval``, plus fallbacks and speed.

:func:`score_strategy` plays ``episodes`` episodes (episode k from
``reset(seed=seed + k)``, as ``neurosym eval`` does) with a
:class:`~neurosym.play.agent.PrologAgent` and scores them with the same code
(:func:`neurosym.agent.evaluation.play_scored`,
:func:`neurosym.agent.evaluation.scores_of`), so the two reports compare line by
line under the same names.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from neurosym.errors import ConfigError
from neurosym.seeds import check_seed

if TYPE_CHECKING:
    from neurosym.agent.evaluation import Scores

BATCH = 64
"""episodes played side by side (sub-envs of one batched env)"""


@dataclass(frozen=True)
class StrategyPlay:
    """A strategy's :func:`score_strategy`: what was played, eval's :class:`Scores`, and who
    decided the steps."""

    policy: str
    features: str
    checkpoint: str | None
    env: str
    env_kwargs: dict[str, Any]
    episodes: int
    seed: int
    scores: Scores
    fallback: str
    fallbacks: dict[str, int]
    """undecided steps by cause: no_goal, no_route, loop"""
    deciders: dict[str, int]
    """steps by what decided them: strategy, default_goal, safe_step, up, none"""
    goals: dict[str, int]
    """steps per object chosen"""
    steps: int
    steps_per_s: float | None
    """env steps per second of the whole loop: facts, Prolog, env"""

    def as_dict(self) -> dict[str, Any]:
        """Plain values: what ``neurosym play --json`` prints, in its order."""
        decided = sum(self.deciders.values())
        return {
            "policy": self.policy,
            "features": self.features,
            "checkpoint": self.checkpoint,
            "env": self.env,
            "env_kwargs": self.env_kwargs,
            "episodes": self.episodes,
            "seed": self.seed,
            **self.scores.as_dict(),
            "fallback": self.fallback,
            "fallbacks": dict(self.fallbacks),
            "fallback_steps": int(sum(self.fallbacks.values())),
            "deciders": dict(self.deciders),
            "decider_shares": {
                d: n / decided if decided else 0.0 for d, n in self.deciders.items()
            },
            "goals": dict(self.goals),
            "steps": self.steps,
            "steps_per_s": self.steps_per_s,
        }


def score_strategy(
    policy: str | os.PathLike[str],
    env: str | None = None,
    episodes: int = 100,
    seed: int = 0,
    env_kwargs: dict[str, Any] | None = None,
    checkpoint: str | os.PathLike[str] | None = None,
    batch: int = BATCH,
    kb: str | os.PathLike[str] | None = None,
    fallback: str = "default",
    refuse_undecided: bool = True,
) -> StrategyPlay:
    """Play ``episodes`` episodes of the strategy ``policy`` on ``env``.

    ``checkpoint``: the network whose relation facts the strategy reads
    (needed for ``features: relations`` or ``both``); its env is the default
    ``env``; ``kb``: the KB the strategy was learned from, whose
    ``threshold/2`` sets which relations hold (when the strategy file has
    none). ``fallback``: what decides a state the strategy leaves undecided
    (:data:`~neurosym.play.agent.FALLBACKS`: ``default``, route.pl's
    default_goal/3, safe_step/3, up; ``none``, nothing: the episode ends as a
    failure, its outcome the cause). ``refuse_undecided``: ConfigError when the strategy
    chose nothing in any step (:func:`check_decided`; off for the strategies a run is compared
    with, whose failing everywhere is a figure). ``.as_dict()`` has the keys of ``neurosym
    eval --json`` that do not describe a network (mean_return ... outcomes), plus ``policy``,
    ``features``, ``fallback``, ``fallbacks``, ``fallback_steps``, ``deciders``,
    ``decider_shares`` (the deciders as shares of all steps), ``goals``, ``steps`` and
    ``steps_per_s``.
    """
    from neurosym.agent.evaluation import play_scored, scores_of
    from neurosym.envs import canonical_name
    from neurosym.play.agent import DECIDERS, PrologAgent
    from neurosym.play.policy import read_policy
    from neurosym.prolog.interrupt import sigint_region

    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
        raise ConfigError(f"--episodes must be a positive integer, got {episodes!r}")
    check_seed(seed, episodes)
    check_file_name(policy, "--policy")
    spec = read_policy(policy)
    network = None
    if checkpoint is not None:
        check_file_name(checkpoint, "--checkpoint")
        from neurosym.agent.agent import env_for, load_agent

        network = load_agent(checkpoint)
        env, env_kwargs = env_for(network, env, env_kwargs)
    if env is None:
        raise ConfigError("give the env to play (--env NAME, e.g. rgw-random)")
    env = canonical_name(env)
    kwargs = dict(env_kwargs or {})
    thresholds = kb_thresholds(kb) if kb is not None else None
    # One SIGINT handler for the whole play: each Prolog call only marks itself (interrupt.py).
    with (
        sigint_region(),
        PrologAgent(spec, network, thresholds=thresholds, fallback=fallback) as agent,
    ):
        start = time.perf_counter()
        done = play_scored(
            agent.act,
            lambda n: agent.make_venv(env, n, seed, **kwargs),
            episodes,
            seed,
            batch,
        )
        seconds = time.perf_counter() - start
        if refuse_undecided:
            check_decided(agent, env)
        steps = int(sum(done.lengths))
        return StrategyPlay(
            policy=str(spec.path),
            features=spec.features,
            checkpoint=str(checkpoint) if checkpoint is not None else None,
            env=env,
            env_kwargs=kwargs,
            episodes=episodes,
            seed=seed,
            scores=scores_of(done),
            fallback=fallback,
            fallbacks=dict(sorted(agent.fallbacks.items())),
            deciders={d: agent.deciders[d] for d in DECIDERS},
            goals=dict(sorted(agent.goals.items())),
            steps=steps,
            steps_per_s=steps / seconds if seconds > 0 else None,
        )


MAX_RELATIONS = 1 << 16
"""the largest relation index a KB's threshold/2 may name"""


def kb_thresholds(kb: str | os.PathLike[str]) -> dict[int, float]:
    """Relation j -> threshold of a KB's ``threshold/2`` facts; ConfigError (one line) when it
    has none, or one that is not ``threshold(J, V)`` with J a relation index and V a number >= 0."""
    import math

    from neurosym.prolog.interrupt import interruptible
    from neurosym.prolog.knowledge_base import KnowledgeBase

    check_file_name(kb, "--kb")
    with interruptible(), KnowledgeBase(kb) as base:
        rows = base.query("current_predicate(threshold/2), threshold(J, V)")
    if not rows:
        raise ConfigError(
            f"{kb} holds no threshold/2 facts, which say when a relation holds: --kb must be "
            "the KB the strategy was learned from, as neurosym extract writes it"
        )
    out: dict[int, float] = {}
    for r in rows:
        j, v = r["J"], r["V"]
        if not (
            isinstance(j, int) and 0 <= j < MAX_RELATIONS
            and isinstance(v, int | float) and math.isfinite(v) and v >= 0
        ):  # fmt: skip
            raise ConfigError(
                f"{kb}: threshold({_short(j)}, {_short(v)}) is not threshold(J, V) with J a "
                f"relation index (0 to {MAX_RELATIONS - 1}) and V a number >= 0, as neurosym "
                "extract writes it"
            )
        out[j] = float(v)
    return out


def _short(value: Any) -> str:
    text = str(value)
    return text if len(text) <= 40 else text[:37] + "..."


def check_file_name(path: str | os.PathLike[str], option: str) -> None:
    """ConfigError (one line) for a file name that is not UTF-8: SWI-Prolog cannot take it."""
    try:
        os.fsencode(path).decode("utf-8")
    except UnicodeDecodeError:
        raise ConfigError(
            f"{option} {os.fsdecode(path)!r}: the file name is not UTF-8, which SWI-Prolog "
            "needs; rename the file"
        ) from None


def check_decided(agent: Any, env: str) -> None:
    """ConfigError (one line) when the strategy chose no object in any step: every action was
    a fallback, so the figures would be route.pl's default strategy, not the strategy's."""
    if agent.decisions and not agent.chosen:
        causes = ", ".join(f"{k} {v}" for k, v in sorted(agent.fallbacks.items()))
        raise ConfigError(
            f"{agent.policy.path} chose no object it could reach in any of the "
            f"{agent.decisions} steps on {env} (fallbacks: {causes}); is it a strategy for "
            "another env (its goal/3 names objects this env's levels do not hold)?"
        )
