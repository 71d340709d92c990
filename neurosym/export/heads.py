"""Which PrediNet heads are worth reading: what their two arguments attend to.

A head whose two attention arguments mostly land on the agent twice, or on
empty cells and walls, relates nothing a rule can use; a head that compares
two different objects (the sword and the enemy, the agent and the terminal)
is where relations show. :func:`head_summary` measures it from a recording's
``attends`` table (the argmax cell of each argument, per state and head):

* ``two_objects``: share of the head's states whose two arguments are two
  different objects: both on a named object's cell (not ``empty``, ``wall`` or
  ``mountain``, the terrain) and not on the same cell (so never agent-agent).
* ``pair_k`` / ``share_k`` (k = 1..3): the (argument 1, argument 2) object
  types it relates most, as ``"sword-enemy"``, and the share of all the head's
  states that pair takes (so the shares add up to at most ``two_objects``);
  None where the head relates fewer pairs. Equal counts are ordered by name.

``neurosym extract`` prints this table; the function returns it as a DataFrame
(``df.to_dict("records")`` gives JSON-ready rows).
"""

from __future__ import annotations

from typing import Any

import pandas as pd

BACKGROUND = ("empty", "wall", "mountain")
"""entities that are terrain, not objects (DESIGN.md: walls and mountains have no at/5)"""


def head_summary(rec: Any, top: int = 3) -> pd.DataFrame:
    """One row per PrediNet head: states, two_objects, pair_1, share_1, ..., pair_top, share_top.

    ``rec`` is a :class:`~neurosym.export.recording.Recording` (or anything
    with its ``attends`` table). An MHDPA recording has no argument pairs:
    the table is empty.
    """
    columns = ["head", "states", "two_objects"]
    for k in range(1, top + 1):
        columns += [f"pair_{k}", f"share_{k}"]
    att = rec.attends
    if att is None or att.empty:
        return pd.DataFrame(columns=columns)
    keys = ["episode", "t", "head"]
    first = att[att["arg"] == 1].set_index(keys)[["entity", "row", "col"]]
    second = att[att["arg"] == 2].set_index(keys)[["entity", "row", "col"]]
    both = first.merge(second, left_index=True, right_index=True, suffixes=("_1", "_2"))
    both = both.reset_index()
    objects = (
        ~both["entity_1"].isin(BACKGROUND)
        & ~both["entity_2"].isin(BACKGROUND)
        & ((both["row_1"] != both["row_2"]) | (both["col_1"] != both["col_2"]))
    )
    both["pair"] = both["entity_1"].astype(str) + "-" + both["entity_2"].astype(str)
    rows = []
    for head, group in both.groupby("head", sort=True):
        mask = objects.loc[group.index]
        n = len(group)
        row: dict[str, Any] = {"head": int(head), "states": n, "two_objects": float(mask.mean())}
        counts = group.loc[mask, "pair"].value_counts()
        counts = counts.sort_index().sort_values(ascending=False, kind="stable")  # ties: by name
        for k in range(1, top + 1):
            if k <= len(counts):
                row[f"pair_{k}"], row[f"share_{k}"] = counts.index[k - 1], counts.iloc[k - 1] / n
            else:
                row[f"pair_{k}"], row[f"share_{k}"] = None, None
        rows.append(row)
    df = pd.DataFrame(rows, columns=columns)
    for k in range(1, top + 1):  # None where a head has fewer pairs (not NaN: JSON-ready)
        for name in (f"pair_{k}", f"share_{k}"):
            df[name] = pd.Series([r[name] for r in rows], dtype=object)
    return df
