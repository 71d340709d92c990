"""Features of (state, candidate object) pairs, computed in Python and defined in Prolog.

Every feature is a literal over ``E, T, O`` (state and candidate) that the
learned file can state: a binary one is a goal that holds or not, a numeric
one a goal that binds ``V``. :data:`BACKGROUND` (neurosym/induce/pl/strategy_features.pl)
and the route features' :data:`~neurosym.induce.strategy_route.PROLOG` define, in
Prolog, every predicate these goals use; they are copied into each learned file,
which needs the KB's facts and, for the route features, rules/route.pl (whose
``route_moves/4`` gives the route lengths, here and when the file plays). The
Python side computes the same values (tests check that the two agree through
SWI-Prolog).

Feature sets:

* ``world``: the object's kind, the agent's distance to it (Manhattan), whether
  it is the nearest of its kind or of all, what the agent holds, which kinds
  are on the map, Box-World's key/lock facts (the lock of the held key, a
  loose key that has a lock, a box holding the gem or a key that opens another
  lock) and Minigrid's doors (open, locked, the door of the held key, the key
  of a locked door). Read from ``at/5``, ``holding/3``, ``object/2``,
  ``door_state/4``.
* ``relations``: PrediNet, whether head H's argument A attends the object's
  cell (``attends/8``, the cell mapped to the object through ``at/5``) and
  whether relation J holds with the object's entity as first or second
  argument (``holds/5``; the entity is matched by its name, the object's
  ``object/2`` type); MHDPA, whether head H's agent query attends the object's
  entity, whether the object's query attends the agent, and how many queries
  attend the object's entity (``attention/6``, entities matched by name).
* ``both``: the union.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pandas as pd

from neurosym.agent.networks.adapters import module_has
from neurosym.errors import ConfigError, FactError
from neurosym.induce.prolog_text import pl_text
from neurosym.induce.strategy_data import KINDS, KBTables
from neurosym.induce.strategy_route import UNREACHABLE, shortcuts, trace_routes
from neurosym.terms import Term, TermArg, Var, atom_text, format_value, parse_term

FEATURE_SETS = ("world", "relations", "both")


@dataclass(frozen=True)
class Feature:
    """One column: its name, the Prolog goal over E, T, O (binding V when numeric)."""

    name: str
    term: Term
    numeric: bool = False

    @property
    def goal(self) -> str:
        """The goal as Prolog text, every constant spelled by :mod:`neurosym.terms`."""
        return goal_text(self.term)


E_, T_, O_, V_ = Var("E"), Var("T"), Var("O"), Var("V")
"""The variables of a feature's goal: the state (E, T), the candidate O, a numeric value V."""


def goal_term(pred: str, *args: TermArg) -> Term:
    """The goal ``pred(args...)``; E, T, O, V are the clause's variables."""
    return Term(pred, args)


def goal_text(goal: Term) -> str:
    """``pred(E, T, key)``: a goal's text with a space after each comma, arguments by format_value."""
    return f"{atom_text(goal.functor)}({', '.join(format_value(a) for a in goal.args)})"


def _kv(kind: str) -> TermArg:
    """A kind's value from its canonical text (:func:`_kind`)."""
    try:
        return parse_term(kind)  # type: ignore[return-value]
    except FactError:
        raise ConfigError(
            f"object kind {kind} is not a term neurosym induce can write (an atom, a number or "
            "a compound of them)"
        ) from None


BACKGROUND = pl_text("strategy_features.pl")
"""The feature predicates' Prolog text a learned strategy carries (neurosym/induce/pl/)."""


def _kind(ty: str) -> str:
    """The canonical Prolog text of a type's kind: the type itself, or a compound's functor
    (``key`` for ``key(red)``), as ``object_kind/2`` in the learned file derives it."""
    kind = KINDS.get(ty)
    if kind is None:
        kind = KINDS[ty] = _kind_of(ty)
    return kind


def _kind_of(ty: str) -> str:
    """The kind of a type's canonical text not read by :func:`load_trace` (a KBTables built by hand)."""
    try:
        value = parse_term(ty)
    except FactError:
        raise ConfigError(
            f"object type {ty!r} is not a term neurosym induce can read (an atom, a number or "
            "a compound of them)"
        ) from None
    if isinstance(value, Term):
        return atom_text(value.functor)
    if isinstance(value, tuple):  # a list: '[|]' cells, or the empty list []
        return atom_text("[|]") if value else "[]"
    return format_value(value)


def _colour(ty: str) -> str | None:
    return ty[ty.index("(") + 1 : -1] if "(" in ty else None


