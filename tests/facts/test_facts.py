"""extract_facts: fact tables from a hand-made Recording (no Prolog needed here)."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from neurosym.errors import ConfigError
from neurosym.facts.tables import PREDICATES, FactSet, extract_facts
from neurosym.record.recording import Recording

# The relation/7 rows of rules/tests/relations_facts.pl (E, T, Head, J, A, B, Value).
RELATIONS = [
    (0, 0, 0, 0, "sword", "enemy", 1.0),
    (0, 0, 0, 1, "sword", "enemy", 0.5),
    (0, 1, 0, 0, "sword", "enemy", 0.5),
    (0, 1, 0, 1, "sword", "enemy", 0.375),
    (0, 2, 0, 0, "sword", "enemy", 0.25),
    (0, 2, 0, 1, "sword", "enemy", -0.125),
    (1, 0, 0, 0, "agent", "sword", -0.5),
    (1, 0, 0, 1, "agent", "sword", 0.125),
    (0, 0, 1, 0, "enemy", "sword", -0.75),
    (0, 0, 1, 1, "enemy", "sword", 0.375),
]
# ... and its holds/5 facts, which these tests check extract_facts reproduces.
HOLDS = [
    (0, 0, 0, "sword", "enemy"),
    (0, 0, 1, "enemy", "sword"),
    (0, 0, 1, "sword", "enemy"),
    (0, 1, 0, "sword", "enemy"),
    (0, 1, 1, "sword", "enemy"),
    (1, 0, 0, "sword", "agent"),
]


def recording() -> Recording:
    rel = pd.DataFrame(RELATIONS, columns=["episode", "t", "head", "j", "a", "b", "value"])
    return Recording(
        episodes=pd.DataFrame(
            {
                "episode": [0, 1],
                "steps": [3, 1],
                "return": [10.5, -1.0],
                "outcome": ["terminal", "pit"],
                "seed": [0, 1],
            }
        ),
        steps=pd.DataFrame(
            {
                "episode": [0, 0, 0, 1],
                "t": [0, 1, 2, 0],
                "action": ["right", "right", "down", "up"],
                "reward": [0.0, 0.5, 10.0, -1.0],
            }
        ),
        positions=pd.DataFrame(
            {
                "episode": [0, 0, 0, 0, 0],
                "t": [0, 0, 0, 1, 1],
                "object": ["agent", "sword", "enemy", "agent", "sword"],
                "type": ["agent", "sword", "enemy", "agent", "sword"],
                "row": [0, 0, 9, 0, 0],
                "col": [0, 6, 1, 1, 6],
            }
        ),
        holding=pd.DataFrame({"episode": [0], "t": [2], "item": ["sword"]}),
        events=pd.DataFrame(
            {"episode": [0, 1], "t": [1, 0], "event": ["picked(sword)", "fell(pit)"]}
        ),
        relations=rel,
        meta={
            "checkpoint": "ckpt.pt",
            "env": "rgw2",
            "module": "predinet",
            "heads": 2,
            "relations": 2,
            "seed": 0,
        },
    )


def rows(df: pd.DataFrame) -> list[tuple]:
    return [tuple(r) for r in df.itertuples(index=False)]


def test_holds_are_thresholded_oriented_and_deduplicated() -> None:
    facts = extract_facts(recording(), threshold="abs:0.3")  # the thresholds of relations_facts.pl
    assert rows(facts["holds"]) == HOLDS
    assert rows(facts["threshold"]) == [(0, 0.3), (1, 0.3)]


def test_every_holds_fact_has_a_positive_value_above_threshold() -> None:
    rec = recording()
    facts = extract_facts(rec, threshold="abs:0.3")
    rel = rec.relations
    for e, t, j, a, b in rows(facts["holds"]):
        same = rel[(rel.episode == e) & (rel.t == t) & (rel.j == j)]
        forward = same[(same.a == a) & (same.b == b)]["value"]
        backward = same[(same.a == b) & (same.b == a)]["value"]
        assert (forward > 0.3).any() or (backward < -0.3).any(), (e, t, j, a, b)


def test_quantile_threshold_keeps_the_strongest_per_relation() -> None:
    facts = extract_facts(recording(), threshold="quantile:0.8")
    thr = dict(rows(facts["threshold"]))
    rel = recording().relations
    for j, value in thr.items():
        mags = rel.loc[rel.j == j, "value"].abs()
        assert value == pytest.approx(mags.quantile(0.8))


def test_trace_tables() -> None:
    facts = extract_facts(recording())
    assert rows(facts["episode"]) == [(0, 3, 10.5, "terminal"), (1, 1, -1.0, "pit")]
    assert rows(facts["object"]) == [("agent", "agent"), ("enemy", "enemy"), ("sword", "sword")]
    assert rows(facts["at"])[:2] == [(0, 0, "agent", 0, 0), (0, 0, "sword", 0, 6)]
    assert rows(facts["event"]) == [(0, 1, "picked(sword)"), (1, 0, "fell(pit)")]
    assert rows(facts["step"])[1] == (0, 1, "right", 0.5)
    assert facts["attention"].empty
    for name, cols in PREDICATES.items():
        assert tuple(facts[name].columns) == cols, name


def test_kb_meta_carries_the_threshold() -> None:
    meta = dict(rows(extract_facts(recording(), threshold="z:1")["kb_meta"]))
    assert meta == {
        "checkpoint": "ckpt.pt",
        "env": "rgw2",
        "module": "predinet",
        "heads": 2,
        "relations": 2,
        "seed": 0,
        "threshold": "z:1",
    }


def test_counts_and_summary() -> None:
    facts = extract_facts(recording(), threshold="abs:0.3")
    counts = facts.counts()
    assert counts["relation"] == len(RELATIONS)
    assert counts["episode"] == 2
    assert facts.n_facts == sum(counts.values())
    text = facts.summary()
    assert "2 episodes, 4 steps" in text
    assert "outcomes: pit 1, terminal 1" in text
    assert "thresholds (abs:0.3): r(0) 0.3, r(1) 0.3" in text


def test_strongest_relations_between_types() -> None:
    facts = extract_facts(recording(), threshold="abs:0.3")
    top = facts.strongest_relations(3)
    # (0, sword, enemy) held at (0, 0) (strongest head 1.0) and (0, 1) (0.5)
    assert rows(top) == [
        (0, "sword", "enemy", 2, 0.75),
        (1, "sword", "enemy", 2, 0.4375),
        (0, "sword", "agent", 1, 0.5),
    ]


def test_strongest_relations_leave_out_background_cells() -> None:
    rec = recording()
    extra = pd.DataFrame(
        [(0, 2, 1, 0, "sword", "empty", 5.0), (0, 2, 1, 1, "wall", "enemy", 5.0)],
        columns=rec.relations.columns,
    )
    rel = pd.concat([rec.relations, extra], ignore_index=True)
    facts = extract_facts(Recording(**{**rec.tables, "relations": rel}, meta=rec.meta), "abs:0.3")
    top = facts.strongest_relations(10)
    assert not top["a"].isin(["empty", "wall"]).any() and not top["b"].isin(["empty", "wall"]).any()
    assert len(facts["holds"]) == len(HOLDS) + 2  # holds/5 itself keeps them


def test_object_with_two_types_is_refused() -> None:
    rec = recording()
    pos = rec.positions.copy()
    pos.loc[4, "type"] = "enemy"
    with pytest.raises(ValueError, match="object 'sword' has more than one type"):
        extract_facts(Recording(**{**rec.tables, "positions": pos}, meta=rec.meta))


def test_bad_threshold_is_a_config_error() -> None:
    with pytest.raises(ConfigError, match="bad threshold 'top:3'"):
        extract_facts(recording(), threshold="top:3")


def test_empty_recording() -> None:
    facts = extract_facts(Recording())
    assert all(n == 0 for k, n in facts.counts().items() if k != "kb_meta")
    assert facts.strongest_relations().empty


def test_to_parquet(tmp_path: Path) -> None:
    facts = extract_facts(recording())
    facts.to_parquet(tmp_path / "facts")
    back = pd.read_parquet(tmp_path / "facts" / "holds.parquet")
    assert rows(back) == rows(facts["holds"])
    assert isinstance(facts, FactSet)


# --------------------------------------------------------------------------- property


relation_rows = st.lists(
    st.tuples(
        st.integers(0, 2),  # episode
        st.integers(0, 3),  # t
        st.integers(0, 1),  # head
        st.integers(0, 2),  # j
        st.sampled_from(["agent", "sword", "enemy", "key(red)"]),
        st.sampled_from(["agent", "sword", "enemy", "key(red)"]),
        st.floats(-2, 2, allow_nan=False).filter(lambda v: v != 0),
    ),
    max_size=40,
)


@settings(max_examples=60, deadline=None)
@given(rows=relation_rows, spec=st.sampled_from(["abs:0.5", "quantile:0.5", "z:0", "abs:0"]))
def test_holds_is_exactly_the_oriented_rows_above_threshold(rows: list[tuple], spec: str) -> None:
    rel = pd.DataFrame(rows, columns=["episode", "t", "head", "j", "a", "b", "value"])
    facts = extract_facts(Recording(relations=rel), threshold=spec)
    thr = dict(facts.thresholds().items())
    expected = set()
    for e, t, _h, j, a, b, v in rows:
        if abs(v) > thr[j]:
            expected.add((e, t, j, a, b) if v > 0 else (e, t, j, b, a))
    got = [tuple(r) for r in facts["holds"].itertuples(index=False)]
    assert len(got) == len(set(got))  # one fact per (E, T, J, A, B)
    assert set(got) == expected
    assert got == sorted(got, key=lambda r: (r[0], r[1], r[2], r[3], r[4]))
