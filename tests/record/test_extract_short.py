"""`neurosym extract` prints a short report by default and the full one with --verbose."""

from __future__ import annotations

from pathlib import Path

import pytest

from neurosym.facts.tables import extract_facts
from neurosym.record.extraction import write_outputs
from neurosym.reports.terminal import print_report

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def report(scripted_recording):  # noqa: ANN201
    """``report(...)``, built from the shared builders."""
    def report(tmp_path: Path, capsys: pytest.CaptureFixture[str], verbose: bool) -> str:
        rec = scripted_recording()
        facts = extract_facts(rec, threshold="quantile:0.9")
        written = write_outputs(tmp_path / "out", rec, facts, ("pl",))
        print_report(rec, facts, written, kb=written.get("kb.pl"), verbose=verbose)
        return capsys.readouterr().out
    return report


def test_the_short_report_leaves_out_the_tables_the_verbose_one_has(
    report,
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    short, full = report(tmp_path, capsys, False), report(tmp_path, capsys, True)
    for text in (short, full):
        assert "heads: two arguments on two different objects" in text
        assert (
            "  (share of states with the head's two arguments on two objects; top pairs)\n" in text
        )
        assert "rules/rgw.pl" in text and "sword before enemy" in text
        assert "  (answers from kb.pl; ask your own with neurosym query --rules rgw)\n" in text
    for section in ("  (steps, return and how each episode ended)\n", "thresholds (quantile:0.9)",
                    "on or beside two objects"):  # fmt: skip
        assert section in full and section not in short, section
    assert "1 of 5 episodes" in short and "0  (1 of 5 episodes)" in full  # a count, not the list
    assert "facts: " in short and "(--verbose: by predicate, and the relation tables)" in short
    assert len(short.splitlines()) < len(full.splitlines())


def test_extract_verbose_flag(run_neurosym, tmp_path: Path) -> None:
    args = ("extract", "--checkpoint", REPO / "checkpoints" / "rgw2-predinet.pt", "--episodes", "1")
    short = run_neurosym(*args, "--out", tmp_path / "a")
    full = run_neurosym(*args, "--out", tmp_path / "b", "--verbose")
    assert short.returncode == 0 and full.returncode == 0, short.stderr + full.stderr
    assert "steps, return and how each episode ended" not in short.stdout
    assert "steps, return and how each episode ended" in full.stdout
    assert "1 of 1 episodes" in short.stdout and "0  (1 of 1 episodes)" in full.stdout


def test_missing_rule_files_are_said_in_one_line(
    report,
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import neurosym.shipped

    monkeypatch.setattr(neurosym.shipped, "rules_dir", lambda: None)
    text = report(tmp_path, capsys, False)
    assert (
        "rule answers: none (neurosym's rule files are missing: no rules/ folder found)\n" in text
    )
    assert "rules/rgw.pl" not in text
