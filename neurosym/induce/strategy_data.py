"""The data a strategy is learned from: a KB's trace tables, its states' candidates and labels.

A *state* is (episode E, step T). Its *candidates* are the objects on the map
in that state (``at/5`` facts other than the agent's), in the standard order
of their ids (the order the learned file's ``strategy_candidate/3`` gives).
Its *label* (the next object) is the object of the first contact at T' >= T:
the object in the cell that the action at T' moves into, on a step whose
events include a contact (:data:`CONTACTS`); in Minigrid (states with
``facing/3``) the object ahead of the agent on a forward, pickup or toggle
whose events include one of :data:`AHEAD_CONTACTS` (``picked(key(C))``,
``unlocked(door(C))``, ``opened(door(C))``, ``reached(goal)``). States after the last contact
have no label and are left out.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from neurosym.display import plain
from neurosym.errors import ConfigError
from neurosym.facts.schema import SCHEMA
from neurosym.terms import format_value

CONTACTS = frozenset(
    {
        # Relational-Grid-World
        "picked(sword)",
        "defeated(enemy)",
        "hurt_by(enemy)",
        "bumped(enemy)",
        "killed_by(enemy)",
        "teleported",
        "reached(terminal)",
        "fell(pit)",
        # Box-World: picking a loose key, opening a box
        "opened",
        "got_loose_key",
    }
)
"""Events that are a contact with the object in the cell moved into (Box-World by functor)."""

MOVES = {"up": (-1, 0), "right": (0, 1), "down": (1, 0), "left": (0, -1)}
"""Action -> (row, col) offset of the cell it moves into."""

# Minigrid and BabyAI (states with facing/3): the agent acts on the cell ahead of it
AHEAD_CONTACTS = frozenset({"picked", "unlocked", "opened", "reached"})
"""Minigrid: event functors that are a contact with the object ahead (``picked(key(C))``,
``unlocked(door(C))``, ``opened(door(C))`` or ``opened(box(C))``, ``reached(goal)``)"""

AHEAD_ACTIONS = frozenset({"forward", "pickup", "toggle"})
"""Minigrid: the actions that act on the cell ahead (forward moves into it)"""

AHEAD = {"east": (0, 1), "south": (1, 0), "west": (0, -1), "north": (-1, 0)}
"""Minigrid: facing/3's direction -> (row, col) offset of the cell ahead"""

_KIND = "( compound({x}) -> functor({x}, Kind, _) ; Kind = {x} )"
"""binds Kind to the kind of a type or item, as the learned file's object_kind/2 derives it"""

KINDS: dict[str, str] = {}
"""A type's (or held item's) canonical text -> the canonical text of its kind (``key(red)`` ->
``key``), from Prolog's own answer: filled by :func:`load_trace`, read by the features."""

_FORMAT = "format(atom({x}), '~k', [{x}0])"
"""binds {x} to the canonical text of the term {x}0"""


COLUMNS: dict[str, dict[str, str]] = {}
"""Table -> {its schema column: the KBTables column it becomes}: filled by :func:`_table` from
the same declarations as :data:`TABLES` (``Ty0`` read then formatted becomes ``Ty``; ``r(J)``
becomes ``J``)."""


def _trace_column(variable: str) -> str:
    """The KBTables column a goal variable ends up in: ``Ty0`` -> ``Ty``, ``r(J)`` -> ``J``."""
    inner = re.fullmatch(r"\w+\((\w+)\)", variable)
    if inner:
        return inner.group(1)
    return variable[:-1] if variable.endswith("0") and len(variable) > 1 else variable


def _table(name: str, *then: str, old: bool = False, **variables: str) -> tuple[str, str]:
    """``(name, goal)``: the schema's goal for ``name`` binding ``variables`` (by column), then ``then``.

    ``old``: KBs written before the predicate existed lack its declaration; a goal
    on it reads no rows there instead of raising.
    """
    COLUMNS[name] = {column: _trace_column(v) for column, v in variables.items()}
    goal = SCHEMA[name].goal(**variables)
    if old:
        goal = f"catch({goal}, error(existence_error(_, _), _), fail)"
    return name, ", ".join((goal, *then))


TABLES: dict[str, str] = dict(
    (
        _table("object", _FORMAT.format(x="Ty"), _KIND.format(x="Ty0"), id="O", type="Ty0"),
        _table("at", episode="E", t="T", id="O", row="R", col="C"),
        _table("step", episode="E", t="T", action="A"),
        _table("event", "term_to_atom(Ev0, Ev)", episode="E", t="T", event="Ev0"),
        _table(
            "holding", _FORMAT.format(x="I"), _KIND.format(x="I0"), episode="E", t="T", item="I0"
        ),
        _table("attends", episode="E", t="T", head="H", arg="Arg", row="R", col="C"),
        _table(
            "holds", _FORMAT.format(x="X"), _FORMAT.format(x="Y"),
            episode="E", t="T", j="r(J)", a="X0", b="Y0",
        ),
        _table(
            "attention", _FORMAT.format(x="Q"), _FORMAT.format(x="K"),
            episode="E", t="T", head="H", query="Q0", key="K0",
        ),
        _table("kb_meta", "term_to_atom(V0, V)", key="Key", value="V0"),
        _table(
            "terrain", "term_to_atom(Ty0, Ty)", old=True, episode="E", type="Ty0", row="R", col="C"
        ),
        _table("grid", old=True, episode="E", rows="Rows", cols="Cols"),
        _table("facing", old=True, episode="E", t="T", direction="Dir"),
        _table("door_state", old=True, episode="E", t="T", id="O", state="S"),
    )
)
"""The goal that reads each table, compound terms as their Prolog text: types, items and
entities canonical (``write_canonical``: quoted, no operators), which
:func:`neurosym.terms.parse_term` reads back, so a learned file spells them as the KB does."""