def world_features(trace: KBTables, pairs: pd.DataFrame) -> tuple[list[Feature], np.ndarray]:
    """The world feature columns of ``pairs`` (E, T, O, R, C rows) and their Prolog goals."""
    types = dict(zip(trace.object["O"], trace.object["Ty"], strict=True))
    kinds = sorted({_kind(types[o]) for o in pairs["O"].unique()})
    held = sorted({_kind(i) for i in trace.holding["I"].unique()})
    agent = {(e, t): (r, c) for e, t, o, r, c in trace.at.itertuples(index=False) if o == "agent"}
    holding = {(e, t, i) for e, t, i in trace.holding.itertuples(index=False)}
    by_state: dict[tuple[int, int], list[tuple[str, int, int]]] = {}
    for e, t, o, r, c in pairs.itertuples(index=False):
        by_state.setdefault((e, t), []).append((o, r, c))
    cols: dict[str, list[float]] = {}
    feats: list[Feature] = []

    def add(name: str, goal: Term, fn: Callable[..., float], numeric: bool = False) -> None:
        feats.append(Feature(name, goal, numeric))
        cols[name] = [fn(e, t, o, r, c) for e, t, o, r, c in pairs.itertuples(index=False)]

    def dist(e: int, t: int, r: int, c: int) -> int:
        r0, c0 = agent[(e, t)]
        return abs(r - r0) + abs(c - c0)

    def nearest(e: int, t: int, o: str, r: int, c: int, same_kind: bool) -> float:
        d = dist(e, t, r, c)
        k = _kind(types[o])
        return float(
            not any(
                o2 != o and (not same_kind or _kind(types[o2]) == k) and dist(e, t, r2, c2) < d
                for o2, r2, c2 in by_state[(e, t)]
            )
        )

    def at_cell(e: int, t: int, r: int, c: int) -> str | None:
        return next((o2 for o2, r2, c2 in by_state[(e, t)] if (r2, c2) == (r, c)), None)

    def locks(e: int, t: int, colour: str | None, but: str = "") -> bool:
        return any(types[o2] == f"lock({colour})" and o2 != but for o2, _, _ in by_state[(e, t)])

    def content(e: int, t: int, o: str, r: int, c: int) -> str | None:
        return at_cell(e, t, r, c - 1) if _kind(types[o]) == "lock" else None

    for k in kinds:
        add(f"kind={k}", goal_term("object_kind", O_, _kv(k)), lambda e, t, o, r, c, k=k: float(_kind(types[o]) == k))
    for k in held:
        add(
            f"holding={k}",
            goal_term("holding_kind", E_, T_, _kv(k)),
            lambda e, t, o, r, c, k=k: float(
                any((e, t, i) in holding for i in trace.holding["I"].unique() if _kind(i) == k)
            ),
        )
    for k in kinds:
        add(
            f"on_map={k}",
            goal_term("on_map", E_, T_, _kv(k)),
            lambda e, t, o, r, c, k=k: float(any(_kind(types[o2]) == k for o2, _, _ in by_state[(e, t)])),
        )
    add("distance", goal_term("agent_distance", E_, T_, O_, V_), lambda e, t, o, r, c: float(dist(e, t, r, c)), True)
    add("nearest_of_kind", goal_term("nearest_of_kind", E_, T_, O_), lambda e, t, o, r, c: nearest(e, t, o, r, c, True))
    add("nearest_object", goal_term("nearest_object", E_, T_, O_), lambda e, t, o, r, c: nearest(e, t, o, r, c, False))
    if not trace.grid.empty:
        _routes(trace, pairs, types, kinds, add)
    minigrid = not trace.facing.empty
    if not minigrid and any(_kind(types[o]) in ("key", "lock") for o in pairs["O"].unique()):
        _box_world(add, types, holding, at_cell, locks, content)
    if minigrid and any(_kind(types[o]) == "door" for o in pairs["O"].unique()):
        _minigrid(trace, add, types, holding, by_state)
    return feats, np.array([cols[f.name] for f in feats], dtype=float).T


