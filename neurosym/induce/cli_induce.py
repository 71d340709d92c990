"""``neurosym induce``: learn rules back from a knowledge base.

    neurosym induce world --kb KB.pl --out world.pl [--holdout KB2.pl]
    neurosym induce strategy --kb KB.pl --out strategy.pl [--features world|relations|both]
                    [--holdout KB2.pl | --holdout-share 0.3] [--learner best|tree|covering]

``induce world`` learns, for every event of the env's vocabulary that the KB
shows, ``predicts(E, T, Event)`` clauses over the state facts and the action
(:mod:`neurosym.induce.world`), prints per event its clauses, train
precision/recall, held-out precision/recall with ``--holdout`` and whether
it is solved perfectly (precision and recall 1.0 held out), and writes the
clauses as a Prolog file that loads beside a KB of other episodes.
Events the KB cannot decide are reported as undetermined, not guessed.

``induce strategy`` learns which object the agent goes for next, as
``goal(E, T, Object)`` clauses whose first answer is the choice
(:mod:`neurosym.induce.strategy`), prints the clauses and the fidelity (share
of held-out states whose first answer is the labelled next object) and
writes them as a Prolog file that loads in plain swipl beside a KB.

Before any learning the options are checked, each refused in one line: a
flag of ``induce strategy`` given to ``induce world`` (exit 2), an empty ``--out``,
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
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar, Literal

from neurosym.errors import ConfigError
from neurosym.flags import Out, add_options, option, refuse


@dataclass(kw_only=True)
class InduceOptions(Out):
    """What ``neurosym induce world`` and ``neurosym induce strategy`` both take."""

    kb: str = option(metavar="FILE")
    """knowledge base (.pl) to learn from"""
    holdout: str | None = option(None, metavar="FILE")
    """a KB of other episodes to score the learned rules on"""
    out: str = option(metavar="FILE")
    """learned rules (.pl) to write"""


ONLY_STRATEGY = "{flag} belongs to neurosym induce strategy; neurosym induce world does not read it"


@dataclass(kw_only=True)
class WorldOptions(InduceOptions):
    """``neurosym induce world``'s options."""

    what: ClassVar[str] = "world"
    RENAMED: ClassVar[dict[str, str]] = {
        flag: ONLY_STRATEGY.format(flag=flag)
        for flag in ("--features", "--learner", "--holdout-share")
    }


@dataclass(kw_only=True)
class StrategyOptions(InduceOptions):
    """``neurosym induce strategy``'s options."""

    what: ClassVar[str] = "strategy"
    holdout: str | None = option(None, exclusive="held-out")
    holdout_share: float | None = option(None, metavar="S", exclusive="held-out", shown="0.3")
    """without --holdout, score on the last share S of the KB's episodes, learning from the
    rest"""
    features: Literal["world", "relations", "both"] | None = option(None, shown="world")
    """the facts the clauses may read: the world's (at/5, holding/3, ...), the network's
    relations (attends/8, holds/5, attention/6) or both"""
    learner: Literal["best", "tree", "covering"] | None = option(None, shown="best")
    """a scikit-learn decision tree over (state, object) pairs, sequential covering of states,
    or best: both, keeping the higher training fidelity"""


SUBCOMMANDS: dict[str, tuple[type, str]] = {
    "world": (WorldOptions, "Learn the world's rules: predicts(E, T, Event) clauses per event."),
    "strategy": (StrategyOptions, "Learn the agent's strategy: goal(E, T, Object) clauses."),
}


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the induce subcommands, each with its own options."""
    refuse(parser, {"--what": "--what is now a subcommand: neurosym induce world ... or "
                    "neurosym induce strategy ..."})  # fmt: skip
    sub = parser.add_subparsers(dest="what", metavar="WHAT", required=True)
    for name, (cls, help_text) in SUBCOMMANDS.items():
        add_options(sub.add_parser(name, help=help_text, description=help_text), cls)


def run(args: InduceOptions) -> int:
    """Check every option and the output before any learning, then learn what was asked."""
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
    return WHATS[args.what](args)


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


def run_world(args: WorldOptions) -> int:
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


def run_strategy(args: StrategyOptions) -> int:
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


WHATS: dict[str, Callable[[Any], int]] = {
    "world": run_world,
    "strategy": run_strategy,
}
"""subcommand -> the function that learns and writes it"""