@dataclass
class KBTables:
    """A KB's tables (DataFrames, columns named as the goals' variables in :data:`TABLES`)."""

    path: Path
    object: pd.DataFrame
    at: pd.DataFrame
    step: pd.DataFrame
    event: pd.DataFrame
    holding: pd.DataFrame
    attends: pd.DataFrame
    holds: pd.DataFrame
    attention: pd.DataFrame
    terrain: pd.DataFrame
    grid: pd.DataFrame
    meta: dict[str, str]
    facing: pd.DataFrame = field(default_factory=lambda: pd.DataFrame(columns=["E", "T", "Dir"]))
    """Minigrid: the agent's direction per state (none for the other families)"""
    door_state: pd.DataFrame = field(
        default_factory=lambda: pd.DataFrame(columns=["E", "T", "O", "S"])
    )
    """Minigrid: each door's state (open, closed, locked) per state"""

    def episodes(self) -> list[int]:
        """The episode ids that have states, sorted."""
        return sorted(int(e) for e in self.at["E"].unique())

    def subset(self, episodes: list[int]) -> KBTables:
        """The same tables restricted to ``episodes``."""
        keep = set(episodes)
        parts = {
            name: getattr(self, name)[getattr(self, name)["E"].isin(keep)].reset_index(drop=True)
            for name in TABLES
            if SCHEMA[name].columns[0] == "episode"
        }
        return KBTables(self.path, self.object, meta=self.meta, **parts)


def _columns(df: pd.DataFrame) -> pd.DataFrame:
    """Drop the goals' helper variables (those ending in 0: the terms before term_to_atom)."""
    return df[[c for c in df.columns if not c.endswith("0")]]


def load_trace(path: str | Path) -> KBTables:
    """Read a KB file's trace and relation facts (as data: nothing in it runs)."""
    from neurosym.prolog.knowledge_base import KnowledgeBase

    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"no knowledge base at {path}; pass a kb.pl written by neurosym extract")
    with KnowledgeBase(path) as kb:
        tables = {name: _columns(kb.query_df(goal)) for name, goal in TABLES.items()}
        named = kb.once(NAMED)
    for name, column in (("object", "Ty"), ("holding", "I")):
        table = tables[name]
        for text, kind in zip(table[column], table["Kind"], strict=True):
            if text not in KINDS:
                KINDS[text] = format_value(kind)
        tables[name] = table.drop(columns="Kind")
    meta = dict(zip(tables["kb_meta"]["Key"], tables["kb_meta"]["V"], strict=True))
    trace = KBTables(path, meta=meta, **{k: v for k, v in tables.items() if k != "kb_meta"})
    if trace.at.empty:
        raise ConfigError(f"{path} has no at/5 facts; pass a KB of recorded episodes (neurosym extract)")
    check_types(trace)
    check_grids(trace)
    heads = max(_top(trace.attends["H"]), _top(trace.attention["H"]), int(named["H"])) + 1 if named else 0
    relations = max(_top(trace.holds["J"]), int(named["J"])) + 1 if named else 0
    check_count(trace, "heads", heads, "attends/8, attention/6 and relation/7 facts")
    check_count(trace, "relations", relations, "holds/5, relation/7 and threshold/2 facts")
    return trace


NAMED = (
    "( aggregate_all(max(H0), catch(relation(_, _, H0, _, _, _, _), _, fail), H) -> true ; H = -1 ), "
    "( aggregate_all(max(J0), ( catch(relation(_, _, _, J0, _, _, _), _, fail) ; "
    "catch(threshold(J0, _), _, fail) ), J) -> true ; J = -1 )"
)
"""The highest head and relation number the KB's relation/7 and threshold/2 facts name (-1: none)."""

GRID_SLACK = 2
"""A grid may be at most twice the rows (columns) the KB's facts reach, plus this."""


def _top(column: pd.Series) -> int:
    """The highest integer in ``column``, -1 when it is empty (or holds no integer)."""
    values = pd.to_numeric(column, errors="coerce").dropna()
    return int(values.max()) if len(values) else -1


def _whole(value: object) -> bool:
    return isinstance(value, int | np.integer) and not isinstance(value, bool)


