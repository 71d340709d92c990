"""``neurosym play``: a strategy file plays the env; the figures of ``neurosym eval``.

Each step the live state's facts go into SWI-Prolog as data, the strategy's
``goal(E, T, Object)`` (first answer) names the object to go for and
rules/route.pl's ``route/4`` the action (:mod:`neurosym.play.agent`).
Episode k is played from ``reset(seed=seed + k)``, as ``neurosym eval`` plays
it, and scored by the same code, so the two reports compare line by line;
``--json`` prints one object with eval's names plus ``fallback``, ``fallbacks``,
``fallback_steps``, ``deciders``, ``decider_shares``, ``goals``, ``steps`` and
``steps_per_s``. ``--map FILE``
plays a map of one's own on a fixed-map RGW env (``--env rgw1`` or ``rgw2``,
default rgw2), as eval, extract and report do.

A state the strategy leaves undecided (goal/3 has no answer, route/4 no path
to its object, or the episode was in this very state before) goes to the
fallback: with ``--fallback default`` route.pl's default_goal/3, then
safe_step/3, then ``up`` decide it; with ``--fallback none`` nothing does and
the episode ends there as a failure (its outcome the cause: ``no_goal``,
``no_route`` or ``loop``; that step counts in its length, reward 0). The
report says what decided the steps (``decided by``; ``--json``:
``deciders`` and ``decider_shares``). ``--compare trivial,handwritten`` plays
the same levels with shipped strategies of the env's family (trivial: RGW
``goal(_, _, terminal).``, Box-World the gem; handwritten: route.pl's
knowledge written as a strategy) or strategy files of one's own, under the
same fallback, and prints one table (``--json``: ``compare``).

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
from pathlib import Path
from typing import Literal

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
    fallback: Literal["default", "none"] = "default"
    """what decides a state the strategy leaves undecided (goal/3 has no answer, route/4 no
    path to its object, or a state seen before): default, route.pl's default_goal/3, then
    safe_step/3, then up; none, nothing: the episode ends there as a failure, its outcome
    no_goal, no_route or loop"""
    compare: str | None = option(None, metavar="LIST")
    """also play the same levels with these strategies, comma-separated, and print one table:
    trivial (RGW goal(_, _, terminal), Box-World the gem, Minigrid the goal), handwritten (shipped for the env's
    family) or strategy files"""
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
    names = compare_names(args.compare)
    report = score_strategy(
        args.policy, env, args.episodes, args.seed, options, checkpoint=checkpoint, kb=args.kb,
        fallback=args.fallback,
    ).as_dict()  # fmt: skip
    if names:
        report["compare"] = {
            name: score_strategy(
                compare_file(name, report["env"]),
                report["env"],
                args.episodes,
                args.seed,
                report["env_kwargs"],
                fallback=args.fallback,
                refuse_undecided=False,
            ).as_dict()  # fmt: skip
            for name in names
        }
    if args.json:
        print(json.dumps(report))
        return 0
    print_report(report)
    if names:
        print_compare(report)
    return 0


SHIPPED = ("trivial", "handwritten")
"""the shipped strategies ``--compare`` names: neurosym/play/strategies/<family>_<name>.pl"""


def compare_names(text: str | None) -> list[str]:
    """``--compare``'s names in order, each once; ConfigError (one line) for an empty one."""
    from neurosym.errors import ConfigError

    if text is None:
        return []
    names = [n.strip() for n in text.split(",")]
    if not all(names):
        raise ConfigError(
            f"--compare {text!r}: give strategies separated by commas, e.g. trivial,handwritten"
        )
    return list(dict.fromkeys(names))


def compare_file(name: str, env: str) -> Path:
    """The strategy file a ``--compare`` name stands for: a shipped one of the env's family
    (rgw*, bw*) for trivial and handwritten, else the name as a path."""
    from neurosym.errors import ConfigError

    if name not in SHIPPED:
        return Path(name)
    from neurosym.envs.registration import env_family

    try:
        family = env_family(env)
    except ConfigError:
        family = None
    if family is None:
        raise ConfigError(
            f"--compare {name}: neurosym ships {' and '.join(SHIPPED)} strategies for rgw*, bw* "
            f"and Minigrid envs, not {env}; give a strategy file instead"
        )
    return Path(__file__).with_name("strategies") / f"{family}_{name}.pl"


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
    undecided = "ended" if report["fallback"] == "none" else "fallbacks"
    print(
        f"{undecided:<12} {fallbacks} of {steps} steps ({share}){f': {causes}' if causes else ''}"
    )
    shares = ", ".join(f"{k} {100 * v:.1f} %" for k, v in report["decider_shares"].items() if v)
    print(f"decided by   {shares or 'nothing'}")
    print(f"speed        {report['steps_per_s']:.0f} steps/s")


def print_compare(report: dict) -> None:
    """One table: the strategy and each ``--compare`` one on the same levels."""
    from neurosym.display import plain

    rows = [(Path(report["policy"]).name, report)] + list(report["compare"].items())
    width = max(12, *(len(plain(name)) for name, _ in rows))
    print()
    print(
        f"{'strategy':<{width}} {'success':>8} {'optimal':>8} {'return':>7} "
        f"{'by goal/3':>9} {'fallback':>8} {'ended':>7} {'steps/s':>8}"
    )
    for name, r in rows:
        shares = r["decider_shares"]
        fallback = shares["default_goal"] + shares["safe_step"] + shares["up"]
        optimal = r.get("optimal_rate")
        print(
            f"{plain(name):<{width}} {_pct(r['success_rate']):>8} "
            f"{_pct(optimal) if optimal is not None else '-':>8} {r['mean_return']:>7.2f} "
            f"{_pct(shares['strategy']):>9} {_pct(fallback):>8} {_pct(shares['none']):>7} "
            f"{r['steps_per_s']:>8.0f}"
        )
    print(
        f"(same {report['episodes']} levels from seed {report['seed']}, fallback {report['fallback']}; "
        "by goal/3, fallback, ended: shares of steps)"
    )


def _pct(x: float) -> str:
    return f"{100 * x:.1f} %"
