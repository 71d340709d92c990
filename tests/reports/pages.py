"""Helpers of the report-page tests: the page's embedded data, a folder as extract writes it,
the page built from it, and the hostile text a KB may carry."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

from neurosym.cli import main
from neurosym.facts.tables import extract_facts
from neurosym.record.extraction import write_outputs
from neurosym.record.recording import Recording

DATA = re.compile(r'<script type="application/json" id="report-data">(.*?)</script>', re.S)


def embedded(html: str) -> dict:
    """The page's JSON data block, parsed."""
    blocks = DATA.findall(html)
    assert len(blocks) == 1
    return json.loads(blocks[0])


def extract_folder(rec: Recording, out: Path) -> Path:
    """What ``neurosym extract --out out`` writes for ``rec`` (kb.pl, recording/)."""
    write_outputs(out, rec, extract_facts(rec, threshold="quantile:0.9"), ("pl",))
    return out


def report(folder: Path, *extra: str) -> str:
    assert main(["report", "--recording", str(folder), "--quiet", *extra]) == 0
    return (folder / "index.html").read_text(encoding="utf-8")


SCRIPT = "</script><script>alert(1)</script>"
TAG = "<img src=x onerror=alert(2)>"
HOSTILE = f"'{SCRIPT}'"  # quoted atoms: legal Prolog, so a KB can hold them
HOSTILE_EVENT = f"'{TAG}'"


def errors(driver: Any) -> list[str]:
    """Console messages of level SEVERE since the last call (CSP violations included)."""
    return [e["message"] for e in driver.get_log("browser") if e["level"] == "SEVERE"]


def open_page(driver: Any, page: Path, fragment: str = "") -> None:
    """Load ``page`` afresh (not a fragment change of the page already open)."""
    driver.get("about:blank")
    driver.get(page.resolve().as_uri() + fragment)