def _routes(trace: KBTables, pairs: pd.DataFrame, types: dict[str, str], kinds: list[str], add) -> None:  # type: ignore[no-untyped-def]
    """Route features (:mod:`neurosym.induce.strategy_route`): reachable, route length, nearest reachable."""
    routes = trace_routes(trace)
    cuts: dict[tuple[int, int, str], set[str]] = {}
    ties: dict[tuple[int, int, str], set[str]] = {}
    for (e, t), group in trace.at.groupby(["E", "T"], sort=False):
        objects = [o for o in dict.fromkeys(group["O"]) if o != "agent"]
        kind_of = {o: _kind(types[o]) for o in objects}
        state = (int(e), int(t))
        for o, ks in shortcuts(routes, state, objects, kind_of).items():
            cuts[(*state, o)] = ks
        for o, ks in shortcuts(routes, state, objects, kind_of, ties=True).items():
            ties[(*state, o)] = ks
    by_state: dict[tuple[int, int], list[str]] = {}
    for e, t, o in zip(pairs["E"], pairs["T"], pairs["O"], strict=True):
        by_state.setdefault((e, t), []).append(o)

    length = routes.length

    def nearest(e: int, t: int, o: str, r: int, c: int) -> float:
        d, k = length(e, t, o), _kind(types[o])
        return float(
            d < UNREACHABLE
            and not any(
                o2 != o and _kind(types[o2]) == k and length(e, t, o2) < d for o2 in by_state[(e, t)]
            )
        )

    add("route_length", goal_term("route_length", E_, T_, O_, V_), lambda e, t, o, r, c: float(length(e, t, o)), True)
    add("reachable", goal_term("reachable", E_, T_, O_), lambda e, t, o, r, c: float(length(e, t, o) < UNREACHABLE))
    add("nearest_reachable_of_kind", goal_term("nearest_reachable_of_kind", E_, T_, O_), nearest)
    for k in kinds:
        if k != "teleport" and "teleport" in kinds:
            add(
                f"teleport_shortcut={k}",
                goal_term("teleport_shortcut", E_, T_, O_, _kv(k)),
                lambda e, t, o, r, c, k=k: float(k in cuts.get((e, t, o), ())),
            )
            add(
                f"teleport_not_longer={k}",
                goal_term("teleport_not_longer", E_, T_, O_, _kv(k)),
                lambda e, t, o, r, c, k=k: float(k in ties.get((e, t, o), ())),
            )
            add(
                f"teleport_shortcut_to={k}",
                goal_term("teleport_shortcut_to", E_, T_, _kv(k)),
                lambda e, t, o, r, c, k=k: float(
                    any(k in cuts.get((e, t, o2), ()) for o2 in by_state[(e, t)])
                ),
            )
    for k in kinds:
        add(
            f"route_not_longer={k}",
            goal_term("route_not_longer", E_, T_, O_, _kv(k)),
            lambda e, t, o, r, c, k=k: float(
                length(e, t, o) < UNREACHABLE
                and not any(
                    o2 != o and _kind(types[o2]) == k and length(e, t, o2) < length(e, t, o)
                    for o2 in by_state[(e, t)]
                )
            ),
        )
    for k in kinds:
        add(
            f"reachable_kind={k}",
            goal_term("reachable_kind", E_, T_, _kv(k)),
            lambda e, t, o, r, c, k=k: float(
                any(_kind(types[o2]) == k and length(e, t, o2) < UNREACHABLE for o2 in by_state[(e, t)])
            ),
        )


def _of_held_key(
    kind: str, types: dict[str, str], holding: set[tuple[int, int, str]]
) -> Callable[..., float]:
    """The feature "O is a ``kind`` (lock, door) of the held key's colour"."""
    return lambda e, t, o, r, c: float(
        _kind(types[o]) == kind and (e, t, f"key({_colour(types[o])})") in holding
    )


def _box_world(add, types, holding, at_cell, locks, content) -> None:  # type: ignore[no-untyped-def]
    """Box-World's key and lock features (only where the KB has keys or locks, and no facing/3)."""
    add(
        "lock_of_held_key",
        goal_term("lock_of_held_key", E_, T_, O_),
        _of_held_key("lock", types, holding),
    )
    add(
        "key_fits_lock",
        goal_term("key_fits_lock", E_, T_, O_),
        lambda e, t, o, r, c: float(_kind(types[o]) == "key" and locks(e, t, _colour(types[o]))),
    )

    def loose(e: int, t: int, o: str, r: int, c: int) -> float:
        right = at_cell(e, t, r, c + 1)
        return float(_kind(types[o]) == "key" and not (right and _kind(types[right]) == "lock"))

    def gem_box(e: int, t: int, o: str, r: int, c: int) -> float:
        x = content(e, t, o, r, c)
        return float(x is not None and _kind(types[x]) == "gem")

    def useful_box(e: int, t: int, o: str, r: int, c: int) -> float:
        x = content(e, t, o, r, c)
        return float(x is not None and _kind(types[x]) == "key" and locks(e, t, _colour(types[x]), o))

    add("loose", goal_term("loose", E_, T_, O_), loose)
    add("box_holds_gem", goal_term("box_holds_gem", E_, T_, O_), gem_box)
    add("box_holds_useful_key", goal_term("box_holds_useful_key", E_, T_, O_), useful_box)


