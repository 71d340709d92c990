"""Route lengths on the recorded map: rules/route.pl's ``route_moves/5``, for the features and the learned file.

A route goes through the grid's cells (``grid/3``) in the four directions and
passes only empty cells, mountains and the sword's cell: walls and other
terrain, and every other object (a pit, a teleport end, the enemy, the
terminal, a key, a lock) block it, except the object it leads to. So a route
says what the agent can reach without a contact on the way (without the
teleport, in particular). Its length is the number of moves.

The search is route.pl's (one breadth-first search per state and start cell):
:func:`trace_routes` asks it for every state of a trace, and a learned file's
route features (:data:`PROLOG`, ``neurosym/induce/pl/strategy_route.pl``) ask
it when they are played, so the two agree by construction.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import resources

from neurosym.induce.prolog_text import pl_text
from neurosym.induce.strategy_data import KBTables

UNREACHABLE = 999
"""The route length of an object no route reaches."""

PROLOG = pl_text("strategy_route.pl")
"""The route features' Prolog text a learned strategy carries (it needs rules/route.pl beside it)."""

State = tuple[int, int]


@dataclass
class Routes:
    """Route lengths per state: from the agent, and from each teleport end's cell (an object
    a route does not reach is left out: :data:`UNREACHABLE`)."""

    direct: dict[tuple[int, int, str], int]
    """(E, T, O) -> moves from the agent to O"""
    after: dict[tuple[int, int, str, str], int]
    """(E, T, X, O) -> moves from teleport end X's cell to O"""

    def length(self, e: int, t: int, o: str) -> int:
        return self.direct.get((e, t, o), UNREACHABLE)


def trace_routes(trace: KBTables) -> Routes:
    """Every state's route lengths, from rules/route.pl over the trace's facts (asserted in a KB of their own)."""
    from neurosym.prolog.knowledge_base import KnowledgeBase

    table = resources.files("neurosym.induce") / "pl" / "route_table.pl"
    with resources.as_file(table) as path, KnowledgeBase(None, rules=["route", path]) as kb:
        kb.query(
            "assert_trace(Objects, Ats, Terrain, Grids)",
            Objects=trace.object[["O", "Ty"]].values.tolist(),
            Ats=trace.at[["E", "T", "O", "R", "C"]].values.tolist(),
            Terrain=trace.terrain[["E", "Ty", "R", "C"]].values.tolist(),
            Grids=trace.grid[["E", "Rows", "Cols"]].values.tolist(),
        )
        _, rows = kb.solve("trace_route(E, T, From, O, D)")
        kb.query("forget_trace")
    direct: dict[tuple[int, int, str], int] = {}
    after: dict[tuple[int, int, str, str], int] = {}
    for e, t, start, o, d in rows:
        if start == "agent":
            direct[(e, t, o)] = d
        else:
            after[(e, t, start, o)] = d
    return Routes(direct, after)


def shortcuts(
    routes: Routes, state: State, objects: list[str], kinds: dict[str, str], ties: bool = False
) -> dict[str, set[str]]:
    """Teleport end -> the kinds it is a shortcut to (:pl:`teleport_shortcut/4`; ``ties``:
    :pl:`teleport_not_longer/4`, the route through it as long as the one without allowed)."""
    e, t = state
    ends = sorted(o for o in objects if kinds[o] == "teleport")
    out: dict[str, set[str]] = {}
    for o in ends:
        others = [x for x in ends if x != o]
        d1 = routes.length(e, t, o)
        if d1 >= UNREACHABLE or not others:
            continue
        out[o] = set()
        for y in objects:
            d2 = routes.after.get((e, t, others[0], y), UNREACHABLE)
            d = routes.length(e, t, y)
            if kinds[y] != "teleport" and d2 < UNREACHABLE and (d1 + d2 <= d if ties else d1 + d2 < d):
                out[o].add(kinds[y])
    return out
