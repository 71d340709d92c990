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

import os
import shlex
from pathlib import Path
from typing import Any

from neurosym.errors import CheckpointError

CARD_KEYS = ("role", "eval_command", "held_out")
MODES = ("sampled", "greedy")

FIGURE_LABELS = {
    "success_rate": "success",
    "optimal_rate": "optimal route",
    "sword_first_guarded": "sword first when guarded",
    "no_detour_decoy": "no detour for a decoy sword",
    "sword_taken_decoy": "decoy sword taken",
    "mean_return": "mean return",
    "mean_optimal_return": "mean optimal return",
    "guarded_episodes": "guarded levels",
    "decoy_episodes": "decoy levels",
}
"""readable names of ``neurosym eval --json``'s figures, as a card shows them"""

RATES = frozenset(
    ("success_rate", "optimal_rate", "sword_first_guarded", "no_detour_decoy", "sword_taken_decoy")
)
"""figures that are shares of episodes (in [0, 1]; shown in percent)"""


def figure_label(name: str) -> str:
    """``sword_first_guarded`` -> ``sword first when guarded``; an unknown name with spaces."""
    return FIGURE_LABELS.get(name, name.replace("_", " "))


def figure_text(name: str, value: Any) -> str:
    """A figure as a card shows it: a share in percent, a count as is, others to 4 digits."""
    if isinstance(value, float) and name in RATES:
        return f"{100 * value:.1f} %"
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


def check_card(card: Any, where: str = "card") -> dict[str, Any]:
    """``card`` if it has the shape above (one-line CheckpointError naming the field that is wrong)."""
    if not isinstance(card, dict):
        raise CheckpointError(f"{where} is of type {type(card).__name__}, not a dict")
    missing = [k for k in CARD_KEYS if k not in card]
    if missing:
        raise CheckpointError(f"{where} lacks {', '.join(missing)}")
    for key in ("role", "eval_command"):
        if not isinstance(card[key], str):
            raise CheckpointError(f"{where}: {key} is of type {type(card[key]).__name__}, not text")
    held = card["held_out"]
    if not isinstance(held, dict):
        raise CheckpointError(f"{where}: held_out is of type {type(held).__name__}, not a dict")
    for mode in MODES:
        if not isinstance(held.get(mode), dict):
            raise CheckpointError(
                f"{where}: held_out lacks its {mode!r} figures (held_out.{mode} must be a dict)"
            )
        rate = held[mode].get("success_rate")
        if not isinstance(rate, float) or not 0.0 <= rate <= 1.0:
            raise CheckpointError(f"{where}: held_out.{mode}.success_rate must be in [0, 1]")
        for name, value in held[mode].items():
            if not isinstance(value, int | float) or isinstance(value, bool):
                raise CheckpointError(
                    f"{where}: held_out.{mode}.{name} is of type {type(value).__name__}, not a number"
                )
    return card


def card_of(meta: dict[str, Any], where: str) -> tuple[dict[str, Any] | None, str | None]:
    """(the checkpoint's card, None), (None, None) without one, or (None, what is wrong with it)."""
    card = meta.get("card")
    if card is None:
        return None, None
    try:
        return check_card(card, where), None
    except CheckpointError as exc:
        return None, str(exc)


def write_card(path: str | os.PathLike[str], card: dict[str, Any]) -> Path:
    """Store ``card`` in the checkpoint at ``path``, atomically; the weights are not touched."""
    import torch

    from neurosym.agent.checkpoint import read_checkpoint, write_payload
    from neurosym.shipped import checkpoint_file

    path = checkpoint_file(path)
    read_checkpoint(path)  # refuses anything that is not a readable neurosym checkpoint
    payload = torch.load(path, map_location="cpu", weights_only=True)
    payload["card"] = check_card(card, f"the card for {path}")
    return write_payload(path, payload)


def learner(meta: dict[str, Any]) -> str:
    """The learner that made the agent: its train config's ``algo``, else its last train command's.

    Agents whose file has no train config were made before it was stored; their
    command names ``--algo`` when it was not the default (a3c).
    """
    config = meta.get("train_config")
    if isinstance(config, dict) and config.get("algo"):
        return str(config["algo"])
    algo = "a3c"
    for command in str(meta.get("command") or "").split(" && "):
        try:
            words = shlex.split(command)
        except ValueError:  # unbalanced quotes: an edited file; its words as they stand
            words = command.split()
        if words[:2] == ["neurosym", "train"] and "--algo" in words[:-1]:
            algo = words[words.index("--algo") + 1]
    return algo


def training_frames(meta: dict[str, Any]) -> tuple[str, str]:
    """(label, text) of the frames an agent trained for, from its checkpoint's metadata.

    ``frames`` counts the env steps since the run began (``--resume`` adds to
    it); a run started ``--init-from`` another agent starts from 0 and records
    the source's count as ``metrics["init_frames"]``. One such step in its
    command: frames + init_frames is the whole training. Several: the source
    had a source of its own whose frames were not recorded, so the sum is a
    lower bound. A command with ``--init-from`` but no ``init_frames`` (an
    older file): only the last run's count is known, and labelled so.
    """
    frames = int(meta.get("frames") or 0)
    metrics = meta.get("metrics") if isinstance(meta.get("metrics"), dict) else {}
    init = metrics.get("init_frames")
    steps = sum(" --init-from " in f" {c} " for c in str(meta.get("command") or "").split(" && "))
    if isinstance(init, int) and not isinstance(init, bool) and init >= 0:
        total = f"{frames + init:,}" if steps <= 1 else f"at least {frames + init:,}"
        source = metrics.get("init_from") or "the agent it started from"
        return (
            "frames, whole training",
            f"{total} ({frames:,} in its last run, after {init:,} of {source})",
        )
    if steps:
        return "frames in the last run", f"{frames:,} (it started from another agent's weights)"
    return "frames, whole training", f"{frames:,}"


def held_out_text(card: dict[str, Any] | None) -> str:
    """``'98.7/92.3'``: held-out success in percent, sampled / greedy; ``'-'`` without a card."""
    if not card:
        return "-"
    held = card["held_out"]
    return "/".join(f"{100 * held[m]['success_rate']:.1f}" for m in MODES)
