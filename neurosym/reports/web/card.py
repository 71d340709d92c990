"""The agent's card: what it is, how it was trained, and the figures its checkpoint carries.

Held-out figures come from the checkpoint's own card (``meta["card"]``, written
by the tools that ship agents, :mod:`neurosym.cards`) when it has one, with
readable labels ("held-out, sampled: sword first when guarded"); otherwise the
card shows the last figures of training (``metrics``), labelled as such, since
those were not measured on held-out levels. Frames are the whole training's
where the checkpoint records them (a curriculum's earlier steps included), and
labelled as the last run's where it does not (:func:`neurosym.cards.training_frames`).
"""

from __future__ import annotations

from typing import Any

from neurosym.agent.networks.adapters import module_has
from neurosym.cards import check_card, learner, training_frames
from neurosym.errors import CheckpointError

TRAINING_FIGURES = (
    "greedy_return",
    "greedy_success",
    "mean_return",
    "success_rate",
    "mean_length",
    "stop_reason",
)
"""metrics shown when the checkpoint has no card of its own"""


def _text(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, dict):
        return ", ".join(f"{k}={_text(v)}" for k, v in value.items()) or "-"
    return str(value)


def _held_out_rows(card: dict[str, Any]) -> list[tuple[str, str]]:
    """A checked card (:func:`neurosym.cards.check_card`) as readable (label, text) rows."""
    from neurosym.cards import MODES, figure_label, figure_text

    held = card["held_out"]
    levels = f"{_text(held.get('episodes', '?'))} levels of {_text(held.get('env', '?'))}"
    if held.get("env_options"):
        levels += f" ({_text(held['env_options'])})"
    if held.get("seed") is not None:
        levels += f", reset seeds from {_text(held['seed'])}"
    rows = [("role", _text(card["role"])), ("held-out levels", levels)]
    for mode in MODES:
        rows += [
            (f"held-out, {mode}: {figure_label(name)}", figure_text(name, value))
            for name, value in held[mode].items()
        ]
    known = {"env", "env_options", "episodes", "seed", *MODES}
    rows += [(f"held-out: {figure_label(k)}", _text(v)) for k, v in held.items() if k not in known]
    return [*rows, ("measured by", _text(card["eval_command"]))]


def _card(meta: dict[str, Any]) -> Any:
    """The checkpoint's card: ``payload["meta"]["card"]`` or ``payload["card"]``, else None."""
    inner = meta.get("meta")
    for card in ((inner or {}).get("card") if isinstance(inner, dict) else None, meta.get("card")):
        if card is not None:
            return card
    return None


def _checked(card: Any) -> tuple[dict[str, Any] | None, str | None]:
    """(card, None) for a well-formed card, (None, None) for none, (None, what is wrong)."""
    if card is None:
        return None, None
    try:
        return check_card(card, "the card"), None
    except CheckpointError as exc:
        return None, str(exc)


def agent_card(rec_meta: dict[str, Any], agent: Any | None, note: str | None = None) -> dict:
    """``{"rows": [(label, text)], "figures": [(label, text)], "figures_from": text, "note"}``.

    ``agent`` is a loaded :class:`~neurosym.agent.agent.Agent` or None (the
    checkpoint is not at hand: the card holds what the recording says).
    """
    mode = "greedy" if rec_meta.get("greedy", True) else "sampled"
    played = _text(rec_meta.get("env"))
    if rec_meta.get("env_kwargs"):
        played += f" ({_text(rec_meta['env_kwargs'])})"
    rows = [
        ("checkpoint", _text(rec_meta.get("checkpoint"))),
        ("recorded on", f"{played}, {mode} actions, seed {rec_meta.get('seed')}"),
        ("module", _text(rec_meta.get("module"))),
        ("heads", _text(rec_meta.get("heads"))),
    ]
    if module_has(rec_meta.get("module"), "relations"):
        rows.append(("relations", _text(rec_meta.get("relations"))))
    figures: list[tuple[str, str]] = []
    source = "none: the checkpoint is not at hand"
    if agent is not None:
        meta = agent.meta
        trained = agent.env_name + (f" ({_text(agent.env_kwargs)})" if agent.env_kwargs else "")
        metrics = meta.get("metrics") if isinstance(meta.get("metrics"), dict) else {}
        label, frames = training_frames(meta)
        started_from = "init_frames" in metrics or " --init-from " in f" {meta.get('command')} "
        episodes = "episodes in the last run" if started_from else "training episodes"
        rows += [
            ("trained on", trained),
            ("learner", learner(meta)),
            (label, frames),
            (episodes, f"{int(meta.get('episodes') or 0):,}"),
            ("created", _text(meta.get("created", "-"))),
            ("neurosym version", _text(meta.get("version", "-"))),
            ("command", _text(meta.get("command", "-"))),
        ]
        card, problem = _checked(_card(meta))
        if card is not None:
            figures = _held_out_rows(card)
            source = "the checkpoint's card (held-out evaluation)"
        else:
            if problem:
                note = " ".join(x for x in (note, f"Its card is not shown: {problem}.") if x)
            figures = [(k, _text(metrics[k])) for k in TRAINING_FIGURES if k in metrics]
            why = "its card is malformed" if problem else "the checkpoint has no card"
            source = f"the last figures of training (not held out: {why})"
    return {"rows": rows, "figures": figures, "figures_from": source, "note": note}
