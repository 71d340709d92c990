"""The symbolic predicates of every recorded state, computed from the env's own trace.

A probe asks whether a head's relation vector at a state can tell whether a
predicate of that state's *true* situation holds. The truth comes from the
recording's trace tables (positions, holding, events; the env's ``info``),
never from pixels. One row per state the agent acted in (``t`` in 0..S-1 of an
episode of S steps), one column per predicate, as ground Prolog text.

Relational-Grid-World (objects by id: ``agent``, ``sword``, ``enemy``,
``teleport_1``, ``pit_2``, ...; absent objects make a predicate false):

==============================  ==============================================
``holding(sword)``              the agent holds it
``left_of(X, Y)``               X's column is smaller than Y's (pairs X before Y)
``above(X, Y)``                 X's row is smaller than Y's
``adjacent(agent, X)``          Manhattan distance 1
``nearer(agent, X, Y)``         X is nearer the agent than Y (Manhattan)
``next_target(X)``              X (a type) is the next object the agent reaches:
                                the target of the next sword / teleport / enemy /
                                terminal / pit event at or after this state
``visited(X)``                  the agent reached X (a type) before this state
==============================  ==============================================

Box-World: ``holding(key(C))``; ``opens(key(C), lock(C))`` (the agent holds
key C and a lock of colour C is on the map); ``next_lock(C)`` (the next lock the
agent opens has colour C); ``next_target(X)`` and ``visited(X)`` over the
targets ``key(C)``, ``lock(C)``, ``gem`` of its events.

Everything is column work on the tables (no loop over states or cells); the
loops run over the few objects and predicates.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np
import pandas as pd

from neurosym.errors import ConfigError
from neurosym.terms import Term, parse_term

RGW_TARGETS: dict[str, str] = {
    "picked(sword)": "sword",
    "teleported": "teleport",
    "defeated(enemy)": "enemy",
    "hurt_by(enemy)": "enemy",
    "reached(terminal)": "terminal",
    "fell(pit)": "pit",
}
"""RGW event -> the object type it reaches (next_target/visited)."""


@dataclass
class StateLabels:
    """Truth values of predicates at the recorded states."""

    states: pd.DataFrame
    """(S rows) ``episode, t`` of each state the agent acted in, episodes in order"""
    names: list[str]
    """predicate text per column, e.g. ``left_of(agent,sword)``"""
    values: np.ndarray
    """(S, P) bool"""

    def column(self, name: str) -> np.ndarray:
        return self.values[:, self.names.index(name)]


def acted_states(episodes: pd.DataFrame) -> pd.DataFrame:
    """``episode, t`` of every state an agent acted in: t = 0..steps-1 of each episode, in order."""
    ep = episodes["episode"].to_numpy(dtype=np.int64)
    steps = episodes["steps"].to_numpy(dtype=np.int64)
    starts = np.repeat(np.cumsum(steps) - steps, steps)
    t = np.arange(int(steps.sum()), dtype=np.int64) - starts
    return pd.DataFrame({"episode": np.repeat(ep, steps), "t": t})


def _row_of(states: pd.DataFrame, episode: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Row of each (episode, t) in ``states`` (-1 where it is no acted state)."""
    index = pd.MultiIndex.from_arrays([states["episode"], states["t"]])
    return index.get_indexer(pd.MultiIndex.from_arrays([episode, t]))


def _term(functor: str, *args: str) -> str:
    return str(Term(functor, tuple(parse_term(a) for a in args)))


class _Builder:
    """Collects predicate columns over the states."""

    def __init__(self, states: pd.DataFrame) -> None:
        self.states = states
        self.n = len(states)
        self.names: list[str] = []
        self.cols: list[np.ndarray] = []

    def add(self, name: str, values: np.ndarray) -> None:
        self.names.append(name)
        self.cols.append(np.asarray(values, dtype=bool))

    def labels(self) -> StateLabels:
        values = np.stack(self.cols, axis=1) if self.cols else np.zeros((self.n, 0), dtype=bool)
        return StateLabels(self.states, self.names, values)


def _positions(rec_positions: pd.DataFrame, states: pd.DataFrame) -> dict[str, np.ndarray]:
    """object id -> (S, 2) row, col at each state (-1 where it is not on the map)."""
    pos = rec_positions
    rows = _row_of(states, pos["episode"].to_numpy(), pos["t"].to_numpy())
    keep = rows >= 0
    pos, rows = pos.loc[keep], rows[keep]
    out: dict[str, np.ndarray] = {}
    ids = pd.unique(pos["object"])
    order = sorted(ids, key=lambda i: (i != "agent", i))  # the agent first
    obj = pos["object"].to_numpy(dtype=object)
    rc = pos[["row", "col"]].to_numpy(dtype=np.int64)
    for ident in order:
        mask = obj == ident
        grid = np.full((len(states), 2), -1, dtype=np.int64)
        grid[rows[mask]] = rc[mask]
        out[str(ident)] = grid
    return out


