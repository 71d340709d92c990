"""What goes on the page, gathered from a recording, its facts, its KB and the optional folders.

:func:`report_context` is the whole page's data; :func:`load_extract` reads the
folder ``neurosym extract --out DIR`` wrote; :func:`write_report` renders and
writes ``index.html``.

A page never disagrees with the KB it sits beside: it carries the identity of
the recording and KB it was built from (:func:`identity`, a hash of
``recording/meta.json`` and ``kb.pl``, in ``<meta name="neurosym-recording">``);
beside a published extract it is published with them, as one product of the
same run (:func:`write_beside`), so it is written only by ``neurosym report``
and only for the KB it describes; :func:`stale_page` tells a page built from
another recording.
"""

from __future__ import annotations

import hashlib
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from neurosym.agent.networks.adapters import adapter_class, module_has
from neurosym.errors import ConfigError, NeurosymError
from neurosym.record.recording import Recording

PAGE = "index.html"
IDENTITY = re.compile(rb'<meta name="neurosym-recording" content="([0-9a-f]{16})">')
"""the page's identity tag (in its first bytes, see report.html.j2)"""
IDENTITY_BYTES = 1024


@dataclass(frozen=True)
class Extract:
    """What ``neurosym extract --out DIR`` wrote, read from one published run."""

    rec: Recording
    facts: Any
    kb_path: Path | None
    folder: Path
    """the folder the page goes in by default (the extract folder, or the recording's parent)"""
    identity: str
    """:func:`identity` of the recording and KB read"""


def identity(rec_dir: Path, kb_path: Path | None) -> str:
    """16 hex digits of the SHA-256 of ``rec_dir/meta.json`` and ``kb_path`` (when there is one).

    meta.json names the checkpoint, env, seed and the second it was recorded;
    kb.pl holds every fact the page's rule answers come from: a re-extract
    changes one of them, so a page's identity tells whether it is the KB's.
    """
    digest = hashlib.sha256()
    for path in (rec_dir / "meta.json", kb_path):
        digest.update(b"\0")
        if path is not None:
            with path.open("rb") as fh:
                for block in iter(lambda fh=fh: fh.read(1 << 20), b""):
                    digest.update(block)
    return digest.hexdigest()[:16]


def page_identity(page: Path) -> str | None:
    """The identity a report page carries; None for no page, or one without it."""
    try:
        with page.open("rb") as fh:
            head = fh.read(IDENTITY_BYTES)
    except OSError:
        return None
    found = IDENTITY.search(head)
    return found.group(1).decode("ascii") if found else None


def stale_page(folder: Path, current: str) -> str | None:
    """Why ``folder/index.html`` is not the page of the recording and KB ``current`` names; None
    when it is (or there is no page)."""
    page = folder / PAGE
    if not page.is_file():
        return None
    found = page_identity(page)
    if found is None:
        return f"{page} carries no recording identity (an older neurosym wrote it)"
    if found != current:
        return f"{page} was built from another recording or KB than the one beside it"
    return None


def check_page_meta(meta: dict[str, Any], where: str) -> None:
    """Refuse, in one line naming the field, a recording meta the page cannot be built from.

    meta.json is a file a colleague may have edited: plain data of bounded
    size (:func:`~neurosym.agent.checkpoint.check_plain_data`), whole numbers
    where the page counts (heads and relations: :func:`neurosym.record.recording.check_meta`,
    which :meth:`Recording.load` applies first; the seed), names where it names.
    """
    from neurosym.agent.checkpoint import check_plain_data
    from neurosym.record.recording import check_meta

    check_plain_data(meta, where, error=ConfigError)
    check_meta(meta, where)
    seed = meta.get("seed")
    if seed is not None and (not isinstance(seed, int) or isinstance(seed, bool) or seed < 0):
        raise ConfigError(f"{where} has seed {seed!r}; it must be a whole number, 0 or more")
    for key in ("env", "module", "checkpoint"):
        value = meta.get(key)
        if value is not None and not isinstance(value, str):
            raise ConfigError(f"{where} has {key} {value!r}; it must be text")


def _strongest_note(rec: Recording, facts: Any) -> str:
    module = rec.meta.get("module")
    if module_has(module, "attention"):
        return (
            f"{adapter_class(module).label} computes no relation values: attention/6 holds the "
            "strongest key of every query cell, drawn in the player above."
        )
    if facts["relation"].empty:
        return "The recording holds no relation values."
    return "None held above threshold between two different object types."


