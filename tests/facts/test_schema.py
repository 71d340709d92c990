"""The fact schema is declared once (neurosym/facts/schema.py); what is made from it agrees with it."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from neurosym.errors import PrologError
from neurosym.facts import schema

REPO = Path(__file__).resolve().parents[2]


def test_design_md_tables_are_generated_from_the_schema() -> None:
    proc = subprocess.run(
        [sys.executable, str(REPO / "scripts" / "gen_schema_docs.py"), "--check"],
        capture_output=True, text=True,
    )
    assert proc.returncode == 0, "docs/design.md's fact tables are stale: run python scripts/gen_schema_docs.py"


def test_the_generator_replaces_a_stale_table() -> None:
    sys.path.insert(0, str(REPO / "scripts"))
    import gen_schema_docs

    page = "intro\n<!-- schema:probe -->\n| stale |\n<!-- /schema:probe -->\nend\n"
    out = gen_schema_docs.render(page)
    assert out.startswith("intro\n<!-- schema:probe -->\n| fact | arguments |\n")
    assert "| stale |" not in out and out.endswith("<!-- /schema:probe -->\nend\n")
    assert "| `probe_skipped(Predicate, Reason)` |" in out


def test_declarations() -> None:
    holds = schema.SCHEMA["holds"]
    assert holds.indicator == "holds/5"
    assert holds.head == "holds(E, T, r(J), A, B)"
    assert holds.columns == ("episode", "t", "j", "a", "b")
    assert holds.term_columns == ("j", "a", "b")
    assert schema.indicators(["at", "threshold"]) == ["at/5", "threshold/2"]
    assert schema.header_lines("grid") == [
        "%!  grid(?E, ?Rows, ?Cols)",
        "%   the size of episode E's map (the entity grid's shape)",
    ]
    assert [p.name for p in schema.group("probe")] == ["probe", "probe_untrained", "probe_skipped"]


def test_an_unknown_kind_is_refused() -> None:
    with pytest.raises(ValueError, match="unknown kind 'text'"):
        schema.Arg("a", "A", "text")


def test_a_readers_goal_follows_the_declaration() -> None:
    assert schema.SCHEMA["attends"].goal(episode="E", t="T", row="R") == (
        "attends(E, T, _, _, _, R, _, _)"
    )
    assert schema.SCHEMA["holds"].goal(j="r(J)", a="X") == "holds(_, _, r(J), X, _)"
    with pytest.raises(ValueError, match=r"^at/5 has no column object; its columns: episode, t, id, row, col$"):
        schema.SCHEMA["at"].goal(object="O")
    with pytest.raises(ValueError, match=r"^at/5: 'x\), halt, at\(X' is not a Prolog variable"):
        schema.SCHEMA["at"].goal(id="x), halt, at(X")


def test_an_extract_kb_documents_and_declares_each_predicate(tmp_path: Path, swipl: Path) -> None:
    from neurosym.facts.tables import extract_facts
    from neurosym.prolog.knowledge_base import KnowledgeBase
    from neurosym.record.recording import Recording

    path = extract_facts(Recording()).to_prolog(tmp_path / "kb.pl")
    text = path.read_text(encoding="utf-8")
    assert (
        ":- dynamic attends/8.\n"
        "\n"
        "%!  relation(?E, ?T, ?Head, ?J, ?A, ?B, ?Value)\n"
        "%   PrediNet: D^h_j between the two attended entities A (arg 1) and B (arg 2)\n"
        ":- dynamic relation/7.\n"
        "\n"
        "%!  holds(?E, ?T, ?r(J), ?A, ?B)\n"
    ) in text
    declared = [line for line in text.splitlines() if line.startswith(":- dynamic")]
    documented = [line for line in text.splitlines() if line.startswith("%!")]
    trace = schema.group(schema.TRACE)
    assert declared == [f":- dynamic {p.indicator}." for p in trace]
    assert documented == [schema.header_lines(p.name)[0] for p in trace]
    assert text.endswith(":- dynamic faithfulness/5.\n\nkb_meta(threshold,'quantile:0.9').\n")
    with KnowledgeBase(path) as kb:  # the safe reader takes the header; no table raises
        assert kb.query("relation(_, _, _, _, _, _, _)") == []
    proc = subprocess.run(
        [str(swipl), "-q", "-g", f"consult('{path}'), aggregate_all(count, kb_meta(_, _), N), "
         "print(N), halt", "-t", "halt(1)"],
        capture_output=True, text=True, timeout=60,
    )
    assert (proc.returncode, proc.stdout, proc.stderr) == (0, "1", "")


OLD_KB = """:- dynamic holding/3.
:- dynamic event/3.
:- dynamic attends/8.
:- dynamic holds/5.
:- dynamic attention/6.
:- dynamic kb_meta/2.
object(agent,agent).
object(sword,sword).
at(0,0,agent,0,0).
at(0,0,sword,0,1).
at(0,1,agent,0,1).
step(0,0,right,0.0).
"""


def test_the_strategy_reader_reads_a_kb_lacking_terrain_and_grid_as_none(tmp_path: Path) -> None:
    from neurosym.induce.strategy_data import load_trace

    kb = tmp_path / "old.pl"  # written before grid/3 and terrain/4 existed
    kb.write_text(OLD_KB, encoding="utf-8")
    trace = load_trace(kb)
    assert trace.terrain.empty and list(trace.terrain.columns) == ["E", "R", "C", "Ty"]
    assert trace.grid.empty and list(trace.grid.columns) == ["E", "Rows", "Cols"]
    assert trace.at.to_dict("list") == {
        "E": [0, 0, 0], "T": [0, 0, 1], "O": ["agent", "sword", "agent"], "R": [0, 0, 0],
        "C": [0, 1, 1],
    }
    assert trace.object.to_dict("list") == {"O": ["agent", "sword"], "Ty": ["agent", "sword"]}
    assert trace.step.to_dict("list") == {"E": [0], "T": [0], "A": ["right"]}
    (tmp_path / "no_event.pl").write_text(OLD_KB.replace(":- dynamic event/3.\n", ""))
    with pytest.raises(PrologError, match=r"^Unknown procedure: event/3$"):
        load_trace(tmp_path / "no_event.pl")


def test_the_strategy_notes_name_what_each_feature_set_reads() -> None:
    from neurosym.induce.strategy_writer import READS

    assert READS == {
        "world": "at/5, holding/3, object/2, grid/3, terrain/4",
        "relations": "at/5 and object/2 (to map cells and entities to objects), attends/8, "
        "holds/5, attention/6",
        "both": "at/5, holding/3, object/2, grid/3, terrain/4, attends/8, holds/5, attention/6",
    }
