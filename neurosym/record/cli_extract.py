"""``neurosym extract``: record episodes, extract the R-vector facts, write the KB, print answers.

    neurosym extract --checkpoint ckpt.pt [--env rgw2] [--map FILE] [--episodes 20] [--seed 0]
        [--greedy|--sample] [--actions agent|random] [--threshold quantile:0.9|abs:0.5|z:2] [--out DIR]
        [--format pl,parquet] [--qlf] [--no-faithfulness] [--verbose]

Writes into ``--out`` (default ``kb_out/<env>``):

* ``kb.pl`` (format ``pl``) -- the knowledge base; with ``--qlf`` also ``kb.qlf``
  and its signature ``kb.qlf.sig`` beside it;
* ``facts/<predicate>.parquet`` (format ``parquet``) -- the same fact tables;
* ``recording/`` -- the Recording itself, for ``neurosym plot --recording``.

Unless ``--no-faithfulness``, the KB also holds ``faithfulness/5``: how much of the
agent's next objects and actions its relation facts predict on held-out episodes,
beside world facts, an untrained network's relation facts on the same states and
chance (:mod:`neurosym.record.faithfulness`); the report prints them in one table.

The products are written beside the previous ones and published together
by one rename (:mod:`neurosym.publish`), so a failed or killed run writes
nothing, a reader never sees half a KB or a KB beside another run's
recording, and a second run into the same ``--out`` is refused while one
is writing. A product the run does not make (``kb.qlf`` without ``--qlf``)
is removed with the previous run's others, and so is a page ``neurosym report``
wrote into ``--out`` (``index.html``: it describes the previous run). A checkpoint that cannot be read, or that cannot play
``--env`` (another env family or observation shape), is refused before
anything is recorded; any env of its family with its shape is fine.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

from neurosym.cli import env_choice
from neurosym.errors import ConfigError
from neurosym.flags import ActionMode, EnvChoice, Episodes, Out, Quiet, add_options, option

FORMATS = ("pl", "parquet")

@dataclass(kw_only=True)
class ExtractOptions(EnvChoice, Episodes, ActionMode, Out, Quiet):
    """``neurosym extract``'s options."""

    checkpoint: str = option(metavar="FILE")
    """trained agent: a checkpoint (.pt) or a shipped agent's name, FILE.py:FUNCTION (your PyTorch module) or a Stable-Baselines3 .zip"""
    actions: Literal["agent", "random"] = "agent"
    """who chooses the actions: the agent, or uniformly random draws seeded by each episode's
    seed (the network still runs on every state, so its facts are extracted;
    kb_meta(actions, random))"""
    threshold: str | None = option(None, metavar="SPEC", shown="quantile:0.9")
    """per-relation threshold for holds/5: quantile:Q, abs:X or z:K"""
    # an agent with the fact bottleneck (relation_bits=tau) defaults to abs:tau: the bits its
    # policy read (extraction.model_threshold)
    format: str = option("pl", metavar="LIST")
    """comma-separated outputs: pl, parquet"""
    qlf: bool = False
    """also compile the KB to kb.qlf (fast loading)"""
    batch: int | None = option(None, metavar="B", shown="64")
    """environments stepped together"""
    top_keys: int | None = option(None, metavar="N", shown="1")
    """MHDPA only: keep each query cell's N strongest keys as attention/6 facts"""
    faithfulness: bool = True
    """measure how much of the agent's next objects and actions the relation facts predict on
    held-out episodes, beside world facts and an untrained network's relation facts on the
    same states (faithfulness/5; it records the episodes a second time)"""
    verbose: bool = False
    """print the full report: episodes, fact counts, thresholds, relation tables, every answer"""
    episodes: int = 20
    """episodes to record"""
    out: str | None = option(None, metavar="DIR", shown="kb_out/<env>")
    """output folder"""


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the extract options."""
    add_options(parser, ExtractOptions)


def parse_formats(text: str) -> tuple[str, ...]:
    """``"pl,parquet"`` -> ("pl", "parquet"); one-line ConfigError for anything else."""
    parts = tuple(dict.fromkeys(p.strip().lower() for p in text.split(",") if p.strip()))
    bad = [p for p in parts if p not in FORMATS]
    if bad or not parts:
        raise ConfigError(
            f"bad --format {text!r}: expected a comma-separated list of {', '.join(FORMATS)}"
        )
    return parts


def run(args: ExtractOptions) -> int:
    """Validate, record, extract, write, then print the summary and the rule answers."""
    from neurosym.agent.agent import env_for, load_agent
    from neurosym.facts.thresholds import parse_threshold
    from neurosym.publish import check_out
    from neurosym.record.extraction import (
        check_extract_options,
        check_top_keys,
        extract,
        write_outputs,
    )

    formats = parse_formats(args.format)
    if args.threshold is not None:
        parse_threshold(args.threshold)  # a bad spec is refused before the agent is read
    check_extract_options(args.episodes, args.seed, args.batch, args.top_keys)
    agent = load_agent(args.checkpoint, play_env=args.env)
    check_top_keys(agent, args.top_keys)
    env, overrides = env_choice(args, agent.env_name)
    env, env_kwargs = env_for(agent, env, overrides)
    # checked here, once, before anything is recorded: the default folder needs the env
    out = check_out(Path(args.out) if args.out else Path("kb_out") / env)
    show = not args.quiet
    got = extract(
        agent, env, env_kwargs, episodes=args.episodes, seed=args.seed, greedy=args.greedy,
        threshold=args.threshold, batch=args.batch, top_keys=args.top_keys,
        actions=args.actions, progress=show and _tty(), faithfulness=args.faithfulness,
    )  # fmt: skip
    written = write_outputs(out, got.recording, got.facts, formats, qlf=args.qlf)
    if show:
        from neurosym.reports.terminal import print_report

        print_report(
            got.recording, got.facts, written, kb=written.get("kb.pl"), verbose=args.verbose,
            faithfulness=got.faithfulness,
        )  # fmt: skip
    return 0


def _tty() -> bool:
    import sys

    return sys.stderr.isatty()