def _minigrid(trace: KBTables, add, types, holding, by_state) -> None:  # type: ignore[no-untyped-def]
    """Minigrid's door features (where the KB has facing/3 and doors): a door's state (door_state/4),
    the door of the held key's colour, the key of a locked door on the map."""
    doors = {(e, t, o): s for e, t, o, s in trace.door_state.itertuples(index=False)}

    def door_is(state: str) -> Callable[..., float]:
        return lambda e, t, o, r, c: float(
            _kind(types[o]) == "door" and doors.get((e, t, o)) == state
        )

    add("door_open", goal_term("door_open", E_, T_, O_), door_is("open"))
    add("door_locked", goal_term("door_locked", E_, T_, O_), door_is("locked"))
    add(
        "door_of_held_key",
        goal_term("door_of_held_key", E_, T_, O_),
        _of_held_key("door", types, holding),
    )
    add(
        "key_of_locked_door",
        goal_term("key_of_locked_door", E_, T_, O_),
        lambda e, t, o, r, c: float(
            _kind(types[o]) == "key"
            and any(
                types[o2] == f"door({_colour(types[o])})" and doors.get((e, t, o2)) == "locked"
                for o2, _, _ in by_state[(e, t)]
            )
        ),
    )


def relation_features(trace: KBTables, pairs: pd.DataFrame) -> tuple[list[Feature], np.ndarray]:
    """The network's relation columns: PrediNet attends/holds, MHDPA attention."""
    types = dict(zip(trace.object["O"], trace.object["Ty"], strict=True))
    heads = int(trace.meta.get("heads", 0))
    feats: list[Feature] = []
    cols: list[list[float]] = []
    rows = list(pairs.itertuples(index=False))
    module = trace.meta.get("module")
    if not trace.attends.empty or module_has(module, "attends"):
        cells = {(e, t, h, a, r, c) for e, t, h, a, r, c in trace.attends.itertuples(index=False)}
        for h in range(heads):
            for a in (1, 2):
                feats.append(Feature(f"attended_by({h},{a})", goal_term("attended_by", E_, T_, h, a, O_)))
                cols.append([float((e, t, h, a, r, c) in cells) for e, t, o, r, c in rows])
        first = {(e, t, j, x) for e, t, j, x, y in trace.holds.itertuples(index=False)}
        second = {(e, t, j, y) for e, t, j, x, y in trace.holds.itertuples(index=False)}
        for j in range(int(trace.meta.get("relations", 0))):
            for pos, table in ((1, first), (2, second)):
                feats.append(Feature(f"related({j},{pos})", goal_term("related", E_, T_, j, pos, O_)))
                cols.append([float((e, t, j, types[o]) in table) for e, t, o, r, c in rows])
    if not trace.attention.empty or module_has(module, "attention"):
        att = trace.attention
        from_agent = {(e, t, h, k) for e, t, h, q, k in att.itertuples(index=False) if q == "agent"}
        to_agent = {(e, t, h, q) for e, t, h, q, k in att.itertuples(index=False) if k == "agent"}
        count = att.groupby(["E", "T", "H", "K"]).size().to_dict()
        for h in range(heads):
            feats.append(Feature(f"agent_query_attends({h})", goal_term("agent_query_attends", E_, T_, h, O_)))
            cols.append([float((e, t, h, types[o]) in from_agent) for e, t, o, r, c in rows])
            feats.append(Feature(f"query_attends_agent({h})", goal_term("query_attends_agent", E_, T_, h, O_)))
            cols.append([float((e, t, h, types[o]) in to_agent) for e, t, o, r, c in rows])
            feats.append(
                Feature(f"attending_queries({h})", goal_term("attending_queries", E_, T_, h, O_, V_), True)
            )
            cols.append([float(count.get((e, t, h, types[o]), 0)) for e, t, o, r, c in rows])
    matrix = np.array(cols, dtype=float).T if cols else np.zeros((len(rows), 0))
    return feats, matrix


def features(trace: KBTables, pairs: pd.DataFrame, which: str) -> tuple[list[Feature], np.ndarray]:
    """The columns of feature set ``which`` (``world``, ``relations`` or ``both``)."""
    parts = []
    if which in ("world", "both"):
        parts.append(world_features(trace, pairs))
    if which in ("relations", "both"):
        parts.append(relation_features(trace, pairs))
    feats = [f for fs, _ in parts for f in fs]
    return feats, np.hstack([m for _, m in parts]) if parts else np.zeros((len(pairs), 0))
