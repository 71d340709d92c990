"""``neurosym play``: a strategy file plays the env; the figures of ``neurosym eval``.

Each step the live state's facts go into SWI-Prolog as data, the strategy's
``goal(E, T, Object)`` (first answer) names the object to go for and
rules/route.pl's ``route/4`` the action (:mod:`neurosym.play.agent`).
Episode k is played from ``reset(seed=seed + k)``, as ``neurosym eval`` plays
it, and scored by the same code, so the two reports compare line by line;
``--json`` prints one object with eval's names plus ``fallbacks``,
``fallback_steps``, ``goals``, ``steps`` and ``steps_per_s``. ``--map FILE``
plays a map of one's own on a fixed-map RGW env (``--env rgw1`` or ``rgw2``,
default rgw2), as eval, extract and report do.

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
from dataclasses import dataclass

from neurosym.cli import map_option, parse_env_options
from neurosym.flags import EnvChoice, Episodes, Json, add_options, option


@dataclass(kw_only=True)
class PlayOptions(EnvChoice, Episodes, Json):
    """``neurosym play``'s options."""

    policy: str = option(metavar="FILE")
    """strategy file defining goal(E, T, Object) (neurosym induce strategy)"""
    checkpoint: str | None = option(None, metavar="FILE")
    """the agent whose relation facts the strategy reads (features: relations or both)"""
    kb: str | None = option(None, metavar="FILE")
    """the KB the strategy was learned from: its threshold/2 decides which relations hold
    (holds/5) when the strategy file has none"""
    env: str | None = option(None, shown="the checkpoint's")
    """environment, e.g. rgw-random or bw2"""
    env_option: list[str] = option(factory=list)
    """an option of the env, e.g. num_mountains=12 on rgw-random (repeatable)"""
    json: bool = False
    """print one JSON object"""


def configure(parser: argparse.ArgumentParser) -> None:
    add_options(parser, PlayOptions)


def run(args: PlayOptions) -> int:
    from neurosym.errors import ConfigError
    from neurosym.play.evaluate import score_strategy

    env, overrides = map_option(args.env, args.map, args.env or "rgw2")
    if env is None and args.checkpoint is None:
        raise ConfigError("give the env to play (--env NAME, e.g. rgw-random)")
    checkpoint = None
    if args.checkpoint is not None:
        from neurosym.shipped import checkpoint_file

        checkpoint = checkpoint_file(args.checkpoint)
    options = parse_env_options(args.env_option, env)
    if overrides:
        if "map" in options:
            raise ConfigError("give the map once: --map FILE or --env-option map=FILE, not both")
        options = {**overrides, **options}
    if checkpoint is not None:
        import torch

        torch.set_num_threads(1)
    report = score_strategy(
        args.policy, env, args.episodes, args.seed, options, checkpoint=checkpoint, kb=args.kb
    )
    if args.json:
        print(json.dumps(report))
        return 0
    print_report(report)
    return 0


def print_report(report: dict) -> None:
    """The report for people: eval's figure lines, then fallbacks and speed."""
    from neurosym.display import plain
    from neurosym.reports.terminal import print_figures

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
