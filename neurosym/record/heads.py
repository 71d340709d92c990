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

* ``next_object``: whether the head looks where the agent is going. Of the
  head's states from which the agent still meets an object later in its
  episode (the first event naming one at or after that step: ``picked(sword)``,
  ``defeated(enemy)``, ``reached(terminal)``, ``teleported``, ``got(key(red))``,
  ``opened(lock(red))``, ...), the share in which one of its two arguments is
  an object of that type (events never name the agent). None where no state has an object
  ahead (a recording without events, or episodes that met nothing). A head that
  relates the agent to the sword until the sword is taken and then to the
  enemy scores near 1; one fixed on the sword scores only the states before
  it is taken.

* ``beside_objects``, ``beside_pair``, ``beside_share``: the same count with
  each argument read as the object on its cell or, on a terrain cell, an
  object on one of the 8 cells around it (where there are several, the first
  by type name, then row, then column). An entity is a conv feature of
  a neighbourhood (3 x 3 cells for Table 4's encoder), so a head that
  attends to the cell beside the agent still sees the agent, and one that
  does so on most states relates the agent to its other argument, which
  ``two_objects`` does not count. None without a ``positions`` table.
  ``two_objects`` stays the strict figure (the argmax cell itself); this
  one says where the strict one misses a head that looks beside objects.

``neurosym extract`` prints this table; the function returns it as a DataFrame
(``df.to_dict("records")`` gives JSON-ready rows).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd

BACKGROUND = ("empty", "wall", "mountain")
"""entities that are terrain, not objects (docs/design.md: walls and mountains have no at/5)"""

EVENT_OBJECTS = {"teleported": "teleport"}
"""events without an argument that still name the object met (RGW's teleport)"""


def event_object(event: str) -> str | None:
    """The object type an event names: ``picked(sword)`` -> ``sword``, ``got(key(red))`` -> ``key(red)``.

    None for terrain (``crossed(mountain)``) and for events that name no object.
    """
    if event in EVENT_OBJECTS:
        return EVENT_OBJECTS[event]
    start = event.find("(")
    if start < 0 or not event.endswith(")"):
        return None
    inner = event[start + 1 : -1]
    return None if inner in BACKGROUND or "," in inner else inner


def next_objects(rec: Any) -> pd.DataFrame:
    """Per state (episode, t): the object type of the first object event at or after step t.

    Events of ``steps`` row t belong to the transition out of state t, so the
    object taken at step t is still ahead in state t. States with none ahead
    are left out.
    """
    events = getattr(rec, "events", None)
    if events is None or events.empty:
        return pd.DataFrame(columns=["episode", "t", "next"])
    ev = events.assign(next=events["event"].astype(str).map(event_object)).dropna(subset=["next"])
    return ev[["episode", "t", "next"]].sort_values(["episode", "t"], kind="stable")


def head_summary(rec: Any, top: int = 3) -> pd.DataFrame:
    """One row per PrediNet head: states, two_objects, pair_1, share_1, ..., pair_top, share_top.

    ``rec`` is a :class:`~neurosym.record.recording.Recording` (or anything
    with its ``attends`` table). An MHDPA recording has no argument pairs:
    the table is empty.
    """
    columns = ["head", "states", "two_objects", "next_object"]
    for k in range(1, top + 1):
        columns += [f"pair_{k}", f"share_{k}"]
    columns += ["beside_objects", "beside_pair", "beside_share"]
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
    beside = _beside_pairs(both, getattr(rec, "positions", None))  # (pair or None) per row
    both["next"] = _next_at(both, next_objects(rec))
    ahead = both["next"].notna()
    on_next = ahead & ((both["entity_1"] == both["next"]) | (both["entity_2"] == both["next"]))
    rows = []
    for head, group in both.groupby("head", sort=True):
        mask = objects.loc[group.index]
        n = len(group)
        row: dict[str, Any] = {"head": int(head), "states": n, "two_objects": float(mask.mean())}
        n_ahead = int(ahead.loc[group.index].sum())
        row["next_object"] = float(on_next.loc[group.index].sum() / n_ahead) if n_ahead else None
        counts = _ranked(group.loc[mask, "pair"])
        for k in range(1, top + 1):
            if k <= len(counts):
                row[f"pair_{k}"], row[f"share_{k}"] = counts.index[k - 1], counts.iloc[k - 1] / n
            else:
                row[f"pair_{k}"], row[f"share_{k}"] = None, None
        row.update(_top_beside(beside, group.index, n))
        rows.append(row)
    df = pd.DataFrame(rows, columns=columns)
    names = ["next_object"] + [f"{c}_{k}" for k in range(1, top + 1) for c in ("pair", "share")]
    names += ["beside_objects", "beside_pair", "beside_share"]
    for name in names:  # None where a head has fewer pairs or nothing ahead (not NaN: JSON-ready)
        df[name] = pd.Series([r[name] for r in rows], dtype=object)
    return df


def _next_at(states: pd.DataFrame, ahead: pd.DataFrame) -> pd.Series:
    """For each row of ``states`` (episode, t): the next object type at or after t, else None."""
    if ahead.empty:
        return pd.Series([None] * len(states), index=states.index, dtype=object)
    left = states[["episode", "t"]].astype("int64").reset_index().sort_values("t", kind="stable")
    right = ahead.astype({"episode": "int64", "t": "int64"}).sort_values("t", kind="stable")
    found = pd.merge_asof(left, right, on="t", by="episode", direction="forward")
    out = found.set_index("index")["next"].reindex(states.index)
    return out.astype(object).where(out.notna(), None)


def _ranked(pairs: pd.Series) -> pd.Series:
    """Counts of each pair, most frequent first; equal counts ordered by name."""
    return pairs.value_counts().sort_index().sort_values(ascending=False, kind="stable")


def _beside_pairs(both: pd.DataFrame, positions: pd.DataFrame | None) -> pd.Series | None:
    """Per row of ``both`` (one state and head): "type-type" of the two objects its arguments
    are read as (on the cell, else one on the 8 cells around it), None where that is not two
    different objects; None in all when there is no ``positions`` table."""
    if positions is None or positions.empty:
        return None
    ints = {"episode": "int64", "t": "int64", "row": "int64", "col": "int64"}
    pos = positions[["episode", "t", "type", "row", "col"]].astype(ints)
    read = []
    for arg in (1, 2):
        cells = both[["episode", "t", f"entity_{arg}", f"row_{arg}", f"col_{arg}"]].copy()
        cells.columns = ["episode", "t", "entity", "row", "col"]
        cells = cells.astype(ints)
        on = ~cells["entity"].isin(BACKGROUND)
        obj = pd.DataFrame(index=cells.index, columns=["type", "row", "col"], dtype=object)
        obj.loc[on, "type"] = cells.loc[on, "entity"].astype(str)
        obj.loc[on, ["row", "col"]] = cells.loc[on, ["row", "col"]].to_numpy()
        near = cells[~on].rename_axis("cell").reset_index()  # "cell": the row of ``both``
        near = near.merge(pos, on=["episode", "t"], suffixes=("", "_o"))
        dist = np.maximum((near["row"] - near["row_o"]).abs(), (near["col"] - near["col_o"]).abs())
        near = near[dist == 1].sort_values(["cell", "type", "row_o", "col_o"], kind="stable")
        near = near.drop_duplicates("cell")  # one object per cell: the first by type, row, col
        index = near["cell"].to_numpy()
        obj.loc[index, "type"] = near["type"].astype(str).to_numpy()
        obj.loc[index, ["row", "col"]] = near[["row_o", "col_o"]].to_numpy()
        read.append(obj)
    first, second = read
    found = first["type"].notna() & second["type"].notna()
    other = (first["row"] != second["row"]) | (first["col"] != second["col"])
    other |= first["type"] != second["type"]
    pairs = first["type"].astype(str) + "-" + second["type"].astype(str)
    return pairs.where(found & other, None)


def _top_beside(beside: pd.Series | None, index: pd.Index, n: int) -> dict[str, Any]:
    """beside_objects, beside_pair, beside_share of one head's rows (all None without positions)."""
    if beside is None:
        return {"beside_objects": None, "beside_pair": None, "beside_share": None}
    mine = beside.loc[index].dropna()
    counts = _ranked(mine)
    return {
        "beside_objects": len(mine) / n,
        "beside_pair": counts.index[0] if len(counts) else None,
        "beside_share": counts.iloc[0] / n if len(counts) else None,
    }
