"""``neurosym eval``: mean return, success rate and outcome counts of a checkpoint.

Episode k is played from ``reset(seed=seed + k)`` on the env the checkpoint
was trained on (with its env options), or on ``--env`` (any env of its family
with its observation shape; ``--map FILE`` for a map of one's own); episodes
run side by side in batches. ``--sample`` draws actions from the policy with
a torch generator seeded with ``--seed``; ``--greedy`` (the default) takes
the most likely action.

On Relational-Grid-World the report adds the level-aware figures of
:mod:`neurosym.agent.evaluation`: ``optimal_rate``, ``sword_first_guarded``,
``no_detour_decoy`` (and their episode counts). On rgw-random the level is a
function of the reset seed (and the resets since): episode k plays level
(seed + k, 0). Training's sub-envs play levels (s + i, 0), (s + i, 1), ...
with s below 2**31 (``trainer._env_seed``), so ``--seed 3000000000`` evaluates
on levels no training run has played; the default ``--seed 0`` shares a few
first levels with a run trained with ``--seed 0``.
"""

from __future__ import annotations

import argparse
import json
from collections import Counter
from dataclasses import dataclass
from typing import Any

from neurosym.cli import play_options
from neurosym.errors import ConfigError
from neurosym.flags import ActionMode, EnvChoice, Episodes, Json, add_options, option
from neurosym.seeds import check_seed


@dataclass(kw_only=True)
class EvalOptions(EnvChoice, Episodes, ActionMode, Json):
    """``neurosym eval``'s options."""

    checkpoint: str = option(metavar="FILE")
    """checkpoint file (.pt) written by neurosym train, or a shipped agent's name"""
    json: bool = False
    """print one JSON object"""


def configure(parser: argparse.ArgumentParser) -> None:
    add_options(parser, EvalOptions)


def evaluate(
    agent: Any,
    env: str | None = None,
    episodes: int = 100,
    greedy: bool = True,
    seed: int = 0,
    env_kwargs: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Play ``episodes`` episodes of ``agent``; a dict of plain values (what --json prints).

    ``env``: any env of the agent's family with its observation shape
    (default: its own); ``env_kwargs``: options on top (e.g. ``{"map": path}``).
    """
    import torch

    from neurosym.agent.checkpoint import env_for

    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
        raise ConfigError(f"--episodes must be a positive integer, got {episodes!r}")
    check_seed(seed, episodes)
    env, kwargs = env_for(agent, env, env_kwargs)
    generator = None if greedy else torch.Generator().manual_seed(seed)
    report = score(
        lambda obs, _venv: agent.act(obs, greedy=greedy, generator=generator)[0],
        env,
        episodes,
        seed,
        kwargs,
    )
    return {
        "checkpoint": agent.path,
        "env": env,
        "env_kwargs": kwargs,
        "module": agent.config.module,
        "episodes": episodes,
        "greedy": greedy,
        "seed": seed,
        **report,
        "trained_frames": agent.meta.get("frames"),
    }


def score(
    act: Any, env: str, episodes: int, seed: int = 0, env_kwargs: dict[str, Any] | None = None
) -> dict[str, Any]:
    """Play and score ``episodes`` episodes of a policy ``act(obs, venv) -> actions`` on ``env``.

    The figures of the report (returns, success, lengths, outcomes and, on
    RGW, the level-aware ones); any policy, e.g. a scripted one in tests.
    """
    from neurosym.agent.evaluation import play_scored
    from neurosym.envs import make_batched

    done = play_scored(
        act,
        lambda n: make_batched(env, n, seed=seed, **dict(env_kwargs or {})),
        episodes,
        seed,
    )
    return report_of(done)


def report_of(done: Any) -> dict[str, Any]:
    """The report's figures of played episodes (a :class:`~neurosym.agent.evaluation.ScoredEpisodes`)."""
    import numpy as np

    from neurosym.agent.evaluation import level_scores
    from neurosym.agent.rollout import SUCCESS_OUTCOMES

    returns = np.asarray(done.returns)
    return {
        "mean_return": float(returns.mean()),
        "std_return": float(returns.std()),
        "min_return": float(returns.min()),
        "max_return": float(returns.max()),
        "success_rate": float(np.mean([o in SUCCESS_OUTCOMES for o in done.outcomes])),
        **level_scores(done),
        "mean_length": float(np.mean(done.lengths)),
        "outcomes": dict(sorted(Counter(done.outcomes).items())),
    }


def run(args: EvalOptions) -> int:
    import torch

    from neurosym.agent.checkpoint import load_agent

    torch.set_num_threads(1)
    from neurosym.agent.checkpoint import env_for

    agent = load_agent(args.checkpoint, play_env=args.env)
    env, overrides = play_options(args, agent.env_name)
    env, kwargs = env_for(agent, env, overrides)
    report = evaluate(agent, env, args.episodes, args.greedy, args.seed, kwargs)
    if args.json:
        print(json.dumps(report))
        return 0
    from neurosym.display import plain

    frames = report["trained_frames"]
    print(
        f"checkpoint   {plain(report['checkpoint'])} ({plain(report['env'])}, "
        f"{plain(report['module'])}, {f'{frames:,}' if isinstance(frames, int) else plain(frames)} frames)"
    )
    print(
        f"episodes     {report['episodes']} ({'greedy' if report['greedy'] else 'sampled'}, seed {report['seed']})"
    )
    print_figures(report)
    return 0


def print_figures(report: dict[str, Any]) -> None:
    """The report's figure lines, from mean return to outcomes (``neurosym play`` prints the same)."""
    from neurosym.display import plain

    outcomes = plain(", ".join(f"{k} {v}" for k, v in report["outcomes"].items()))
    print(f"mean return  {report['mean_return']:.3f} (std {report['std_return']:.3f})")
    print(f"success      {100 * report['success_rate']:.1f} %")
    for key, label in (
        ("optimal_rate", "optimal     "),
        ("sword_first_guarded", "sword first "),
        ("no_detour_decoy", "no detour   "),
    ):
        if report.get(key) is not None:
            print(f"{label} {100 * report[key]:.1f} %{_of(report, key)}")
    print(f"mean length  {report['mean_length']:.1f} steps")
    print(f"outcomes     {outcomes}")


def _of(report: dict[str, Any], key: str) -> str:
    """' (of N guarded levels)' for the shares that count only some episodes."""
    if key == "sword_first_guarded":
        return f" (of {report['guarded_episodes']} guarded levels)"
    if key == "no_detour_decoy":
        return f" (of {report['decoy_episodes']} decoy levels)"
    return f" (mean optimal return {report['mean_optimal_return']:.3f})"
