"""``neurosym query``: run a Prolog goal against knowledge base files and print the answers.

    neurosym query --kb kb_out/rgw2/kb.pl --rules rules/rgw.pl "holds(E, T, R, agent, B)"
    neurosym query --kb kb.pl --bind A=sword --format json "holds(E, T, R, A, B)"

One column per output variable (names starting with ``_`` are left out);
compound values print as their canonical Prolog text. A goal without output
variables prints ``true`` or ``false``. ``--bind NAME=TERM`` passes a value
(read as Prolog term text: ``3``, ``sword``, ``key(red)``) through janus's
input dict, never through the goal text.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
import warnings
from typing import Any

from neurosym.errors import ConfigError, FactError

FORMATS = ("table", "json", "csv")


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("goal", metavar="GOAL", help="Prolog goal, e.g. 'object(Id, Type)'.")
    parser.add_argument(
        "--kb", action="append", required=True, metavar="FILE",
        help="Fact file (.pl or .qlf) to load; repeat for several.",
    )  # fmt: skip
    parser.add_argument(
        "--rules", action="append", default=[], metavar="FILE",
        help="Rule file to load after the facts; repeat for several.",
    )  # fmt: skip
    parser.add_argument(
        "--bind", action="append", default=[], metavar="NAME=TERM",
        help="Bind variable NAME to a value given as Prolog term text (repeatable).",
    )  # fmt: skip
    parser.add_argument(
        "--format", choices=FORMATS, default="table", help="Output format (default: table)."
    )
    parser.add_argument(
        "--limit",
        type=int,
        default=None,
        metavar="N",
        help="Print at most N answers (default: all).",
    )
    parser.add_argument(
        "--qlf", action="store_true", help="Load .pl fact files through .qlf (compiled when stale)."
    )


def _bindings(specs: list[str]) -> dict[str, Any]:
    from neurosym.terms import parse_term

    out: dict[str, Any] = {}
    for spec in specs:
        name, sep, text = spec.partition("=")
        if not sep or not name.strip():
            raise ConfigError(f"--bind {spec!r}: expected NAME=TERM, e.g. --bind A=sword")
        try:
            out[name.strip()] = parse_term(text)
        except FactError as exc:
            raise ConfigError(f"--bind {spec!r}: {exc}") from None
    return out


def _plain(value: Any) -> Any:
    """JSON/CSV-friendly value: compound terms become their Prolog text."""
    if isinstance(value, list):
        return [_plain(v) for v in value]
    if isinstance(value, str | int | float) or value is None:
        return value
    return str(value)


def _text(value: Any) -> str:
    if isinstance(value, list):
        from neurosym.terms import format_value

        return format_value(value)
    return "" if value is None else str(value)


def print_answers(names: list[str], answers: list[dict[str, Any]], fmt: str) -> None:
    """Print answers in ``fmt`` (table, json or csv) to stdout."""
    if fmt == "json":
        json.dump(
            [{k: _plain(v) for k, v in a.items()} for a in answers], sys.stdout, ensure_ascii=False
        )
        sys.stdout.write("\n")
    elif fmt == "csv":
        writer = csv.writer(sys.stdout, lineterminator="\n")
        writer.writerow(names)
        for a in answers:
            writer.writerow([_text(a[n]) for n in names])
    elif not names:
        print("true" if answers else "false")
    else:
        from rich.console import Console
        from rich.table import Table

        table = Table(*names)
        for a in answers:
            table.add_row(*(_text(a[n]) for n in names))
        console = Console()
        console.print(table)
        console.print(f"{len(answers)} answer{'s' if len(answers) != 1 else ''}", style="dim")


def run(args: argparse.Namespace) -> int:
    from neurosym.prolog.knowledge_base import KnowledgeBase

    if args.limit is not None and args.limit < 1:
        raise ConfigError(f"--limit must be at least 1, not {args.limit}")
    inputs = _bindings(args.bind)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        kb = KnowledgeBase(args.kb, rules=args.rules, qlf=args.qlf)
    for w in caught:
        print(f"neurosym query: warning: {w.message}", file=sys.stderr)
    with kb:
        names, rows = kb.solve(args.goal, limit=args.limit, **inputs)
    print_answers(names, [dict(zip(names, row, strict=True)) for row in rows], args.format)
    return 0
