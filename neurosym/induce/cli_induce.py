"""``neurosym induce``: learn rules back from a knowledge base.

    neurosym induce --kb KB.pl --what world --out world.pl [--holdout KB2.pl]

``--what world`` learns, for every event of the env's vocabulary that the KB
shows, ``predicts(E, T, Event)`` clauses over the state facts and the action
(:mod:`neurosym.induce.world`), prints per event its clauses, train
precision/recall, held-out precision/recall with ``--holdout`` and whether
it is solved perfectly (precision and recall 1.0 held out), and writes the
clauses as a Prolog file that loads beside a KB of other episodes.
Events the KB cannot decide are reported as undetermined, not guessed.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path

from neurosym.errors import ConfigError


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the induce options."""
    parser.add_argument(
        "--kb", required=True, metavar="FILE", help="knowledge base (.pl) to learn from"
    )
    parser.add_argument(
        "--what", required=True, metavar="WHAT", help=f"what to learn: {', '.join(WHATS)}"
    )
    parser.add_argument("--out", required=True, metavar="FILE", help="learned rules (.pl) to write")
    parser.add_argument(
        "--holdout", metavar="FILE", help="a KB of other episodes to score the learned rules on"
    )


def run(args: argparse.Namespace) -> int:
    """Dispatch on --what."""
    learner = WHATS.get(args.what)
    if learner is None:
        raise ConfigError(f"--what {args.what!r} is not one of {', '.join(WHATS)}")
    for name in ("kb", "holdout"):
        path = getattr(args, name)
        if path is not None and not Path(path).is_file():
            raise ConfigError(
                f"--{name} {path} does not exist (give a KB written by neurosym extract)"
            )
    return learner(args)


def run_world(args: argparse.Namespace) -> int:
    """Learn world rules, print them with their scores, write them."""
    from neurosym.atomic import check_target
    from neurosym.induce.world import induce_world

    check_target(args.out)  # refused before the learning, not after
    rules = induce_world(args.kb, holdout=args.holdout)
    out = rules.write(args.out)
    print(
        f"learned from {rules.kb} (env {rules.env or '?'}, {rules.episodes} episodes, "
        f"{rules.states} acted states) in {rules.seconds:.1f} s"
        + (
            f"; held out: {rules.holdout} ({rules.holdout_episodes} episodes)"
            if rules.holdout
            else ""
        )
    )
    determined = solved = 0
    for sc in rules.scores.values():
        if sc.status != "determined":
            print(f"{sc.event}: undetermined ({sc.reason})")
            continue
        determined += 1
        line = (
            f"{sc.event}: {len(sc.clauses)} clause(s); train precision {_f(sc.train_precision)} "
            f"recall {_f(sc.train_recall)} ({sc.train_examples} examples)"
        )
        if sc.holdout_examples is not None:
            line += (
                f"; held-out precision {_f(sc.holdout_precision)} recall {_f(sc.holdout_recall)} "
                f"({sc.holdout_examples} examples)"
            )
            solved += sc.solved
            line += "; solved perfectly" if sc.solved else "; not solved perfectly"
        print(line)
        for clause in sc.clauses:
            print("  " + " ".join(part.strip() for part in clause.text().splitlines()))
    summary = f"{determined} of {len(rules.scores)} events determined"
    if rules.holdout:
        summary += f", {solved} of them solved perfectly on the held-out KB"
    print(summary)
    print(f"wrote {out}")
    return 0


def _f(x: float | None) -> str:
    return "-" if x is None else f"{x:.3f}"


WHATS: dict[str, Callable[[argparse.Namespace], int]] = {"world": run_world}
"""--what -> the function that learns and writes it"""
