"""``neurosym induce``: learn rules back from a knowledge base.

    neurosym induce --kb KB.pl --what world --out world.pl [--holdout KB2.pl]
    neurosym induce --kb KB.pl --what strategy --out strategy.pl [--features world|relations|both]
                    [--holdout KB2.pl | --holdout-share 0.3] [--learner best|tree|covering]

``--what world`` learns, for every event of the env's vocabulary that the KB
shows, ``predicts(E, T, Event)`` clauses over the state facts and the action
(:mod:`neurosym.induce.world`), prints per event its clauses, train
precision/recall, held-out precision/recall with ``--holdout`` and whether
it is solved perfectly (precision and recall 1.0 held out), and writes the
clauses as a Prolog file that loads beside a KB of other episodes.
Events the KB cannot decide are reported as undetermined, not guessed.

``--what strategy`` learns which object the agent goes for next, as
``goal(E, T, Object)`` clauses whose first answer is the choice
(:mod:`neurosym.induce.strategy`), prints the clauses and the fidelity (share
of held-out states whose first answer is the labelled next object) and
writes them as a Prolog file that loads in plain swipl beside a KB.

Before any learning the options are checked, each refused in one line: a
flag of ``--what strategy`` given with ``--what world``, an empty ``--out``,
an ``--out`` that is one of the inputs or a published folder's product
(:func:`neurosym.atomic.refuse_overwrite`) or lies under a file, and a KB
name that is not UTF-8. A learned file is written only when SWI-Prolog
reads it back as exactly the clauses learned (:mod:`neurosym.induce.readback`);
what the command prints passes through :func:`neurosym.display.plain`.
"""

from __future__ import annotations

import argparse
import os
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
    held = parser.add_mutually_exclusive_group()
    held.add_argument(
        "--holdout", metavar="FILE", help="a KB of other episodes to score the learned rules on"
    )
    held.add_argument(
        "--holdout-share",
        type=float,
        metavar="S",
        help="strategy: without --holdout, score on the last share S of the KB's episodes, "
        "learning from the rest (default: 0.3)",
    )
    parser.add_argument(
        "--features",
        choices=("world", "relations", "both"),
        default=None,
        help="strategy: the facts the clauses may read: the world's (at/5, holding/3, ...), "
        "the network's relations (attends/8, holds/5, attention/6) or both (default: world)",
    )
    parser.add_argument(
        "--learner",
        choices=("best", "tree", "covering"),
        default=None,
        help="strategy: a scikit-learn decision tree over (state, object) pairs, sequential "
        "covering of states, or best: both, keeping the higher training fidelity (default: best)",
    )


STRATEGY_FLAGS = {"features": "--features", "learner": "--learner", "holdout_share": "--holdout-share"}
"""options only ``--what strategy`` reads: refused with ``--what world`` rather than ignored"""


def run(args: argparse.Namespace) -> int:
    """Check every option and the output before any learning, then dispatch on --what."""
    learner = WHATS.get(args.what)
    if learner is None:
        raise ConfigError(f"--what {args.what!r} is not one of {', '.join(WHATS)}")
    if args.what != "strategy":
        for name, flag in STRATEGY_FLAGS.items():
            if getattr(args, name, None) is not None:
                raise ConfigError(
                    f"{flag} belongs to --what strategy; --what {args.what} does not read it "
                    "(leave it out)"
                )
    for name in ("kb", "holdout"):
        path = getattr(args, name)
        if path is None:
            continue
        _check_name(f"--{name}", path)
        if not Path(path).is_file():
            raise ConfigError(
                f"--{name} {path} does not exist (give a KB written by neurosym extract)"
            )
    check_out(args.out, [args.kb, args.holdout])
    return learner(args)


def _check_name(flag: str, path: str) -> None:
    """Refuse a file name that is not valid UTF-8: SWI-Prolog (through janus) cannot be given it."""
    try:
        path.encode("utf-8")
    except UnicodeEncodeError:
        raise ConfigError(
            f"{flag} {path}: the file name is not valid UTF-8, which SWI-Prolog cannot open; "
            "rename the file (or link it under a UTF-8 name)"
        ) from None


def check_out(out: str, inputs: list[str | None]) -> Path:
    """Refuse, before the learning, an --out that is empty, not a file, one of the inputs, or
    in a folder that cannot be made (the folders it names are made when the rules are written)."""
    from neurosym.atomic import check_target, refuse_overwrite

    if not out:
        raise ConfigError("--out is empty: give the file to write the learned rules to (a .pl)")
    path = check_target(out)
    refuse_overwrite(path, inputs)
    folder = Path(os.path.abspath(path)).parent
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    if not folder.is_dir():
        raise ConfigError(f"--out {out}: {folder} is not a folder, so the rules cannot be written there")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise ConfigError(f"--out {out}: {folder} is not writable, so the rules cannot be written there")
    return path


def say(text: str) -> None:
    """Print data as text: each line through :func:`neurosym.display.plain` (no raw escapes)."""
    from neurosym.display import plain

    for line in text.splitlines() or [""]:
        print(plain(line))


def run_world(args: argparse.Namespace) -> int:
    """Learn world rules, print them with their scores, write them."""
    from neurosym.induce.world import induce_world

    rules = induce_world(args.kb, holdout=args.holdout)
    out = rules.write(args.out)
    say(
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
            say(f"{sc.event}: undetermined ({sc.reason})")
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
        say(line)
        for clause in sc.clauses:
            say("  " + " ".join(part.strip() for part in clause.text().splitlines()))
    summary = f"{determined} of {len(rules.scores)} events determined"
    if rules.holdout:
        summary += f", {solved} of them solved perfectly on the held-out KB"
    say(summary)
    say(f"wrote {out}")
    return 0


def _f(x: float | None) -> str:
    return "-" if x is None else f"{x:.3f}"


def run_strategy(args: argparse.Namespace) -> int:
    """Learn the agent's next-object strategy, print its clauses and fidelity, write it."""
    from neurosym.induce.strategy import induce_strategy
    from neurosym.induce.strategy_writer import clauses_text

    share = 0.3 if args.holdout_share is None else args.holdout_share
    strategy = induce_strategy(
        args.kb,
        args.features or "world",
        holdout=args.holdout,
        holdout_share=share,
        learner=args.learner or "best",
    )
    out = strategy.write(args.out)
    say(
        f"learned from {strategy.kb} ({strategy.features} features, {strategy.model.learner}) in "
        f"{strategy.seconds:.1f} s: {len(strategy.model.clauses)} clause(s)"
    )
    say(clauses_text(strategy))
    say(
        f"fidelity {strategy.fidelity:.4f} on {strategy.states} held-out states ({strategy.holdout}); "
        f"{strategy.train_fidelity:.4f} on {strategy.train_states} training states"
    )
    say(f"wrote {out}")
    return 0


WHATS: dict[str, Callable[[argparse.Namespace], int]] = {
    "world": run_world,
    "strategy": run_strategy,
}
"""--what -> the function that learns and writes it"""
