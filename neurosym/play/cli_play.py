"""``neurosym play``: a strategy file plays the env; the figures of ``neurosym eval``.

Each step the live state's facts go into SWI-Prolog as data, the strategy's
``goal(E, T, Object)`` (first answer) names the object to go for and
rules/route.pl's ``route/4`` the action (:mod:`neurosym.play.agent`).
Episode k is played from ``reset(seed=seed + k)``, as ``neurosym eval`` plays
it, and scored by the same code, so the two reports compare line by line;
``--json`` prints one object with eval's names plus ``fallbacks``,
``fallback_steps``, ``goals``, ``steps`` and ``steps_per_s``.

A strategy whose ``%! features:`` line says ``relations`` or ``both`` reads
the network's relation facts of the live state: give the agent they came
from with ``--checkpoint`` (its env is then the default ``--env``) and, when
the strategy file has no ``threshold/2``, the KB it was learned from with
``--kb`` (its thresholds decide which relations hold).

A strategy file is read term by term before it loads and refused with one
line naming file and line when it holds what would run code as it loads or
end the process (a directive other than ``dynamic``, ``discontiguous`` or
``use_module(library(Name))``, a load hook, clauses for another module or for
route.pl's predicates, a call of halt, abort, shell, ...); halt or abort
reached at run time is an error. A run in which the strategy chose no
object in any step (every action a fallback: a strategy for another env) is
refused with one line. Ctrl-C stops the run even while the strategy sits in
a blocking call (exit 130).
"""

from __future__ import annotations

import argparse
import json

from neurosym.cli import add_env_option, parse_env_options


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--policy",
        required=True,
        metavar="FILE",
        help="strategy file defining goal(E, T, Object) (neurosym induce --what strategy)",
    )
    parser.add_argument(
        "--env",
        metavar="NAME",
        help="environment, e.g. rgw-random or bw2 (default: the checkpoint's)",
    )
    parser.add_argument(
        "--checkpoint",
        metavar="FILE",
        help="the agent whose relation facts the strategy reads (features: relations or both)",
    )
    parser.add_argument(
        "--kb",
        metavar="FILE",
        help="the KB the strategy was learned from: its threshold/2 decides which relations "
        "hold (holds/5) when the strategy file has none",
    )
    parser.add_argument("--episodes", type=int, default=100, help="episodes to play (100)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the first episode (0)")
    add_env_option(parser)
    parser.add_argument("--json", action="store_true", help="print one JSON object")


def run(args: argparse.Namespace) -> int:
    from neurosym.errors import ConfigError
    from neurosym.play.evaluate import play_policy

    if args.env is None and args.checkpoint is None:
        raise ConfigError("give the env to play (--env NAME, e.g. rgw-random)")
    checkpoint = None
    if args.checkpoint is not None:
        from neurosym.shipped import checkpoint_file

        checkpoint = checkpoint_file(args.checkpoint)
    options = parse_env_options(args.env_option, args.env)
    if checkpoint is not None:
        import torch

        torch.set_num_threads(1)
    report = play_policy(
        args.policy, args.env, args.episodes, args.seed, options, checkpoint=checkpoint, kb=args.kb
    )
    if args.json:
        print(json.dumps(report))
        return 0
    print_report(report)
    return 0


def print_report(report: dict) -> None:
    """The report for people: eval's figure lines, then fallbacks and speed."""
    from neurosym.agent.cli_eval import print_figures
    from neurosym.display import plain

    print(
        f"policy       {plain(report['policy'])} ({plain(report['env'])}, features {report['features']})"
    )
    print(f"episodes     {report['episodes']} (seed {report['seed']})")
    print_figures(report)
    steps = report["steps"]
    fallbacks = report["fallback_steps"]
    causes = ", ".join(f"{k} {v}" for k, v in report["fallbacks"].items())
    share = f"{100 * fallbacks / steps:.1f} %" if steps else "0 %"
    print(f"fallbacks    {fallbacks} of {steps} steps ({share}){f': {causes}' if causes else ''}")
    print(f"speed        {report['steps_per_s']:.0f} steps/s")
