"""The clause search on hand-built grounded states: chains of colour variables, undetermined events."""

from __future__ import annotations

import itertools

import numpy as np
import pandas as pd

from neurosym.induce.examples import PREDICATES, Grounded
from neurosym.induce.foil import learn
from neurosym.induce.world import score

COLOURS = ("blue", "green", "red")


def grounded(states: list[dict[str, list[str]]], events: list[list[str]]) -> Grounded:
    """States as {predicate: values}; events per state."""
    values = sorted({v for st in states for vs in st.values() for v in vs})
    index = {v: i for i, v in enumerate(values)}
    matrix = {p: np.zeros((len(states), len(values)), dtype=bool) for p in PREDICATES}
    for s, st in enumerate(states):
        for pred, vs in st.items():
            for v in vs:
                matrix[pred][s, index[v]] = True
    rows = [(s, e) for s, evs in enumerate(events) for e in evs]
    return Grounded(
        source="hand-built", env="bw", family="boxworld",
        keys=np.array([(0, s) for s in range(len(states))], dtype=np.int64).reshape(-1, 2),
        values=values, matrix=matrix,
        events=pd.DataFrame(rows, columns=["s", "event"]).astype({"s": "int64"}),
        colours=list(COLOURS),
    )  # fmt: skip


def box_states() -> tuple[list[dict[str, list[str]]], list[list[str]]]:
    """Every lock x held key x content: a box opens (and hands its key over) when the colours match."""
    states, events = [], []
    for lock, held, content in itertools.product(COLOURS, [*COLOURS, None], COLOURS):
        states.append(
            {
                "ahead": [f"lock({lock})"],
                "holding": [f"key({held})"] if held else [],
                "left_of_ahead": [f"key({content})"],
            }
        )
        events.append([f"opened(lock({lock}))", f"got(key({content}))"] if held == lock else [])
    for key in COLOURS:  # a loose key ahead is taken
        states.append({"ahead": [f"key({key})"], "left_of_ahead": ["empty"]})
        events.append([f"got(key({key}))"])
    states.append({"ahead": ["empty"], "left_of_ahead": ["empty"]})
    events.append([])
    return states, events


def test_colour_variables_chain_through_the_clause() -> None:
    g = grounded(*box_states())
    clauses, left = learn(g, "opened(lock(C))")
    assert left == 0
    assert [c.text() for c in clauses] == [
        "predicts(E, T, opened(lock(C))) :-\n    ahead(E, T, lock(C)),\n    holding(E, T, key(C))."
    ]
    clauses, left = learn(g, "got(key(C))")
    assert left == 0
    texts = sorted(" ".join(c.text().split()) for c in clauses)
    assert texts == [
        "predicts(E, T, got(key(C))) :- ahead(E, T, key(C)).",
        "predicts(E, T, got(key(C))) :- left_of_ahead(E, T, key(C)), ahead(E, T, lock(C1)),"
        " holding(E, T, key(C1)).",
    ]
    assert score(g, "got(key(C))", clauses) == (len(COLOURS) + len(COLOURS) ** 2, 1.0, 1.0)


def test_examples_no_clause_separates_leave_the_event_uncovered() -> None:
    same = {"ahead": ["enemy"]}
    g = grounded([same, same, {"ahead": ["wall"]}], [["hurt_by(enemy)"], [], []])
    clauses, left = learn(g, "hurt_by(enemy)")
    assert (clauses, left) == ([], 1)
