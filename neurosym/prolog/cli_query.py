"""``neurosym query``: run a Prolog goal against knowledge base files and print the answers.

    neurosym query --kb kb_out/rgw2/kb.pl --rules rgw "holds(E, T, R, agent, B)"
    neurosym query --kb kb.pl --bind A=sword --json "holds(E, T, R, A, B)"

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
Ctrl-C stops any goal: one line, exit 130. Output is rendered whole before
it is written (a value that cannot be shown prints nothing but one error
line); a closed stdout (``| head``) ends the command quietly with 141. The
table shows data as text: rich markup in atoms is escaped and control
characters are written as visible escapes.
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import math
import os
import signal
import sys
import threading
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

from neurosym.errors import ConfigError, FactError
from neurosym.flags import Json, add_options, option

INTERRUPTED = 130  # Ctrl-C
BROKEN_PIPE = 141  # stdout's reader went away (128 + SIGPIPE)
MAX_INFERENCES = (1 << 63) - 1
MAX_STACK_MB = 1 << 20  # 1 TB


def _rule_names() -> str:
    from neurosym.shipped import shipped_rule_names

    return ", ".join(shipped_rule_names()) or "none found"


@dataclass(kw_only=True)
class QueryOptions(Json):
    """``neurosym query``'s options."""

    RENAMED: ClassVar[dict[str, str]] = {
        "--format": "--format is now --json or --csv (the table is the default)",
    }
    goal: str = option(metavar="GOAL", positional=True)
    """Prolog goal, e.g. 'object(Id, Type)'"""
    kb: list[str] = option(metavar="FILE")
    """fact file (.pl or .qlf) to load as data (facts only, nothing runs); repeatable"""
    rules: list[str] = option(factory=list, metavar="FILE", fill=lambda: {"shipped": _rule_names()})
    """rule file to load as code, before the facts, or a shipped one by name ({shipped});
    repeatable"""
    trust: list[str] = option(factory=list, metavar="FILE", shown="none")
    """load this --kb file as code (its directives run; any .qlf); repeatable"""
    timeout: float | None = option(None, metavar="SECONDS", shown="none")
    """stop the goal after SECONDS of wall time"""
    max_inferences: int | None = option(None, metavar="N", shown="none")
    """stop the goal after N inferences"""
    stack_limit: float | None = option(None, metavar="MB", shown="SWI-Prolog's 1024")
    """Prolog stack the goal may use, in MB"""
    bind: list[str] = option(factory=list, metavar="NAME=TERM")
    """bind variable NAME to a value given as Prolog term text (repeatable)"""
    limit: int | None = option(None, metavar="N", shown="all")
    """print at most N answers"""
    qlf: bool = False
    """load .pl fact files through .qlf (compiled when stale)"""
    json: bool = option(False, exclusive="format")
    """print the answers as one JSON list of objects (default: a table)"""
    csv: bool = option(False, exclusive="format", group="output")
    """print the answers as CSV, a header row first"""


def configure(parser: argparse.ArgumentParser) -> None:
    add_options(parser, QueryOptions)


def output_format(args: QueryOptions) -> str:
    """table, json or csv, as --json and --csv say."""
    return "json" if args.json else "csv" if args.csv else "table"


def _bounds(args: QueryOptions) -> dict[str, Any]:
    """--timeout / --max-inferences / --stack-limit as KnowledgeBase.solve's keywords, checked."""
    from neurosym.prolog.knowledge_base import MAX_TIMEOUT

    out: dict[str, Any] = {}
    if args.timeout is not None:
        if not 0 < args.timeout <= MAX_TIMEOUT:  # also nan and inf
            raise ConfigError(
                f"--timeout must be a positive number of seconds up to {int(MAX_TIMEOUT):,}, "
                f"not {args.timeout}"
            )
        out["timeout"] = args.timeout
    if args.max_inferences is not None:
        if not 1 <= args.max_inferences <= MAX_INFERENCES:
            raise ConfigError(
                f"--max-inferences must be from 1 to 2**63-1, not {args.max_inferences}"
            )
        out["inferences"] = args.max_inferences
    if args.stack_limit is not None:
        if not 1 <= args.stack_limit <= MAX_STACK_MB:
            raise ConfigError(
                f"--stack-limit must be from 1 to {MAX_STACK_MB:,} (MB), not {args.stack_limit}"
            )
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
            raise ConfigError(f"--bind {name.strip()}: {exc}") from None
    return out


