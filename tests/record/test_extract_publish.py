"""A new extract run into a folder removes the report page that described the run before."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

import neurosym.publish
from neurosym.cli import main
from neurosym.facts.tables import extract_facts
from neurosym.record.extraction import write_outputs
from neurosym.record.recording import Recording


@pytest.fixture(scope="session")
def extract(scripted_recording):  # noqa: ANN201
    """``extract(...)``, built from the shared builders."""
    def extract(out: Path, seed: int) -> None:
        rec = scripted_recording()
        rec = Recording(**rec.tables, meta={**rec.meta, "seed": seed})
        write_outputs(out, rec, extract_facts(rec), ("pl",))
    return extract


def test_a_new_run_removes_the_report_page_in_the_rename_that_publishes_it(
    extract,
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "kb"
    extract(out, seed=0)
    assert main(["report", "--recording", str(out), "--quiet"]) == 0  # writes out/index.html
    page = (out / "index.html").read_text()
    assert "seed 0" in page
    switch = neurosym.publish._switch
    seen = []

    def watched(store: Path, run: str) -> None:
        seen.append((out / "index.html").read_text() == page)  # the old page until the rename
        switch(store, run)
        seen.append(os.path.exists(out / "index.html"))  # and gone with it

    monkeypatch.setattr(neurosym.publish, "_switch", watched)
    extract(out, seed=777)
    assert seen == [True, False]
    assert sorted(p.name for p in out.iterdir()) == [".neurosym", "kb.pl", "recording"]
    assert "kb_meta(seed,777)." in (out / "kb.pl").read_text()

    (out / "index.html").write_text("<html><title>my notes</title></html>")  # not neurosym's
    extract(out, seed=5)
    assert (out / "index.html").read_text() == "<html><title>my notes</title></html>"
