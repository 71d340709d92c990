"""Write docs/cli.md, every ``neurosym`` command and flag, from the real argparse parsers.

    python scripts/gen_cli_docs.py            # rewrite docs/cli.md
    python scripts/gen_cli_docs.py --check    # exit 1 when docs/cli.md is not what it would write

Each command's parser is built by :func:`neurosym.cli.build_parser` (which
configures the selected command only, from its options dataclass), so the page says
what the code accepts.
tests/test_cli_docs.py fails when the page is stale.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "cli.md"
WIDTH = "100"
"""columns argparse lays the usage lines out in (it reads COLUMNS), fixed so the page is stable"""


def _subparsers(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def _cell(text: str) -> str:
    return " ".join(text.split()).replace("|", "\\|")


def _flag(action: argparse.Action) -> str:
    if not action.option_strings:
        return f"`{action.metavar or action.dest}`"
    names = ", ".join(action.option_strings)
    if action.nargs == 0:
        return f"`{names}`"
    metavar = action.metavar or (
        "{" + ",".join(map(str, action.choices)) + "}" if action.choices else action.dest.upper()
    )
    metavar = " ".join(metavar) if isinstance(metavar, tuple) else metavar
    return f"`{names} {metavar}`"


def _arguments(parser: argparse.ArgumentParser) -> list[str]:
    """A markdown table row per argument (positionals first, then options; -h left out)."""
    formatter = parser._get_formatter()
    rows = []
    for action in parser._actions:
        if isinstance(action, argparse._HelpAction | argparse._SubParsersAction):
            continue
        if action.help == argparse.SUPPRESS:  # hidden flags stay out of the page, as of --help
            continue
        if isinstance(action, argparse._VersionAction):
            text = "print the version and exit"
        else:
            text = formatter._expand_help(action) if action.help else ""
        if action.required and action.option_strings:
            text = f"(required) {text}"
        rows.append(f"| {_flag(action)} | {_cell(text)} |")
    return rows


def _section(title: str, parser: argparse.ArgumentParser, level: str) -> list[str]:
    lines = [f"{level} {title}", ""]
    if parser.description:
        lines += [parser.description, ""]
    lines += ["```", parser.format_usage().strip(), "```", ""]
    rows = _arguments(parser)
    if rows:
        lines += ["| argument | what it does |", "| --- | --- |", *rows, ""]
    for name, sub in _subparsers(parser).items():
        if title != "neurosym":
            lines += _section(f"{title} {name}", sub, level + "#")
    return lines


def render() -> str:
    """The text of docs/cli.md."""
    before = os.environ.get("COLUMNS")
    os.environ["COLUMNS"] = WIDTH
    try:
        return _render()
    finally:
        if before is None:
            del os.environ["COLUMNS"]
        else:
            os.environ["COLUMNS"] = before


def _render() -> str:
    from neurosym.cli import COMMANDS, build_parser

    top = build_parser([])
    lines = [
        "# Command-line reference",
        "",
        "Every `neurosym` command and flag, generated from the argparse parsers by",
        "`python scripts/gen_cli_docs.py` (do not edit by hand; `tests/test_cli_docs.py` fails when",
        "this page is stale). `neurosym COMMAND --help` prints the same. The parsers are built from",
        "each command's options dataclass, a flag per field with its docstring as help",
        "(`neurosym/flags.py`); the flags several commands share (`--env`, `--map`, `--env-option`,",
        "`--episodes`, `--seed`, `--greedy`/`--sample`, `--out`, `--quiet`, `--json`) are defined",
        "once there and mean the same in each.",
        "",
        "| command | what it does |",
        "| --- | --- |",
        *(
            f"| [`{name}`](#neurosym-{name}) | {_cell(text)} |"
            for name, (_, text) in COMMANDS.items()
        ),
        "",
        *_section("neurosym", top, "##"),
    ]
    for name in COMMANDS:
        parser = _subparsers(build_parser([name]))[name]
        lines += _section(f"neurosym {name}", parser, "##")
    return "\n".join(lines).rstrip() + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="exit 1 if docs/cli.md is stale")
    args = parser.parse_args(argv)
    text = render()
    if args.check:
        if not OUT.is_file() or OUT.read_text() != text:
            print(f"{OUT} is stale: run python scripts/gen_cli_docs.py", file=sys.stderr)
            return 1
        return 0
    from neurosym.atomic import write_bytes_atomic

    write_bytes_atomic(OUT, text.encode())
    print(f"wrote {OUT}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