def _title(meta: dict[str, Any]) -> tuple[str, str]:
    name = Path(str(meta.get("checkpoint") or "recording")).name
    module = str(meta.get("module"))
    shape = f"{module}, {meta.get('heads')} heads"
    if module_has(module, "relations"):
        shape += f", {meta.get('relations')} relations"
    return f"{name} on {meta.get('env')}", shape


def report_context(
    rec: Recording,
    facts: Any,
    kb_path: Path | None,
    card: dict[str, Any],
    probes: dict[str, Any] | None = None,
    experiments: dict[str, Any] | None = None,
    source: str = "",
    identity: str = "",
) -> dict[str, Any]:
    """The template's context: tables for the page and ``data`` for the player's JSON.

    ``identity``: :func:`identity` of the recording and KB, carried by the page.
    """
    from neurosym import __version__
    from neurosym.envs import env_family
    from neurosym.reports.terminal import RULE_FILES
    from neurosym.reports.web.page import HEAD_COLOURS
    from neurosym.reports.web.player import entity_styles, finite, names_in, player_data
    from neurosym.reports.web.tables import (
        episode_rows,
        faithfulness_rows,
        head_rows,
        rule_rows,
        strongest_rows,
    )
    from neurosym.viz.style import legend_text

    meta = rec.meta
    family = env_family(str(meta.get("env")))
    player = player_data(rec)
    names = names_in(player)
    thresholds = {int(j): float(v) for j, v in facts.thresholds().items()}
    episodes = episode_rows(rec)
    rules = rule_rows(kb_path, family, {int(e["episode"]) for e in episodes})
    title, shape = _title(meta)
    mode = "greedy" if meta.get("greedy", True) else "sampled"
    rule_files = RULE_FILES[family]
    kb_name = kb_path.name if kb_path is not None else "kb.pl"
    query = f"neurosym query --kb {kb_name} " + " ".join(f"--rules rules/{f}" for f in rule_files)
    return {
        "title": title,
        "subtitle": f"{shape} · {len(episodes)} episodes ({mode}, seed {meta.get('seed')})",
        "module": player["module"],
        "relations": player["relations"] if module_has(player["module"], "relations") else 0,
        "player_heads": [
            {"head": h, "colour": HEAD_COLOURS[i % len(HEAD_COLOURS)]}
            for i, h in enumerate(player["heads"])
        ],
        "legend": legend_text(names),
        "card": card,
        "episodes": episodes,
        "episode_note": f"{mode} actions, episode k played from seed {meta.get('seed')} + k.",
        "heads": head_rows(rec),
        "strongest": strongest_rows(facts),
        "strongest_note": _strongest_note(rec, facts),
        "thresholds": thresholds,
        "threshold_spec": str(facts.threshold),
        "faithfulness": faithfulness_rows(facts, kb_path),
        "rules": rules,
        "rule_files": rule_files,
        "query_example": f"{query} 'GOAL'",
        "rules_note": (
            "No rule answers: they need the Prolog KB (kb.pl) beside the recording and the "
            "repository's rules/ folder."
        ),
        "probes": probes,
        "experiments": experiments,
        "version": __version__,
        "source": source,
        "identity": identity,
        "recorded": str(meta.get("created") or "at an unrecorded time"),
        "data": {
            "player": player,
            "entities": entity_styles(names),
            "head_colours": list(HEAD_COLOURS),
            "thresholds": {str(j): finite(v) for j, v in thresholds.items()},
        },
    }


def recording_folder(path: Path) -> tuple[Path, Path]:
    """(the recording's folder, the extract folder) for ``--recording`` given either of them."""
    if (path / "meta.json").is_file():
        return path, path.parent
    if (path / "recording" / "meta.json").is_file():
        return path / "recording", path
    raise ConfigError(
        f"--recording {path} holds no recording: give the folder `neurosym extract --out` "
        "wrote (with recording/ and kb.pl) or its recording/ folder"
    )


def threshold_of(folder: Path, kb_path: Path | None) -> str | None:
    """The threshold spec the extract used: facts/kb_meta.parquet, else the KB's kb_meta/2."""
    import pandas as pd

    table = folder / "facts" / "kb_meta.parquet"
    if table.is_file():
        meta = pd.read_parquet(table)
        found = meta.loc[meta["key"].astype(str) == "threshold", "value"]
        if len(found):
            return str(found.iloc[0])
    if kb_path is None:
        return None
    from neurosym.prolog.knowledge_base import KnowledgeBase

    with KnowledgeBase(kb_path) as kb:
        row = kb.once("kb_meta(threshold, X), format(atom(T), '~w', [X])")
    return None if row is None else str(row["T"])


