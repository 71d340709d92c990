"""Agent cards: what a shipped agent is for and how it scores, stored in its own checkpoint.

A card is the checkpoint entry ``card`` (plain values; :func:`load_agent` keeps
it in ``agent.meta["card"]``, every other reader ignores it)::

    {"role": "one line: what a user picks this agent for",
     "eval_command": "neurosym eval --checkpoint ... --episodes 300 --seed 3000000000 [--sample] --json",
     "held_out": {"env": "rgw-random", "env_options": {...}, "episodes": 300, "seed": 3000000000,
                  "sampled": {"success_rate": 0.987, ...}, "greedy": {...}}}

The figures under ``sampled`` and ``greedy`` carry the names of
``neurosym eval --json`` (``success_rate``, and on RGW ``optimal_rate``,
``sword_first_guarded``, ``no_detour_decoy``), measured by ``eval_command``
(``--sample`` for the sampled ones) on levels no training run played.
:func:`write_card` replaces the card and nothing else: the weights and every
other entry are written back as they were read.
"""

from __future__ import annotations

import io
import os
import shlex
from pathlib import Path
from typing import Any

from neurosym.errors import CheckpointError

CARD_KEYS = ("role", "eval_command", "held_out")
MODES = ("sampled", "greedy")


def check_card(card: Any, where: str = "card") -> dict[str, Any]:
    """``card`` if it has the shape above (one-line CheckpointError naming what is wrong)."""
    if not isinstance(card, dict):
        raise CheckpointError(f"{where} is a {type(card).__name__}, not a dict")
    missing = [k for k in CARD_KEYS if k not in card]
    if missing:
        raise CheckpointError(f"{where} lacks {', '.join(missing)}")
    held = card["held_out"]
    if not isinstance(held, dict) or not all(isinstance(held.get(m), dict) for m in MODES):
        raise CheckpointError(f"{where}: held_out needs 'sampled' and 'greedy' figures")
    for mode in MODES:
        rate = held[mode].get("success_rate")
        if not isinstance(rate, float) or not 0.0 <= rate <= 1.0:
            raise CheckpointError(f"{where}: held_out.{mode}.success_rate must be in [0, 1]")
    return card


def write_card(path: str | os.PathLike[str], card: dict[str, Any]) -> Path:
    """Store ``card`` in the checkpoint at ``path``, atomically; the weights are not touched."""
    import torch

    from neurosym.agent.checkpoint import read_checkpoint
    from neurosym.atomic import write_bytes_atomic
    from neurosym.shipped import checkpoint_file

    path = checkpoint_file(path)
    read_checkpoint(path)  # refuses anything that is not a readable neurosym checkpoint
    payload = torch.load(path, map_location="cpu", weights_only=True)
    payload["card"] = check_card(card, f"the card for {path}")
    buf = io.BytesIO()
    torch.save(payload, buf)
    return write_bytes_atomic(path, buf.getvalue())


def learner(meta: dict[str, Any]) -> str:
    """The learner that made the agent: its train config's ``algo``, else its last train command's.

    Agents whose file has no train config were made before it was stored; their
    command names ``--algo`` when it was not the default (a3c).
    """
    config = meta.get("train_config") or {}
    if config.get("algo"):
        return str(config["algo"])
    algo = "a3c"
    for command in str(meta.get("command") or "").split(" && "):
        words = shlex.split(command)
        if words[:2] == ["neurosym", "train"] and "--algo" in words[:-1]:
            algo = words[words.index("--algo") + 1]
    return algo


def held_out_text(card: dict[str, Any] | None) -> str:
    """``'98.7/92.3'``: held-out success in percent, sampled / greedy; ``'-'`` without a card."""
    if not card:
        return "-"
    held = card["held_out"]
    return "/".join(f"{100 * held[m]['success_rate']:.1f}" for m in MODES)