def check_types(trace: KBTables) -> None:
    """Every object placed by at/5 has a type in object/2 (the features read it)."""
    untyped = sorted(set(trace.at["O"]) - set(trace.object["O"]), key=str)
    if untyped:
        raise ConfigError(
            f"{trace.path}: object {plain(str(untyped[0]))} has at/5 facts but no object/2 fact "
            "naming its type; a KB written by neurosym extract has one per object"
        )


def check_grids(trace: KBTables) -> None:
    """Refuse a ``grid/3`` fact far larger than the cells the KB's ``at/5`` and ``terrain/4`` reach.

    Route features search every cell of the grid for every state, so the
    grid's size, a value read from the KB, sizes that work (``grid(0, 3000,
    3000)`` with a 10 x 10 map of facts would take hours): it is bounded by
    the map the facts show before any work is done.
    """
    if trace.grid.empty:
        return
    reach = []
    for axis in ("R", "C"):
        cells = pd.concat([trace.at[axis], trace.terrain[axis]], ignore_index=True)
        reach.append(_top(cells) + 1)
    limits = [2 * r + GRID_SLACK for r in reach]
    for e, rows, cols in trace.grid[["E", "Rows", "Cols"]].itertuples(index=False):
        if not all(_whole(v) and 0 <= v <= lim for v, lim in zip((rows, cols), limits, strict=True)):
            raise ConfigError(
                f"grid({e}, {rows}, {cols}) in {trace.path}: its at/5 and terrain/4 facts reach "
                f"{reach[0]} rows and {reach[1]} columns, so a grid may have at most {limits[0]} rows "
                f"and {limits[1]} columns (twice what the facts reach, plus {GRID_SLACK})"
            )


def check_count(trace: KBTables, key: str, present: int, facts: str) -> None:
    """Refuse a ``kb_meta(key, N)`` (heads, relations) that is no count or exceeds what the facts name.

    The count sizes the relation features (a column per head and argument),
    so ``kb_meta(heads, 20000000)`` would fill the memory: it may be at most
    the number the KB's relation facts name (at least 1).
    """
    text = trace.meta.get(key)
    if text is None:
        return
    allowed = max(present, 1)
    try:
        value = int(text)
    except ValueError:
        value = None
    if value is None or not 0 <= value <= allowed:
        raise ConfigError(
            f"kb_meta({key}, {text}) in {trace.path}: {key} must be a whole number from 0 to "
            f"{allowed} (the {key} its {facts} name)"
        )


def _contact(events: list[str], target: str | None, types: dict[str, str], ahead: bool = False) -> bool:
    """Whether a step with these events is a contact with ``target`` (the object moved into; with
    ``ahead``, Minigrid's object ahead of the agent)."""
    if target is None:
        return False
    if ahead:
        return any(ev.partition("(")[0] in AHEAD_CONTACTS for ev in events)
    kind = types.get(target, "")
    for ev in events:
        if ev in CONTACTS:
            return True
        if ev.startswith("opened(") and kind.startswith("lock("):
            return True
        if ev.startswith("got(key(") and kind.startswith("key("):
            return True  # walking into a key's cell: a loose key (a box's content blocks)
    return False


def labels(trace: KBTables) -> pd.DataFrame:
    """The next object of every labelled state: columns E, T, Goal, sorted by (E, T)."""
    types = dict(zip(trace.object["O"], trace.object["Ty"], strict=True))
    cells = {(e, t, r, c): o for e, t, o, r, c in trace.at.itertuples(index=False) if o != "agent"}
    agent = {(e, t): (r, c) for e, t, o, r, c in trace.at.itertuples(index=False) if o == "agent"}
    events: dict[tuple[int, int], list[str]] = {}
    for e, t, ev in trace.event.itertuples(index=False):
        events.setdefault((e, t), []).append(ev)
    facing = {(e, t): d for e, t, d in trace.facing.itertuples(index=False)}
    contacts: dict[int, list[tuple[int, str]]] = {}
    for e, t, a in trace.step.sort_values(["E", "T"]).itertuples(index=False):
        if (e, t) not in events or (e, t) not in agent:
            continue
        ahead = (e, t) in facing
        offset = (AHEAD.get(facing[(e, t)]) if a in AHEAD_ACTIONS else None) if ahead else MOVES.get(a)
        if offset is None:
            continue
        r, c = agent[(e, t)]
        target = cells.get((e, t, r + offset[0], c + offset[1]))
        if _contact(events[(e, t)], target, types, ahead):
            contacts.setdefault(e, []).append((t, target))
    rows = []
    states = trace.at[["E", "T"]].drop_duplicates().sort_values(["E", "T"])
    for e, t in states.itertuples(index=False):
        nxt = next((o for tc, o in contacts.get(e, []) if tc >= t), None)
        if nxt is not None:
            rows.append((int(e), int(t), nxt))
    return pd.DataFrame(rows, columns=["E", "T", "Goal"])


def candidates(trace: KBTables) -> pd.DataFrame:
    """Every (state, object on the map) pair but the agent: columns E, T, O, R, C, ordered by (E, T, O)."""
    pairs = trace.at[trace.at["O"] != "agent"]
    return pairs.sort_values(["E", "T", "O"], kind="stable").reset_index(drop=True)
