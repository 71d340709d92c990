"""``neurosym extract``: record episodes, extract the R-vector facts, write the KB, print answers.

    neurosym extract --checkpoint ckpt.pt [--env rgw2] [--map FILE] [--episodes 20] [--seed 0]
        [--greedy|--sample] [--actions agent|random] [--threshold quantile:0.9|abs:0.5|z:2] [--out DIR]
        [--format pl,parquet] [--qlf] [--verbose]

Writes into ``--out`` (default ``kb_out/<env>``):

* ``kb.pl`` (format ``pl``) -- the knowledge base; with ``--qlf`` also ``kb.qlf``
  and its signature ``kb.qlf.sig`` beside it;
* ``facts/<predicate>.parquet`` (format ``parquet``) -- the same fact tables;
* ``recording/`` -- the Recording itself, for ``neurosym plot --recording``.

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
from typing import Any, Literal

from neurosym.cli import play_options
from neurosym.errors import ConfigError
from neurosym.flags import ActionMode, EnvChoice, Episodes, Out, Quiet, add_options, option
from neurosym.seeds import check_seed

FORMATS = ("pl", "parquet")
_FACTS = {"attends": "attends/8", "relations": "relation/7 and holds/5", "attention": "attention/6"}
"""a recording table's fact predicates, for messages"""
PRODUCTS = ("kb.pl", "kb.qlf", "kb.qlf.sig", "facts", "recording")
"""what an extract run writes into --out; one run's set replaces the previous run's"""

REPORT_PAGE = "index.html"
"""the page ``neurosym report`` writes into --out: it describes the run it was built from, so
a new run removes it in the step that publishes the new products"""

_PAGE_MARK = b"<title>neurosym report: "


@dataclass(kw_only=True)
class ExtractOptions(EnvChoice, Episodes, ActionMode, Out, Quiet):
    """``neurosym extract``'s options."""

    checkpoint: str = option(metavar="FILE")
    """trained agent (.pt)"""
    actions: Literal["agent", "random"] = "agent"
    """who chooses the actions: the agent, or uniformly random draws seeded by each episode's
    seed (the network still runs on every state, so its facts are extracted;
    kb_meta(actions, random))"""
    threshold: str | None = option(None, metavar="SPEC", shown="quantile:0.9")
    """per-relation threshold for holds/5: quantile:Q, abs:X or z:K"""
    # an agent with the fact bottleneck (relation_bits=tau) defaults to abs:tau: the bits its
    # policy read (model_threshold)
    format: str = option("pl", metavar="LIST")
    """comma-separated outputs: pl, parquet"""
    qlf: bool = False
    """also compile the KB to kb.qlf (fast loading)"""
    batch: int | None = option(None, metavar="B", shown="64")
    """environments stepped together"""
    top_keys: int | None = option(None, metavar="N", shown="1")
    """MHDPA only: keep each query cell's N strongest keys as attention/6 facts"""
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
    from neurosym.export.thresholds import parse_threshold

    formats = parse_formats(args.format)
    if args.threshold is not None:
        parse_threshold(args.threshold)  # a bad spec is refused before the agent is read
    if args.episodes < 1:
        raise ConfigError(f"--episodes must be at least 1, got {args.episodes}")
    check_seed(args.seed, args.episodes)
    if args.batch is not None and args.batch < 1:
        raise ConfigError(f"--batch must be at least 1, got {args.batch}")
    if args.top_keys is not None and args.top_keys < 1:
        raise ConfigError(f"--top-keys must be at least 1, got {args.top_keys}")

    from neurosym.agent.checkpoint import env_for, load_agent
    from neurosym.agent.networks.adapters import adapter_class
    from neurosym.export.facts import extract_facts
    from neurosym.export.recorder import record
    from neurosym.publish import check_out

    agent = load_agent(args.checkpoint)
    threshold = parse_threshold(args.threshold or model_threshold(agent.config))
    adapter = adapter_class(agent.config.module)
    if args.top_keys is not None and not adapter.has("attention"):
        facts = " and ".join(_FACTS[name] for name in adapter.tables if name in _FACTS)
        raise ConfigError(
            f"--top-keys is for MHDPA checkpoints (attention/6 facts); {args.checkpoint} is a "
            f"{agent.config.module} (its facts are {facts})"
        )
    env, overrides = play_options(args, agent.env_name)
    env, env_kwargs = env_for(agent, env, overrides)
    # checked here, once: the default folder needs the checkpoint's env
    out = check_out(Path(args.out) if args.out else Path("kb_out") / env)
    show = not args.quiet
    rec = record(
        agent,
        env,
        episodes=args.episodes,
        seed=args.seed,
        greedy=args.greedy,
        batch=args.batch,
        progress=show and _tty(),
        top_keys=args.top_keys or 1,
        env_kwargs=env_kwargs,
        actions=args.actions,
    )
    facts = extract_facts(rec, threshold=threshold)
    written = write_outputs(out, rec, facts, formats, qlf=args.qlf)
    if show:
        from neurosym.export.report import print_report

        print_report(rec, facts, written, kb=written.get("kb.pl"), verbose=args.verbose)
    return 0


def model_threshold(config: Any) -> str:
    """The holds/5 threshold an agent's KB is written with by default: ``abs:tau`` for the fact
    bottleneck (ModelConfig.relation_bits, so the KB's holds/5 are the bits its policy read),
    else quantile:0.9."""
    from neurosym.agent.networks.predinet import bits_threshold
    from neurosym.export.facts import DEFAULT_THRESHOLD

    tau = bits_threshold(getattr(config, "relation_bits", None))
    return DEFAULT_THRESHOLD if tau is None else f"abs:{tau!r}"


def _tty() -> bool:
    import sys

    return sys.stderr.isatty()


def write_outputs(
    out: Path, rec: Any, facts: Any, formats: tuple[str, ...], qlf: bool = False
) -> dict[str, Path]:
    """Write the products into ``out`` through :func:`neurosym.publish.publish`.

    Only neurosym's own names (kb.pl, kb.qlf, kb.qlf.sig, facts/, recording/)
    change in ``out``, all in one step; a killed run leaves the previous
    products as they were. Returns name -> final path.
    """
    from neurosym.publish import publish

    def write(stage: Path) -> None:
        if "pl" in formats:
            facts.to_prolog(stage / "kb.pl", qlf=qlf)
        if "parquet" in formats:
            facts.to_parquet(stage / "facts")
        rec.save(stage / "recording")

    stale = (REPORT_PAGE,) if is_report_page(out / REPORT_PAGE) else ()
    return publish(out, write, owned=PRODUCTS + stale)


def is_report_page(path: Path) -> bool:
    """Whether ``path`` is a page ``neurosym report`` wrote: its published link, or a regular
    file whose head has the page's title (another tool's index.html is left alone)."""
    import os

    from neurosym.atomic import file_kind
    from neurosym.publish import CURRENT, STORE

    if path.is_symlink():
        return os.readlink(path) == f"{STORE}/{CURRENT}/{path.name}"
    if file_kind(path) is not None or not path.is_file():
        return False
    try:
        with open(path, "rb") as page:
            return _PAGE_MARK in page.read(4096)
    except OSError:
        return False
