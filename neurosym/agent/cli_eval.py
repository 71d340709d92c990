"""``neurosym eval``: mean return, success rate and outcome counts of a checkpoint.

Episode k is played from ``reset(seed=seed + k)`` on the env the checkpoint
was trained on (with its env options); episodes run side by side in batches.
``--sample`` draws actions from the policy with a torch generator seeded with
``--seed``; ``--greedy`` (the default) takes the most likely action.
"""

from __future__ import annotations

import argparse
import json
from collections import Counter
from typing import Any

from neurosym.cli import add_action_mode
from neurosym.errors import ConfigError


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--checkpoint", required=True, help="checkpoint file (.pt) written by neurosym train"
    )
    parser.add_argument(
        "--env", help="environment to evaluate on; must be the checkpoint's (default: it)"
    )
    parser.add_argument("--episodes", type=int, default=100, help="episodes to play (100)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the first episode (0)")
    add_action_mode(parser)
    parser.add_argument("--json", action="store_true", help="print one JSON object")


def evaluate(
    agent: Any, env: str, episodes: int, greedy: bool = True, seed: int = 0
) -> dict[str, Any]:
    """Play ``episodes`` episodes of ``agent``; a dict of plain values (what --json prints)."""
    import numpy as np
    import torch

    from neurosym.agent.rollout import SUCCESS_OUTCOMES, play_episodes
    from neurosym.envs import make_batched

    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
        raise ConfigError(f"--episodes must be a positive integer, got {episodes!r}")
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise ConfigError(f"--seed must be a non-negative integer, got {seed!r}")
    generator = None if greedy else torch.Generator().manual_seed(seed)
    done = play_episodes(
        lambda obs: agent.act(obs, greedy=greedy, generator=generator)[0],
        lambda n: make_batched(env, n, seed=seed, **agent.env_kwargs),
        episodes,
        seed,
    )
    returns = np.asarray(done.returns)
    return {
        "checkpoint": agent.path,
        "env": env,
        "module": agent.config.module,
        "episodes": episodes,
        "greedy": greedy,
        "seed": seed,
        "mean_return": float(returns.mean()),
        "std_return": float(returns.std()),
        "min_return": float(returns.min()),
        "max_return": float(returns.max()),
        "success_rate": float(np.mean([o in SUCCESS_OUTCOMES for o in done.outcomes])),
        "mean_length": float(np.mean(done.lengths)),
        "outcomes": dict(sorted(Counter(done.outcomes).items())),
        "trained_frames": agent.meta.get("frames"),
    }


def run(args: argparse.Namespace) -> int:
    import torch

    from neurosym.agent.checkpoint import load_agent

    torch.set_num_threads(1)
    agent = load_agent(args.checkpoint, env=args.env)
    report = evaluate(agent, agent.env_name, args.episodes, args.greedy, args.seed)
    if args.json:
        print(json.dumps(report))
        return 0
    outcomes = ", ".join(f"{k} {v}" for k, v in report["outcomes"].items())
    print(
        f"checkpoint   {report['checkpoint']} ({report['env']}, {report['module']}, {report['trained_frames']:,} frames)"
    )
    print(
        f"episodes     {report['episodes']} ({'greedy' if report['greedy'] else 'sampled'}, seed {report['seed']})"
    )
    print(f"mean return  {report['mean_return']:.3f} (std {report['std_return']:.3f})")
    print(f"success      {100 * report['success_rate']:.1f} %")
    print(f"mean length  {report['mean_length']:.1f} steps")
    print(f"outcomes     {outcomes}")
    return 0
