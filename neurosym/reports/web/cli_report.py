"""``neurosym report``: one self-contained HTML page about an agent, opened from disk.

    neurosym report --checkpoint ckpt.pt [--env rgw2] [--map FILE] [--env-option K=V]
        [--episodes 20] [--seed 0] [--greedy|--sample] [--threshold quantile:0.9]
        [--probe DIR] [--intervene DIR] [--out DIR]
    neurosym report --recording DIR [--probe DIR] [--intervene DIR] [--out DIR]

With ``--checkpoint`` it records episodes as ``neurosym extract`` does and
writes, into ``--out`` (default ``kb_out/<env>``), what extract writes
(``kb.pl``, ``recording/``) plus ``index.html``; everything is staged first
and moved in by one rename each (:mod:`neurosym.publish`). With
``--recording`` it reports a folder extract wrote (or its ``recording/``
folder) and publishes ``index.html`` there beside the KB it was built from
(or writes it into ``--out``, saying so when the folder's own page is stale).
The page carries the identity of its recording and KB
(:func:`neurosym.reports.web.build.identity`). The checkpoint the recording
names gives the card only when it is the agent recorded (env family, module,
heads).
``--probe`` and ``--intervene`` add the tables of the folders ``neurosym
probe`` and ``neurosym intervene`` wrote.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from neurosym.cli import env_choice
from neurosym.errors import ConfigError
from neurosym.flags import ActionMode, EnvChoice, Episodes, Out, Quiet, add_options, option
from neurosym.publish import check_out

CHECKPOINT_ONLY = ("env", "map", "episodes", "seed", "batch", "top_keys")


@dataclass(kw_only=True)
class ReportOptions(EnvChoice, Episodes, ActionMode, Out, Quiet):
    """``neurosym report``'s options."""

    checkpoint: str | None = option(None, metavar="FILE", exclusive="source", required_one=True)
    """trained agent: a checkpoint (.pt) or a shipped agent's name, FILE.py:FUNCTION (your PyTorch module) or a Stable-Baselines3 .zip, to record"""
    recording: str | None = option(None, metavar="DIR", exclusive="source")
    """report the folder `neurosym extract --out DIR` wrote"""
    threshold: str | None = option(None, metavar="SPEC")
    """threshold for holds/5: quantile:Q, abs:X or z:K (default: the extract's, else
    quantile:0.9)"""
    batch: int | None = option(None, metavar="B", hidden=True)
    top_keys: int | None = option(None, metavar="N", shown="1")
    """MHDPA: keep each query cell's N strongest keys"""
    probe: str | None = option(None, metavar="DIR")
    """add the probes `neurosym probe --out DIR` wrote"""
    intervene: str | None = option(None, metavar="DIR")
    """add the experiments `neurosym intervene --out DIR` wrote"""
    episodes: int | None = option(None, shown="20")
    """episodes to record"""
    seed: int | None = option(None, shown="0")
    out: str | None = option(None, metavar="DIR")
    """output folder (default: --recording's folder, or kb_out/<env> with --checkpoint)"""


def configure(parser: argparse.ArgumentParser) -> None:
    """Add the report options."""
    add_options(parser, ReportOptions)


def _extras(args: ReportOptions) -> tuple[dict[str, Any] | None, dict[str, Any] | None]:
    """The probe and experiment sections, read before anything is recorded (bad folders fail fast)."""
    from neurosym.reports.web.extras import intervene_section, probe_section

    probes = probe_section(Path(args.probe)) if args.probe else None
    experiments = intervene_section(Path(args.intervene)) if args.intervene else None
    return probes, experiments


def _check(args: ReportOptions) -> None:
    if args.recording is not None:
        given = [name for name in CHECKPOINT_ONLY if getattr(args, name) is not None]
        given += ["env_option"] if args.env_option else []
        if given:
            flags = ", ".join("--" + g.replace("_", "-") for g in given)
            raise ConfigError(
                f"{flags} go(es) with --checkpoint; a recording is reported as recorded"
            )
        return
    for name, low in (("episodes", 1), ("seed", 0), ("batch", 1), ("top_keys", 1)):
        value = getattr(args, name)
        if value is not None and value < low:
            flag = "--" + name.replace("_", "-")
            raise ConfigError(f"{flag} must be at least {low}, got {value}")


def run(args: ReportOptions) -> int:
    """Validate, then report a recording or record the checkpoint and report it."""
    _check(args)
    if args.out is not None:
        check_out(Path(args.out))
    if args.threshold is not None:
        from neurosym.facts.thresholds import parse_threshold

        parse_threshold(args.threshold)
    probes, experiments = _extras(args)
    if args.recording is not None:
        page = _from_recording(args, probes, experiments)
    else:
        page = _from_checkpoint(args, probes, experiments)
    if not args.quiet:
        print(f"wrote {page}")
    return 0


def _from_recording(args: ReportOptions, probes: Any, experiments: Any) -> Path:
    from neurosym.reports.web.build import (
        load_agent_or_note,
        load_extract,
        report_context,
        stale_page,
        write_beside,
        write_report,
    )
    from neurosym.reports.web.card import agent_card

    extract = load_extract(Path(args.recording), args.threshold)
    rec = extract.rec
    agent, note = load_agent_or_note(rec.meta.get("checkpoint"), rec.meta)
    card = agent_card(rec.meta, agent, note)
    context = report_context(
        rec, extract.facts, extract.kb_path, card, probes, experiments,
        source=f"the recording in {extract.folder}", identity=extract.identity,
    )  # fmt: skip
    if args.out is None:
        return write_beside(extract, context)
    stale = stale_page(extract.folder, extract.identity)
    if stale and not args.quiet:
        print(
            f"note: {stale}; `neurosym report --recording {extract.folder}` rebuilds it",
            file=sys.stderr,
        )
    return write_report(Path(args.out), context)


def _from_checkpoint(args: ReportOptions, probes: Any, experiments: Any) -> Path:
    from neurosym.agent.agent import env_for, load_agent
    from neurosym.publish import publish
    from neurosym.record.extraction import extract
    from neurosym.reports.web.build import identity, report_context
    from neurosym.reports.web.card import agent_card
    from neurosym.reports.web.page import render

    agent = load_agent(args.checkpoint, play_env=args.env)
    env, overrides = env_choice(args, agent.env_name)
    env, env_kwargs = env_for(agent, env, overrides)
    out = Path(args.out) if args.out else Path("kb_out") / env
    check_out(out)
    got = extract(
        agent, env, env_kwargs, episodes=20 if args.episodes is None else args.episodes,
        seed=args.seed or 0, greedy=args.greedy, batch=args.batch, top_keys=args.top_keys,
        threshold=args.threshold,
    )  # fmt: skip
    rec, facts = got.recording, got.facts
    card = agent_card(rec.meta, agent)

    def write(stage: Path) -> None:
        facts.to_prolog(stage / "kb.pl")
        rec.save(stage / "recording")
        context = report_context(
            rec, facts, stage / "kb.pl", card, probes, experiments, source=f"{args.checkpoint}",
            identity=identity(stage / "recording", stage / "kb.pl"),
        )  # fmt: skip
        (stage / "index.html").write_text(render(context), encoding="utf-8")

    written = publish(out, write, folders=("recording",), prefix=".report-")
    return written["index.html"]