def _plain(value: Any) -> Any:
    """JSON-friendly value: compound terms become their Prolog text, as do
    infinities and NaN (JSON has no number for them)."""
    if isinstance(value, tuple):  # a Prolog list
        return [_plain(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    if isinstance(value, str | int | float) or value is None:
        return value
    return str(value)


def _text(value: Any) -> str:
    if isinstance(value, tuple):  # a Prolog list
        from neurosym.terms import format_value

        return format_value(value)
    return "" if value is None else str(value)


def render(names: list[str], answers: list[dict[str, Any]], fmt: str) -> str:
    """The whole output for ``answers`` in ``fmt`` (table, json or csv), as one string.

    Rendered before anything is written, so that a value that cannot be
    shown ends the command with one line and no half-printed output.
    """
    if fmt == "json":
        rows = [{k: _plain(v) for k, v in a.items()} for a in answers]
        return json.dumps(rows, ensure_ascii=False, allow_nan=False) + "\n"
    if fmt == "csv":
        out = io.StringIO()
        writer = csv.writer(out, lineterminator="\n")
        writer.writerow(names)
        for a in answers:
            writer.writerow([_text(a[n]) for n in names])
        return out.getvalue()
    if not names:
        return "true\n" if answers else "false\n"
    return _table(names, answers)


def _table(names: list[str], answers: list[dict[str, Any]]) -> str:
    """A rich table whose cells are data shown as text (markup escaped, control characters visible)."""
    from rich.console import Console
    from rich.table import Table

    from neurosym.display import show

    table = Table(*(show(n) for n in names))
    for a in answers:
        table.add_row(*(show(_text(a[n])) for n in names))
    console = Console()
    with console.capture() as captured:
        console.print(table)
        console.print(f"{len(answers)} answer{'s' if len(answers) != 1 else ''}", style="dim")
    return captured.get()


def _interruptible(work: Callable[[], Any]) -> Any:
    """``work()`` such that Ctrl-C stops it at once, whatever Prolog goal it runs.

    Python runs signal handlers in the main thread between its own steps, so
    while SWI-Prolog runs a goal there (``repeat, fail``), Ctrl-C would wait
    for the goal to end. Python's C-level handler also writes the signal's
    number to the wakeup fd at once; a watcher thread reads it (janus lets
    other threads run while Prolog works), says so in one line and exits
    with 130 without waiting for Prolog.
    """
    if threading.current_thread() is not threading.main_thread():
        return work()  # signals reach the main thread only: nothing to watch here
    read_fd, write_fd = os.pipe()
    os.set_blocking(write_fd, False)
    watcher = threading.Thread(target=_watch, args=(read_fd,), name="neurosym-ctrl-c", daemon=True)
    old_fd = signal.set_wakeup_fd(write_fd, warn_on_full_buffer=False)
    old_handler = signal.signal(signal.SIGINT, lambda *_: None)  # the watcher handles it
    watcher.start()
    try:
        return work()
    finally:
        signal.signal(signal.SIGINT, old_handler)
        signal.set_wakeup_fd(old_fd)
        os.close(write_fd)  # the watcher reads end-of-file and ends
        watcher.join()
        os.close(read_fd)


def _watch(read_fd: int) -> None:
    while data := os.read(read_fd, 64):
        if signal.SIGINT in data:
            print("neurosym query: interrupted", file=sys.stderr, flush=True)
            os._exit(INTERRUPTED)


def _solve(args: QueryOptions, bounds: dict[str, Any], inputs: dict[str, Any]) -> Any:
    """Load the KB and run the goal: (names, rows, load warnings)."""
    from neurosym.prolog.knowledge_base import KnowledgeBase
    from neurosym.shipped import rule_file

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rules = [rule_file(name) for name in args.rules]
        kb = KnowledgeBase(args.kb, rules=rules, qlf=args.qlf, trusted=args.trust)
    with kb:
        names, rows = kb.solve(args.goal, limit=args.limit, **bounds, **inputs)
    return names, rows, [_warning_text(w) for w in caught]


def _warning_text(caught: warnings.WarningMessage) -> str:
    """A load warning as one line that names the user's file and line when it has one."""
    if caught.lineno:
        return f"{caught.filename}:{caught.lineno}: {caught.message}"
    return str(caught.message)


def run(args: QueryOptions) -> int:
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
    names, rows, notes = _interruptible(lambda: _solve(args, bounds, inputs))
    for note in notes:
        print(f"neurosym query: warning: {note}", file=sys.stderr)
    text = render(names, [dict(zip(names, row, strict=True)) for row in rows], output_format(args))
    try:
        sys.stdout.write(text)
        sys.stdout.flush()
    except BrokenPipeError:  # the reader went away (| head): stop quietly
        _stdout_to_devnull()
        return BROKEN_PIPE
    return 0


def _stdout_to_devnull() -> None:
    """Point stdout at devnull, so that Python's flush at exit finds no closed pipe."""
    try:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    except (OSError, ValueError):
        pass