def load_agent_or_note(
    path: str | None, rec_meta: dict[str, Any] | None = None
) -> tuple[Any | None, str | None]:
    """The checkpoint a recording names, loaded for its card; (None, why) when it cannot be.

    ``rec_meta``: the recording's meta; a checkpoint of another env family,
    module or head count than the one recorded (meta.json edited, or the
    file replaced since) is not that agent: its card is not shown.
    """
    if not path:
        return None, "The recording names no checkpoint."
    if not Path(path).is_file():
        return (
            None,
            f"The checkpoint {path} the recording names is not at hand: its card is partial.",
        )
    from neurosym.agent.agent import load_agent

    try:
        agent = load_agent(path, play_env=(rec_meta or {}).get("env"))
    except NeurosymError as exc:
        return None, f"The checkpoint {path} could not be read ({exc}): its card is partial."
    differs = _other_agent(agent, rec_meta or {})
    if differs:
        return None, (
            f"The checkpoint {path} the recording names is not the agent recorded "
            f"({differs}): its card is not shown."
        )
    return agent, None


def _other_agent(agent: Any, rec_meta: dict[str, Any]) -> str:
    """How ``agent`` differs from the one ``rec_meta`` recorded ('' when it does not)."""
    from neurosym.envs import env_family

    recorded = str(rec_meta.get("env"))
    try:
        theirs = env_family(recorded)
    except NeurosymError:
        theirs = None
    mine = env_family(agent.env_name)
    diffs = []
    if theirs != mine:
        diffs.append(
            f"it was trained on {agent.env_name}, a {mine} env; the recording is of {recorded}"
        )
    config = agent.config
    for key, value in (("module", config.module), ("heads", config.heads)):
        if key in rec_meta and rec_meta[key] != value:
            diffs.append(f"its {key} is {value}, the recording's {rec_meta[key]}")
    if module_has(config.module, "relations") and rec_meta.get("module") == config.module:
        if "relations" in rec_meta and rec_meta["relations"] != config.relations:
            diffs.append(
                f"its relations are {config.relations}, the recording's {rec_meta['relations']}"
            )
    return "; ".join(diffs)


def load_extract(path: Path, threshold: str | None = None) -> Extract:
    """The extract folder at ``path`` (or its recording/), facts at the extract's threshold."""
    from neurosym.facts.tables import DEFAULT_THRESHOLD, extract_facts
    from neurosym.publish import published

    rec_dir, folder = recording_folder(path)
    target = folder
    # Every product from one published run (a run published meanwhile cannot give a mix).
    if rec_dir == folder / "recording":
        folder = published(folder)
        rec_dir = folder / "recording"
    else:
        rec_dir = rec_dir.resolve()
        folder = rec_dir.parent
    rec = Recording.load(rec_dir)
    check_page_meta(rec.meta, f"{path}: its recording's meta.json")
    kb = folder / "kb.pl"
    kb_path = kb if kb.is_file() else None
    spec = threshold or threshold_of(folder, kb_path) or DEFAULT_THRESHOLD
    facts = extract_facts(rec, threshold=spec)
    return Extract(rec, facts, kb_path, target, identity(rec_dir, kb_path))


def write_report(out: Path, context: dict[str, Any]) -> Path:
    """Render the page for ``context`` and write ``out/index.html`` atomically."""
    from neurosym.reports.web.page import render, write_page

    out.mkdir(parents=True, exist_ok=True)
    return write_page(out / PAGE, render(context))


def write_beside(extract: Extract, context: dict[str, Any]) -> Path:
    """Write the page beside the recording and KB it was built from.

    Beside a published extract (:mod:`neurosym.publish`) the page is published
    as a product of a new run that carries the same KB and recording, under
    the folder's lock: if another extract was published while the page was
    built, nothing is written (one line: run the report again). A folder of
    the older layout gets the page written atomically.
    """
    from neurosym.publish import STORE, publish, published
    from neurosym.reports.web.page import render

    folder = extract.folder
    if not (folder / STORE).is_dir():
        return write_report(folder, context)
    html = render(context)

    def write(run: Path) -> None:
        now = published(folder)
        kb = now / "kb.pl"
        if identity(now / "recording", kb if kb.is_file() else None) != extract.identity:
            raise ConfigError(
                f"{folder} was extracted again while its report was built; nothing was "
                f"written: run `neurosym report --recording {folder}` again"
            )
        (run / PAGE).write_text(html, encoding="utf-8")

    return publish(folder, write, owned=(PAGE,))[PAGE]
