"""The agent's card: what it is, how it was trained, and the figures its checkpoint carries.

Held-out figures come from the checkpoint's own card (``meta["card"]``, written
by the tools that ship agents) when it has one; otherwise the card shows the
last figures of training (``metrics``), labelled as such, since those were not
measured on held-out levels.
"""

from __future__ import annotations

from typing import Any

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


def _flat(prefix: str, value: Any) -> list[tuple[str, str]]:
    """Nested dicts as (dotted label, text) rows."""
    if isinstance(value, dict) and value:
        out = []
        for key, inner in value.items():
            out += _flat(f"{prefix}.{key}" if prefix else str(key), inner)
        return out
    return [(prefix, _text(value))]


def _card(meta: dict[str, Any]) -> dict[str, Any] | None:
    """The checkpoint's card: ``payload["meta"]["card"]`` or ``payload["card"]``, else None."""
    inner = meta.get("meta")
    for card in ((inner or {}).get("card") if isinstance(inner, dict) else None, meta.get("card")):
        if isinstance(card, dict) and card:
            return card
    return None


def agent_card(rec_meta: dict[str, Any], agent: Any | None, note: str | None = None) -> dict:
    """``{"rows": [(label, text)], "figures": [(label, text)], "figures_from": text, "note"}``.

    ``agent`` is a loaded :class:`~neurosym.agent.checkpoint.Agent` or None (the
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
    if rec_meta.get("module") == "predinet":
        rows.append(("relations", _text(rec_meta.get("relations"))))
    figures: list[tuple[str, str]] = []
    source = "none: the checkpoint is not at hand"
    if agent is not None:
        meta = agent.meta
        trained = agent.env_name + (f" ({_text(agent.env_kwargs)})" if agent.env_kwargs else "")
        train_config = meta.get("train_config") or {}
        rows += [
            ("trained on", trained),
            ("learner", _text(train_config.get("algo", "a3c"))),
            ("frames", f"{int(meta.get('frames') or 0):,}"),
            ("training episodes", f"{int(meta.get('episodes') or 0):,}"),
            ("created", _text(meta.get("created", "-"))),
            ("neurosym version", _text(meta.get("version", "-"))),
            ("command", _text(meta.get("command", "-"))),
        ]
        card = _card(meta)
        if card is not None:
            figures = _flat("", card)
            source = "the checkpoint's card (held-out evaluation)"
        else:
            metrics = meta.get("metrics") or {}
            figures = [(k, _text(metrics[k])) for k in TRAINING_FIGURES if k in metrics]
            source = "the last figures of training (not held out: the checkpoint has no card)"
    return {"rows": rows, "figures": figures, "figures_from": source, "note": note}
