"""``neurosym envs``: list the environments (short name, gymnasium id, one line each).

The Minigrid family lists every id Farama's Minigrid registers (``MiniGrid-*``, ``BabyAI-*``).

``--json`` prints one JSON object per line instead of a table; ``--show NAME``
prints the first state of one environment as text.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass

from neurosym.envs.registration import all_entries, canonical_name
from neurosym.flags import Json, add_options, option


@dataclass(kw_only=True)
class EnvsOptions(Json):
    """``neurosym envs``'s options."""

    show: str | None = option(None, metavar="NAME")
    """print the first state of one environment as text (seed 0)"""
    json: bool = False
    """print one JSON object per line"""


def configure(parser: argparse.ArgumentParser) -> None:
    add_options(parser, EnvsOptions)


def run(args: EnvsOptions) -> int:
    if args.show:
        return _show(args.show)
    entries = all_entries()  # neurosym's own, then every Minigrid and BabyAI id
    if args.json:
        for e in entries:
            row = {"name": e.short, "id": e.id, "family": e.family, "description": e.description}
            print(json.dumps(row))
        return 0
    from rich.console import Console
    from rich.table import Table

    from neurosym.display import show

    table = Table(title="neurosym environments", title_justify="left")
    for column in ("name", "id", "family"):  # names never wrap; the description does, at spaces
        table.add_column(column, no_wrap=True)
    table.add_column("description")
    for e in entries:
        table.add_row(show(e.short), show(e.id), show(e.family), show(e.description))
    console = Console()
    if not console.is_terminal:  # piped: never wrap, whatever width rich guesses
        rows = [(e.short, e.id, e.family, e.description) for e in entries]
        natural = sum(max(len(r[i]) for r in rows) + 3 for i in range(4)) + 1
        console = Console(width=max(natural, console.width))
    console.print(table)
    return 0


def _show(name: str) -> int:
    from neurosym.envs.registration import make

    env = make(canonical_name(name), render_mode="ansi")
    env.reset(seed=0)
    text = env.render()
    if not sys.stdout.isatty():
        import re

        text = re.sub(r"\x1b\[[0-9;]*m", "", text)
    print(text, end="" if text.endswith("\n") else "\n")
    return 0
