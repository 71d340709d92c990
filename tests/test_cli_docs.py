"""docs/cli.md is what scripts/gen_cli_docs.py writes from the real parsers."""

from __future__ import annotations

import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def test_docs_cli_md_is_up_to_date() -> None:
    sys.path.insert(0, str(REPO / "scripts"))
    try:
        import gen_cli_docs
    finally:
        sys.path.remove(str(REPO / "scripts"))
    text = gen_cli_docs.render()
    page = (REPO / "docs" / "cli.md").read_text()
    assert page == text, "docs/cli.md is stale: run python scripts/gen_cli_docs.py"
    from neurosym.cli import COMMANDS

    for name in COMMANDS:  # every command has its section, and its flags are in it
        assert f"\n## neurosym {name}\n" in page
    assert "| `--rules FILE` |" in page and "| `--verbose` |" in page and "| `--dir DIR` |" in page
    # a hidden flag (help=SUPPRESS, e.g. report's --batch) is left out, as from --help
    report = page[page.index("\n## neurosym report\n") :]
    report = report[: report.index("\n## ", 1)]
    assert "SUPPRESS" not in page and "--batch" not in report
