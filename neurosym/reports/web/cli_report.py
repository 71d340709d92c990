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
    from neurosym.reports.web.pages import report_recording

    page = report_recording(
        args.recording, args.out, threshold=args.threshold, probes=probes, experiments=experiments
    )
    if page.stale and not args.quiet:
        print(
            f"note: {page.stale}; `neurosym report --recording {page.folder}` rebuilds it",
            file=sys.stderr,
        )
    return page.path


def _from_checkpoint(args: ReportOptions, probes: Any, experiments: Any) -> Path:
    from neurosym.agent.agent import load_agent
    from neurosym.reports.web.pages import report_agent

    agent = load_agent(args.checkpoint, play_env=args.env)
    env, overrides = env_choice(args, agent.env_name)
    page = report_agent(
        agent, env, overrides, args.out, episodes=20 if args.episodes is None else args.episodes,
        seed=args.seed or 0, greedy=args.greedy, batch=args.batch, top_keys=args.top_keys,
        threshold=args.threshold, probes=probes, experiments=experiments,
        source=f"{args.checkpoint}",
    )  # fmt: skip
    return page.path
