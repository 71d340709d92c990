"""The report pipeline as library functions: a page from a recording, or from an agent.

:func:`report_recording` reports a folder ``neurosym extract`` wrote (beside its KB, or into
``out``); :func:`report_agent` records an agent as extract does and writes extract's products
plus the page into ``out``, all published in one step. Both return a :class:`ReportPage`;
``neurosym report`` is a thin wrapper over them.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any


@dataclass(frozen=True)
class ReportPage:
    """A page written: where, what it describes, and a note when the folder's own page is stale."""

    path: Path
    source: str
    stale: str | None = None
    """the reported folder's own page describes another run (``out`` was given)"""
    folder: Path | None = None
    """the recording's folder (a page from a recording)"""


def report_recording(
    folder: str | Path,
    out: str | Path | None = None,
    *,
    threshold: str | None = None,
    probes: dict[str, Any] | None = None,
    experiments: dict[str, Any] | None = None,
) -> ReportPage:
    """The page of a recording folder (extract's ``--out``, or its ``recording/``), written
    beside its KB or into ``out``. ``probes``/``experiments``: the sections of
    :mod:`neurosym.reports.web.extras` (``probe_section``, ``intervene_section``)."""
    from neurosym.reports.web.build import (
        load_agent_or_note,
        load_extract,
        report_context,
        stale_page,
        write_beside,
        write_report,
    )
    from neurosym.reports.web.card import agent_card

    extract = load_extract(Path(folder), threshold)
    rec = extract.rec
    agent, note = load_agent_or_note(rec.meta.get("checkpoint"), rec.meta)
    card = agent_card(rec.meta, agent, note)
    source = f"the recording in {extract.folder}"
    context = report_context(
        rec, extract.facts, extract.kb_path, card, probes, experiments,
        source=source, identity=extract.identity,
    )  # fmt: skip
    if out is None:
        return ReportPage(write_beside(extract, context), source, folder=extract.folder)
    stale = stale_page(extract.folder, extract.identity)
    return ReportPage(write_report(Path(out), context), source, stale, extract.folder)


def report_agent(
    agent: Any,
    env: str | None = None,
    env_kwargs: dict[str, Any] | None = None,
    out: str | Path | None = None,
    *,
    episodes: int = 20,
    seed: int = 0,
    greedy: bool = True,
    batch: int | None = None,
    top_keys: int | None = None,
    threshold: str | None = None,
    probes: dict[str, Any] | None = None,
    experiments: dict[str, Any] | None = None,
    source: str | None = None,
) -> ReportPage:
    """Record ``agent`` (a loaded Agent or a checkpoint path) as extract does and write its
    products (kb.pl, recording/) and the page into ``out`` (default ``kb_out/<env>``).
    ``source``: how the page names the agent (default: its path)."""
    from neurosym.agent.agent import env_for, load_agent
    from neurosym.publish import check_out, publish
    from neurosym.record.extraction import extract
    from neurosym.reports.web.build import identity, report_context
    from neurosym.reports.web.card import agent_card
    from neurosym.reports.web.page import render

    if isinstance(agent, str | Path):
        agent = load_agent(agent)
    env, env_kwargs = env_for(agent, env, env_kwargs)
    folder = check_out(Path(out) if out is not None else Path("kb_out") / env)
    got = extract(
        agent, env, env_kwargs, episodes=episodes, seed=seed, greedy=greedy, batch=batch,
        top_keys=top_keys, threshold=threshold,
    )  # fmt: skip
    rec, facts = got.recording, got.facts
    card = agent_card(rec.meta, agent)
    source = source if source is not None else f"{agent.path}"

    def write(stage: Path) -> None:
        facts.to_prolog(stage / "kb.pl")
        rec.save(stage / "recording")
        context = report_context(
            rec, facts, stage / "kb.pl", card, probes, experiments, source=source,
            identity=identity(stage / "recording", stage / "kb.pl"),
        )  # fmt: skip
        (stage / "index.html").write_text(render(context), encoding="utf-8")

    written = publish(folder, write, folders=("recording",), prefix=".report-")
    return ReportPage(written["index.html"], source)
