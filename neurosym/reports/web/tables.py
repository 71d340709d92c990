"""The page's tables: episodes, heads, strongest relations, rule answers, each row with its examples.

The figures are the ones ``neurosym extract`` prints, from the same functions
(:func:`neurosym.record.heads.head_summary`,
:meth:`neurosym.facts.tables.FactSet.strongest_relations`,
:func:`neurosym.reports.terminal.rule_answers`); this module adds to each row
the (episode, step) states it counts, the first :data:`EXAMPLES` of them,
which the page links to its player.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pandas as pd

from neurosym.record.heads import BACKGROUND, head_summary

EXAMPLES = 5
"""(episode, step) links per table row"""


def _states(df: pd.DataFrame, n: int = EXAMPLES) -> list[list[int]]:
    """The first ``n`` distinct (episode, t) of ``df``, in episode and step order."""
    if df.empty:
        return []
    first = df[["episode", "t"]].drop_duplicates().sort_values(["episode", "t"]).head(n)
    return [[int(e), int(t)] for e, t in first.itertuples(index=False, name=None)]


def episode_rows(rec: Any) -> list[dict[str, Any]]:
    """One row per episode: episode, steps, return, outcome, seed."""
    cols = ["episode", "steps", "return", "outcome", "seed"]
    rows = rec.episodes.sort_values("episode")[cols].to_dict("records")
    return [{**r, "outcome": str(r["outcome"])} for r in rows]


def _argument_pairs(attends: pd.DataFrame) -> pd.DataFrame:
    """Per (episode, t, head): the two arguments' entities, ``pair`` "a-b", and ``objects``
    (both on named objects and on two different cells, as head_summary counts them)."""
    keys = ["episode", "t", "head"]
    first = attends[attends["arg"] == 1].set_index(keys)[["entity", "row", "col"]]
    second = attends[attends["arg"] == 2].set_index(keys)[["entity", "row", "col"]]
    both = first.merge(second, left_index=True, right_index=True, suffixes=("_1", "_2"))
    both = both.reset_index()
    both["pair"] = both["entity_1"].astype(str) + "-" + both["entity_2"].astype(str)
    both["objects"] = (
        ~both["entity_1"].isin(BACKGROUND)
        & ~both["entity_2"].isin(BACKGROUND)
        & ((both["row_1"] != both["row_2"]) | (both["col_1"] != both["col_2"]))
    )
    return both


def head_rows(rec: Any) -> list[dict[str, Any]]:
    """:func:`head_summary` rows (PrediNet), each top pair with the states it counts."""
    summary = head_summary(rec)
    if summary.empty:
        return []
    both = _argument_pairs(rec.attends)
    rows = []
    for row in summary.to_dict("records"):
        mine = both[(both["head"] == row["head"]) & both["objects"]]
        pairs = []
        for k in (1, 2, 3):
            pair = row.get(f"pair_{k}")
            if pair is not None:
                examples = _states(mine[mine["pair"] == pair])
                pairs.append({"pair": pair, "share": row[f"share_{k}"], "examples": examples})
        rows.append(
            {
                "head": int(row["head"]),
                "states": int(row["states"]),
                "two_objects": row["two_objects"],
                "next_object": row["next_object"],
                "pairs": pairs,
                "beside_objects": row["beside_objects"],
                "beside_pair": row["beside_pair"],
                "beside_share": row["beside_share"],
                "examples": _states(mine),
            }
        )
    return rows


def strongest_rows(facts: Any, n: int = 5) -> list[dict[str, Any]]:
    """:meth:`FactSet.strongest_relations` rows, each with the states its holds/5 facts name."""
    table = facts.strongest_relations(n)
    holds = facts["holds"]
    rows = []
    for r in table.to_dict("records"):
        match = holds[(holds["j"] == r["j"]) & (holds["a"] == r["a"]) & (holds["b"] == r["b"])]
        rows.append(
            {
                "j": int(r["j"]),
                "a": str(r["a"]),
                "b": str(r["b"]),
                "held": int(r["held"]),
                "mean_value": float(r["mean_value"]),
                "examples": _states(match),
            }
        )
    return rows


def rule_rows(kb_path: Path | None, family: str, episodes: set[int]) -> list[dict[str, Any]]:
    """The family's rule answers (rules/<family>.pl and relations.pl) over the KB at ``kb_path``.

    An answer of a goal over episodes (``sword_before_enemy(E)``) links to its episode.
    """
    if kb_path is None:
        return []
    from neurosym.reports.terminal import rule_answers

    rows = []
    for title, goal, answers in rule_answers(kb_path, family):
        per_episode = goal.endswith("(E)")
        items = []
        for text in answers:
            e = int(text) if per_episode and text.lstrip("-").isdigit() else None
            items.append({"text": text, "episode": e if e in episodes else None})
        rows.append({"title": title, "goal": goal, "answers": items, "per_episode": per_episode})
    return rows


FAITHFULNESS_GOAL = (
    "catch(faithfulness(Target, Features, Score, States, Episodes), "
    "error(existence_error(_, _), _), fail)"
)
"""the KB's faithfulness/5 facts (a KB written before the predicate existed has none)"""


def faithfulness_table(facts: Any, kb_path: Path | None) -> pd.DataFrame:
    """The faithfulness/5 facts: ``facts``' table, else (facts re-extracted from a recording
    hold none) the KB's, numbers checked (a fact that is not one is left out)."""
    table = facts["faithfulness"]
    if not table.empty or kb_path is None:
        return table
    from neurosym.prolog.knowledge_base import KnowledgeBase

    with KnowledgeBase(kb_path) as kb:
        found = kb.query_df(FAITHFULNESS_GOAL)
    if found.empty:
        return table
    found.columns = [c.lower() for c in found.columns]
    number = found["score"].map(lambda v: isinstance(v, float | int) and not isinstance(v, bool))
    whole = found[["states", "episodes"]].map(lambda v: isinstance(v, int) and not isinstance(v, bool) and v >= 0)
    keep = number & whole.all(axis=1)
    return found.loc[keep, list(table.columns)].astype({"target": str, "features": str}).reset_index(drop=True)


def faithfulness_rows(facts: Any, kb_path: Path | None) -> list[dict[str, Any]]:
    """One row per target: its score per feature set (None: not measured), held-out states and episodes."""
    from neurosym.reports.terminal import FAITHFULNESS_COLUMNS

    table = faithfulness_table(facts, kb_path)
    rows = []
    for target in dict.fromkeys(table["target"]):
        mine = table[table["target"] == target]
        scores = dict(zip(mine["features"], mine["score"], strict=True))
        rows.append(
            {
                "target": str(target).replace("_", " "),
                "scores": [
                    None if f not in scores else float(scores[f]) for f, _ in FAITHFULNESS_COLUMNS
                ],
                "states": int(mine["states"].max()),
                "episodes": int(mine["episodes"].max()),
            }
        )
    return rows
