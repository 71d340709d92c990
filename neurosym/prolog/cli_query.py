"""``neurosym query``: run a Prolog goal against knowledge base files and print the answers.

    neurosym query --kb kb_out/rgw2/kb.pl --rules rgw "holds(E, T, R, agent, B)"
    neurosym query --kb kb.pl --bind A=sword --format json "holds(E, T, R, A, B)"

One column per output variable (names starting with ``_`` are left out);
compound values print as their canonical Prolog text. A goal without output
variables prints ``true`` or ``false``. ``--bind NAME=TERM`` passes a value
(read as Prolog term text: ``3``, ``sword``, ``key(red)``) through janus's
input dict, never through the goal text.

Fact files (``--kb``) are data: they are read term by term and only facts
are accepted, so a KB someone sent you runs nothing when it loads; ``--trust
FILE`` loads that one file as code (directives run), and a ``.qlf`` is
loaded only when neurosym compiled it on this account or it is trusted.
Rule files (``--rules``) are code; a bare name (``rgw``) is a shipped one.
``--timeout``, ``--max-inferences`` and ``--stack-limit`` stop a runaway goal
with one line (no limit by default, beyond SWI-Prolog's own 1 GB stack).
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
import warnings
from pathlib import Path
from typing import Any

from neurosym.errors import ConfigError, FactError

FORMATS = ("table", "json", "csv")


def configure(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("goal", metavar="GOAL", help="Prolog goal, e.g. 'object(Id, Type)'.")
    parser.add_argument(
        "--kb", action="append", required=True, metavar="FILE",
        help="Fact file (.pl or .qlf) to load as data (facts only, nothing runs); repeatable.",
    )  # fmt: skip
    parser.add_argument(
        "--rules", action="append", default=[], metavar="FILE",
        help="Rule file to load as code, before the facts, or a shipped one by name "
        "(rgw, boxworld, relations, causal, meaning); repeatable.",
    )  # fmt: skip
    parser.add_argument(
        "--trust", action="append", default=[], metavar="FILE",
        help="Load this --kb file as code (its directives run; any .qlf); repeatable. Default: none.",
    )  # fmt: skip
    parser.add_argument(
        "--timeout", type=float, default=None, metavar="SECONDS",
        help="Stop the goal after SECONDS of wall time (default: none).",
    )  # fmt: skip
    parser.add_argument(
        "--max-inferences", type=int, default=None, metavar="N",
        help="Stop the goal after N inferences (default: none).",
    )  # fmt: skip
    parser.add_argument(
        "--stack-limit", type=float, default=None, metavar="MB",
        help="Prolog stack the goal may use, in MB (default: SWI-Prolog's 1024).",
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


def _bounds(args: argparse.Namespace) -> dict[str, Any]:
    """--timeout / --max-inferences / --stack-limit as KnowledgeBase.solve's keywords, checked."""
    out: dict[str, Any] = {}
    if args.timeout is not None:
        if not args.timeout > 0:
            raise ConfigError(f"--timeout must be a positive number of seconds, not {args.timeout}")
        out["timeout"] = args.timeout
    if args.max_inferences is not None:
        if args.max_inferences < 1:
            raise ConfigError(f"--max-inferences must be at least 1, not {args.max_inferences}")
        out["inferences"] = args.max_inferences
    if args.stack_limit is not None:
        if not args.stack_limit >= 1:
            raise ConfigError(f"--stack-limit must be at least 1 (MB), not {args.stack_limit}")
        out["stack_limit"] = int(args.stack_limit * 1024 * 1024)
    return out


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
    from neurosym.shipped import rule_file

    if args.limit is not None and args.limit < 1:
        raise ConfigError(f"--limit must be at least 1, not {args.limit}")
    bounds = _bounds(args)
    inputs = _bindings(args.bind)
    kbs = {Path(p).resolve() for p in args.kb}
    for name in args.trust:
        if Path(name).resolve() not in kbs:
            raise ConfigError(
                f"--trust {name}: not one of the --kb files (trust names a --kb FILE)"
            )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rules = [rule_file(name) for name in args.rules]
        kb = KnowledgeBase(args.kb, rules=rules, qlf=args.qlf, trusted=args.trust)
    for w in caught:
        print(f"neurosym query: warning: {w.message}", file=sys.stderr)
    with kb:
        names, rows = kb.solve(args.goal, limit=args.limit, **bounds, **inputs)
    print_answers(names, [dict(zip(names, row, strict=True)) for row in rows], args.format)
    return 0
