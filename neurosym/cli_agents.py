"""``neurosym agents``: the shipped agents, each described by its own file.

    neurosym agents [--dir DIR] [--json]

Lists the checkpoints of the shipped zoo (the clone's checkpoints/, or the
copy inside an installed package; see :mod:`neurosym.shipped`), or those in
``--dir``: name, env, module, learner, frames, the held-out success stored in
the file's card (:mod:`neurosym.cards`) and what the agent is for. A shipped
agent's name works wherever a checkpoint is asked for
(``--checkpoint rgw2-predinet``). A file that is not a neurosym checkpoint is
skipped with one line on stderr; an agent whose card is malformed is listed
with its held-out figures and role blank, and one line on stderr names the
field (its weights still play; ``--json`` gives ``card: null`` and the reason
as ``card_error``).
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from neurosym.errors import CheckpointError, ConfigError
from neurosym.flags import Json, add_options, option


@dataclass(kw_only=True)
class AgentsOptions(Json):
    """``neurosym agents``'s options."""

    dir: str | None = option(None, metavar="DIR")
    """list the agents (*.pt) in DIR instead of the shipped ones"""
    json: bool = False
    """print one JSON list"""


def configure(parser: argparse.ArgumentParser) -> None:
    add_options(parser, AgentsOptions)


def agent_folder(folder: str | None) -> Path:
    """``--dir``, or the shipped agents' folder (one-line ConfigError when there is none)."""
    from neurosym.shipped import checkpoints_dir

    if folder is not None:
        path = Path(folder)
        if not path.is_dir():
            raise ConfigError(f"--dir {folder}: no such folder")
        return path
    found = checkpoints_dir()
    if found is None:
        raise ConfigError(
            "no shipped agents found: neither checkpoints/ beside the package nor "
            "neurosym/checkpoints/ inside it holds a .pt file (give --dir DIR)"
        )
    return found


def describe(path: Path) -> dict[str, Any]:
    """One agent's entry: what its file says about it (CheckpointError for a bad file)."""
    from neurosym.agent.checkpoint import read_checkpoint
    from neurosym.cards import card_of, learner

    payload = read_checkpoint(path)  # its metadata plain and bounded, its counts not negative
    card, problem = card_of(payload, f"the card in {path.name}")
    return {
        "name": path.stem,
        "file": str(path.resolve()),
        "env": payload["env"],
        "env_options": payload["env_kwargs"],
        "module": payload["model_config"].module,
        "learner": learner(payload),
        "frames": payload["frames"],
        "card": card,
        "card_error": problem,
    }


def _frames(n: int) -> str:
    return f"{n / 1e6:.1f} M" if n >= 1_000_000 else f"{n / 1e3:.0f} k"


def print_table(agents: list[dict[str, Any]]) -> None:
    from rich.console import Console
    from rich.table import Table

    from neurosym.cards import held_out_text
    from neurosym.display import show

    table = Table(
        box=None,
        title="agents",
        title_justify="left",
        caption="held out: success in % on 300 levels of its env that no training run played "
        "(fixed-map agents: rgw-random's), sampled / greedy; frames: its last training run's",
        caption_justify="left",
    )
    for col in ("agent", "env", "module", "learner", "frames", "held out", "for"):
        table.add_column(col, justify="right" if col == "frames" else "left", no_wrap=True)
    for a in agents:
        role = (a["card"] or {}).get("role", "-")
        cells = (a["name"], a["env"], a["module"], a["learner"], _frames(a["frames"]),
                 held_out_text(a["card"]), role)  # fmt: skip
        table.add_row(*(show(c) for c in cells))
    # one line per agent at any terminal width: a wrapped row is harder to read than a long one
    console = Console(highlight=False)
    console.width = max(console.width, WIDTH)
    with console.capture() as out:
        console.print(table, crop=False)
    print("\n".join(line.rstrip() for line in out.get().splitlines()))


WIDTH = 148
"""columns the table is laid out in at least (its rows are about 135 characters)"""


def run(args: AgentsOptions) -> int:
    folder = agent_folder(args.dir)
    files = sorted(folder.glob("*.pt"))
    if not files:
        raise ConfigError(f"no agents (*.pt files) in {folder}")
    agents = []
    for path in files:
        try:
            agents.append(describe(path))
        except CheckpointError as exc:
            print(f"neurosym agents: skipped {path.name}: {exc}", file=sys.stderr)
            continue
        if agents[-1]["card_error"]:
            print(
                f"neurosym agents: {agents[-1]['card_error']}; its held-out figures are left blank",
                file=sys.stderr,
            )
    if args.json:
        print(json.dumps(agents))
    elif agents:
        print_table(agents)
    return 0
