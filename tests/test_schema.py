"""The fact schema is declared once (neurosym/schema.py); what is made from it agrees with it."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from neurosym import schema

REPO = Path(__file__).resolve().parents[1]


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
    assert schema.header_lines(["grid"]) == [
        "%!  grid(E, Rows, Cols): the size of episode E's map (the entity grid's shape)"
    ]
    assert [p.name for p in schema.group("probe")] == ["probe", "probe_untrained", "probe_skipped"]


def test_an_unknown_kind_is_refused() -> None:
    with pytest.raises(ValueError, match="unknown kind 'text'"):
        schema.Arg("a", "A", "text")
