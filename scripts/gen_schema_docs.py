"""Write docs/design.md's fact tables from the schema (neurosym/facts/schema.py).

    python scripts/gen_schema_docs.py            # rewrite the tables in docs/design.md
    python scripts/gen_schema_docs.py --check    # exit 1 when a table is not what it would write

Each table sits between ``<!-- schema:GROUP -->`` and ``<!-- /schema:GROUP -->`` lines;
everything else on the page is left as it is. tests/facts/test_schema.py fails when a table is stale.
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DESIGN = ROOT / "docs" / "design.md"
BLOCK = re.compile(r"(<!-- schema:(\w+) -->\n)(.*?)(<!-- /schema:\2 -->)", re.S)


def render(text: str) -> str:
    """``text`` with every schema block replaced by its group's generated table."""
    sys.path.insert(0, str(ROOT))
    from neurosym.facts.schema import markdown_table

    return BLOCK.sub(lambda m: f"{m.group(1)}{markdown_table(m.group(2))}\n{m.group(4)}", text)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="only check; exit 1 when stale")
    args = parser.parse_args()
    text = DESIGN.read_text()
    new = render(text)
    if args.check:
        sys.exit(0 if new == text else 1)
    if new != text:
        DESIGN.write_text(new)


if __name__ == "__main__":
    main()
