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
from dataclasses import dataclass

from neurosym.cli import env_choice
from neurosym.flags import ActionMode, EnvChoice, Episodes, Json, add_options, option


@dataclass(kw_only=True)
class EvalOptions(EnvChoice, Episodes, ActionMode, Json):
    """``neurosym eval``'s options."""

    checkpoint: str = option(metavar="FILE")
    """trained agent: a checkpoint (.pt) or a shipped agent's name, FILE.py:FUNCTION (your PyTorch module) or a Stable-Baselines3 .zip"""
    json: bool = False
    """print one JSON object"""


def configure(parser: argparse.ArgumentParser) -> None:
    add_options(parser, EvalOptions)


def run(args: EvalOptions) -> int:
    """Load, play, print: the figures of :func:`neurosym.agent.evaluation.evaluate`."""
    import torch

    from neurosym.agent.agent import env_for, load_agent
    from neurosym.agent.evaluation import evaluate
    from neurosym.reports.terminal import print_figures

    torch.set_num_threads(1)

    agent = load_agent(args.checkpoint, play_env=args.env)
    env, overrides = env_choice(args, agent.env_name)
    env, kwargs = env_for(agent, env, overrides)
    report = evaluate(agent, env, args.episodes, args.greedy, args.seed, kwargs).as_dict()
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