def _event_targets(
    events: pd.DataFrame, states: pd.DataFrame, target_of: dict[str, str]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Events that reach an object, ordered: (episode, t, target) arrays."""
    ev = events.loc[events["event"].isin(list(target_of))]
    order = np.lexsort((ev["t"].to_numpy(), ev["episode"].to_numpy()))
    ev = ev.iloc[order]
    target = ev["event"].map(target_of).to_numpy(dtype=object)
    return ev["episode"].to_numpy(dtype=np.int64), ev["t"].to_numpy(dtype=np.int64), target


def _next_and_visited(
    b: _Builder, ep_ev: np.ndarray, t_ev: np.ndarray, target: np.ndarray, functor_next: str
) -> None:
    """next_target(X) / visited(X) columns from ordered target events."""
    st_ep = b.states["episode"].to_numpy(dtype=np.int64)
    st_t = b.states["t"].to_numpy(dtype=np.int64)
    big = int(max(st_t.max(initial=0), t_ev.max(initial=0))) + 2
    ev_key = ep_ev * big + t_ev
    st_key = st_ep * big + st_t
    i = np.searchsorted(ev_key, st_key, side="left")  # first event at or after the state
    found = i < len(ev_key)
    i_safe = np.minimum(i, max(len(ev_key) - 1, 0))
    found &= len(ev_key) > 0
    if len(ev_key):
        found &= ep_ev[i_safe] == st_ep
    nxt = np.where(found, target[i_safe] if len(ev_key) else None, None)
    for x in sorted(set(target.tolist())):
        b.add(_term(functor_next, x), nxt == x)
    for x in sorted(set(target.tolist())):
        first = pd.Series(t_ev[target == x]).groupby(ep_ev[target == x]).min()
        tf = first.reindex(st_ep).to_numpy(dtype=np.float64)  # NaN: never reached
        b.add(_term("visited", x), st_t > np.nan_to_num(tf, nan=np.inf))


def _holding(b: _Builder, holding: pd.DataFrame) -> dict[str, np.ndarray]:
    rows = _row_of(b.states, holding["episode"].to_numpy(), holding["t"].to_numpy())
    keep = rows >= 0
    items = holding["item"].to_numpy(dtype=object)[keep]
    rows = rows[keep]
    out: dict[str, np.ndarray] = {}
    for item in sorted(set(items.tolist())):
        col = np.zeros(b.n, dtype=bool)
        col[rows[items == item]] = True
        out[item] = col
        b.add(_term("holding", item), col)
    return out


def _manhattan(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.abs(a - b).sum(axis=1)


def rgw_labels(recording) -> StateLabels:  # noqa: ANN001 (a Recording)
    """The RGW predicates (module docstring) at every acted state of ``recording``."""
    states = acted_states(recording.episodes)
    b = _Builder(states)
    _holding(b, recording.holding)
    pos = _positions(recording.positions, states)
    present = {k: v[:, 0] >= 0 for k, v in pos.items()}
    ids = list(pos)
    for x, y in combinations(ids, 2):
        both = present[x] & present[y]
        b.add(_term("left_of", x, y), both & (pos[x][:, 1] < pos[y][:, 1]))
        b.add(_term("above", x, y), both & (pos[x][:, 0] < pos[y][:, 0]))
    if "agent" in pos:
        agent = pos["agent"]
        others = [i for i in ids if i != "agent"]
        for x in others:
            b.add(_term("adjacent", "agent", x), present[x] & (_manhattan(agent, pos[x]) == 1))
        for x, y in combinations(others, 2):
            both = present[x] & present[y]
            nearer = _manhattan(agent, pos[x]) < _manhattan(agent, pos[y])
            b.add(_term("nearer", "agent", x, y), both & nearer)
    ep_ev, t_ev, target = _event_targets(recording.events, states, RGW_TARGETS)
    _next_and_visited(b, ep_ev, t_ev, target, "next_target")
    return b.labels()


def boxworld_labels(recording) -> StateLabels:  # noqa: ANN001 (a Recording)
    """The Box-World predicates (module docstring) at every acted state of ``recording``."""
    states = acted_states(recording.episodes)
    b = _Builder(states)
    held = _holding(b, recording.holding)
    # locks on the map per state, by colour
    pos = recording.positions
    rows = _row_of(states, pos["episode"].to_numpy(), pos["t"].to_numpy())
    keep = rows >= 0
    types = pos["type"].to_numpy(dtype=object)[keep]
    rows = rows[keep]
    for item, holding in held.items():
        term = parse_term(item)
        if not isinstance(term, Term) or term.functor != "key":
            continue
        colour = str(term.args[0])
        lock = _term("lock", colour)
        on_map = np.zeros(b.n, dtype=bool)
        on_map[rows[types == lock]] = True
        b.add(_term("opens", item, lock), holding & on_map)
    ev = recording.events
    texts = pd.unique(ev["event"]).tolist()
    target_of: dict[str, str] = {}
    lock_of: dict[str, str] = {}
    for text in texts:
        term = parse_term(text)
        if isinstance(term, Term) and term.functor in ("got", "opened") and len(term.args) == 1:
            target_of[text] = str(term.args[0])
            inner = term.args[0]
            if term.functor == "opened" and isinstance(inner, Term) and inner.functor == "lock":
                lock_of[text] = str(inner.args[0])
    if lock_of:
        ep_l, t_l, colour = _event_targets(ev, states, lock_of)
        sub = _Builder(states)
        _next_and_visited(sub, ep_l, t_l, colour, "next_lock")
        for name, col in zip(sub.names, sub.cols, strict=True):
            if name.startswith("next_lock("):
                b.add(name, col)
    ep_ev, t_ev, target = _event_targets(ev, states, target_of)
    _next_and_visited(b, ep_ev, t_ev, target, "next_target")
    return b.labels()


def state_labels(recording, family: str) -> StateLabels:  # noqa: ANN001 (a Recording)
    """The predicates of ``family`` ("rgw" or "boxworld") at every acted state."""
    if family == "rgw":
        return rgw_labels(recording)
    if family == "boxworld":
        return boxworld_labels(recording)
    raise ConfigError(f"no predicates for env family {family!r}; expected rgw or boxworld")
