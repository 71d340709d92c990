"""What goes on the page, gathered from a recording, its facts, its KB and the optional folders.

:func:`report_context` is the whole page's data; :func:`load_extract` reads the
folder ``neurosym extract --out DIR`` wrote; :func:`write_report` renders and
writes ``index.html``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from neurosym.errors import ConfigError, NeurosymError
from neurosym.export.recording import Recording


def _strongest_note(rec: Recording, facts: Any) -> str:
    if str(rec.meta.get("module")) == "mhdpa":
        return (
            "MHDPA computes no relation values: attention/6 holds the strongest key of every "
            "query cell, drawn in the player above."
        )
    if facts["relation"].empty:
        return "The recording holds no relation values."
    return "None held above threshold between two different object types."


def _title(meta: dict[str, Any]) -> tuple[str, str]:
    name = Path(str(meta.get("checkpoint") or "recording")).name
    module = str(meta.get("module"))
    shape = f"{module}, {meta.get('heads')} heads"
    if module == "predinet":
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
) -> dict[str, Any]:
    """The template's context: tables for the page and ``data`` for the player's JSON."""
    from neurosym import __version__
    from neurosym.envs import env_family
    from neurosym.export.report import RULE_FILES
    from neurosym.viz.style import legend_text
    from neurosym.webreport.page import HEAD_COLOURS
    from neurosym.webreport.player import entity_styles, names_in, player_data
    from neurosym.webreport.tables import episode_rows, head_rows, rule_rows, strongest_rows

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
        "relations": player["relations"] if player["module"] == "predinet" else 0,
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
        "data": {
            "player": player,
            "entities": entity_styles(names),
            "head_colours": list(HEAD_COLOURS),
            "thresholds": {str(j): v for j, v in thresholds.items()},
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


def load_agent_or_note(path: str | None) -> tuple[Any | None, str | None]:
    """The checkpoint a recording names, loaded for its card; (None, why) when it cannot be."""
    if not path:
        return None, "The recording names no checkpoint."
    if not Path(path).is_file():
        return (
            None,
            f"The checkpoint {path} the recording names is not at hand: its card is partial.",
        )
    from neurosym.agent.checkpoint import load_agent

    try:
        return load_agent(path), None
    except NeurosymError as exc:
        return None, f"The checkpoint {path} could not be read ({exc}): its card is partial."


def load_extract(path: Path, threshold: str | None = None) -> tuple[Recording, Any, Path | None]:
    """(recording, facts, kb.pl or None) of an extract folder; facts at the extract's threshold."""
    from neurosym.export.facts import DEFAULT_THRESHOLD, extract_facts
    from neurosym.publish import published

    rec_dir, folder = recording_folder(path)
    # Every product from one published run (a run published meanwhile cannot give a mix).
    if rec_dir == folder / "recording":
        folder = published(folder)
        rec_dir = folder / "recording"
    else:
        rec_dir = rec_dir.resolve()
        folder = rec_dir.parent
    rec = Recording.load(rec_dir)
    kb = folder / "kb.pl"
    kb_path = kb if kb.is_file() else None
    spec = threshold or threshold_of(folder, kb_path) or DEFAULT_THRESHOLD
    return rec, extract_facts(rec, threshold=spec), kb_path


def write_report(out: Path, context: dict[str, Any]) -> Path:
    """Render the page for ``context`` and write ``out/index.html`` atomically."""
    from neurosym.webreport.page import render, write_page

    out.mkdir(parents=True, exist_ok=True)
    return write_page(out / "index.html", render(context))
