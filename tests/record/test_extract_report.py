"""The summary ``neurosym extract`` prints, in process, for Box-World and for an MHDPA agent."""

from __future__ import annotations

import io
import re
from pathlib import Path

import pytest

from neurosym.facts.tables import extract_facts
from neurosym.record.extraction import write_outputs
from neurosym.record.recording import Recording
from neurosym.reports.terminal import QUERIES, print_report


def report(
    rec: Recording,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    formats: tuple[str, ...] = ("pl",),
    verbose: bool = True,
) -> str:
    facts = extract_facts(rec, threshold="quantile:0.9")
    written = write_outputs(tmp_path / "out", rec, facts, formats)
    print_report(rec, facts, written, kb=written.get("kb.pl"), verbose=verbose)
    return capsys.readouterr().out


def test_boxworld_report_answers_every_question(
    explorer_recording,
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    rec = explorer_recording()
    text = report(rec, tmp_path, capsys)
    for title, _goal, _var in QUERIES["boxworld"]:
        assert title in text
    assert "key(" in text and "lock(" in text  # key opens lock answers, as Prolog text
    taken = int((rec.episodes["outcome"] == "distractor").sum())
    # every bw2 level has a distractor box: the count is of the episodes with one
    flat = re.sub(r"\s*│\s*|\n\s+", " ", text)
    assert re.search(
        rf"distractor taken [0-9, ]+ \({taken} of {len(rec.episodes)} episodes with a distractor\)",
        flat,
    ), flat


def test_levels_without_a_distractor_say_so(
    explorer_recording,
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """bw1 has no distractor box: its distractor questions say so instead of "0 of 4 episodes"."""
    rec = explorer_recording("bw1", episodes=4)
    for verbose in (False, True):
        text = report(rec, tmp_path / str(verbose), capsys, verbose=verbose)
        for title in ("distractor taken", "distractor avoided"):
            assert re.search(rf"\n {title} +│ no distractor on these levels +\n", text), text


def test_counts_say_what_they_count(explorer_recording, scripted_recording, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Visit orders: the three most common, of how many distinct orders; other lists: answers."""
    rec = scripted_recording()
    text = report(rec, tmp_path, capsys, verbose=True)
    orders = rec.events.groupby("episode")["event"].agg(tuple).nunique()
    assert orders == 5  # the five plans visit the objects in five different orders
    flat = re.sub(r"\s*│\s*|\n\s+", " ", text)
    assert "x1, [sword,teleport,pit] x1  (3 most common of 5 distinct orders)" in flat, flat
    bw = report(explorer_recording(), tmp_path / "bw", capsys, verbose=False)
    flat = re.sub(r"\s*│\s*|\n\s+", " ", bw)
    assert re.search(r"key opens lock (key\(\w+\)-lock\(\w+\), ){3}\.\.\.  \(\d+ answers\)", flat)


def test_mhdpa_report(scripted_recording, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    text = report(scripted_recording("mhdpa"), tmp_path, capsys)
    assert "MHDPA: attention/6 holds the strongest key of every query cell" in text
    assert "sword before enemy" in text and "0  (1 of 5 episodes)" in text


def test_report_without_a_prolog_kb(scripted_recording, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    text = report(scripted_recording(), tmp_path, capsys, formats=("parquet",))
    assert "rule answers: none (they need the Prolog KB: --format pl)" in text
    assert not (tmp_path / "out" / "kb.pl").exists()
    assert (tmp_path / "out" / "facts" / "holds.parquet").is_file()


def test_report_shows_data_as_text(
    scripted_recording,
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Markup, hyperlinks and escape codes from a recording print as the characters they are."""
    rec = scripted_recording()
    rec = Recording(**rec.tables, meta=rec.meta)  # a copy: the fixture is shared
    link = "[link=https://evil.example]click[/link]"
    rec.meta["checkpoint"] = link + "\x1b[31m"
    rec.meta["seed"] = "[bold]7[/bold]"
    monkeypatch.setenv("COLUMNS", "200")
    text = report(rec, tmp_path, capsys)
    assert "\x1b" not in text
    assert f"of {link}\\e[31m (" in text and "seed [bold]7[/bold])" in text


def test_report_columns_of_values_never_wrap(
    scripted_recording,
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """In a narrow terminal a value such as "29 %" stays whole; text columns and headers wrap."""
    from rich.console import Console
    from rich.table import Table

    from neurosym.reports.terminal import add_rows

    table = Table(show_edge=False)
    for col in ("head", "two objects", "top pairs (share of states)"):
        table.add_column(col)
    add_rows(table, [("0", "100 %", "agent-pit, sword-enemy")], whole=(0, 1))
    console = Console(width=18, file=io.StringIO(), color_system=None)
    console.print(table)
    text = console.file.getvalue()
    assert "│ 100 % │" in text, text  # rich alone gives "100" over "%" at this width
    monkeypatch.setenv("COLUMNS", "45")
    text += report(scripted_recording(), tmp_path, capsys)
    cells = [c.strip() for line in text.splitlines() for c in re.split(r"[│┃]", line)]
    assert "%" not in cells, text  # a "%" alone: a percentage split over two lines


def test_report_lines_break_between_phrases(
    scripted_recording,
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Output to a file or pipe is 80 columns wide: the header and the counts break between
    phrases ("4 heads", "event 89" stay whole), and a path is never broken."""
    rec = scripted_recording()
    rec = Recording(
        **rec.tables, meta={**rec.meta, "checkpoint": "checkpoints/" + "x" * 90 + ".pt"}
    )
    monkeypatch.setenv("COLUMNS", "80")
    lines = report(rec, tmp_path, capsys, verbose=True).splitlines()
    assert lines[:3] == [
        "rgw2: 5 episodes (greedy, seed 0)",
        "  of checkpoints/" + "x" * 90 + ".pt",
        "  (predinet, 2 heads, 3 relations)",
    ]
    facts = next(i for i, line in enumerate(lines) if line.startswith("facts: "))
    assert lines[facts : facts + 3] == [
        "facts: kb_meta 11, object 8, episode 5, grid 5, terrain 125, optimal_visits 5,",
        "  step 164, at 1308, holding 40, event 89, attends 656, relation 984, holds 98,",
        "  threshold 3 (3501 in all)",
    ]
    assert lines[-1] == f"wrote {tmp_path / 'out' / 'recording'}"
