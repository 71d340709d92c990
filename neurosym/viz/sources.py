"""Where a picture's episode comes from: a recording, a checkpoint, or a trace already built.

Every plotting function takes ``source`` as a Recording, an Agent (played on
``env`` from ``reset(seed)``) or an EpisodeTrace; :func:`load_trace` turns it
into the trace, and :func:`require_source_module` refuses a plot for the other
relational module before any episode is played.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, TypeAlias

from neurosym.errors import ConfigError
from neurosym.record.recording import Recording
from neurosym.viz.live import trace_from_agent
from neurosym.viz.recorded import trace_from_recording
from neurosym.viz.trace import EpisodeTrace, require_module

if TYPE_CHECKING:
    import gymnasium

    from neurosym.agent.agent import Agent

Source: TypeAlias = "Recording | Agent | EpisodeTrace"
"""what every plotting function draws from"""

EnvLike: TypeAlias = "str | gymnasium.Env | None"
"""a short env name or registered id, an env object, or None for the checkpoint's own env"""

__all__ = [
    "EnvLike",
    "Source",
    "load_trace",
    "require_source_module",
    "trace_from_agent",
    "trace_from_recording",
]


def require_source_module(source: Source, module: str, what: str) -> None:
    """Refuse early (before playing an episode) a plot that needs the other module."""
    if isinstance(source, EpisodeTrace):
        found, name = source.module, source.checkpoint
    elif isinstance(source, Recording):
        found, name = str(source.meta.get("module", "")), str(source.meta.get("checkpoint", ""))
    elif hasattr(source, "config"):
        found, name = str(source.config.module), str(getattr(source, "path", ""))
    else:
        return  # load_trace words the error for anything else
    require_module(found, module, what, name)


def load_trace(
    source: Source,
    env: EnvLike = None,
    *,
    episode: int | None = None,
    seed: int = 0,
    max_steps: int | None = None,
    keep_attention: set[int] | None = None,
) -> EpisodeTrace:
    """A trace from an EpisodeTrace (returned as is), a Recording, or an Agent (+ env)."""
    if isinstance(source, EpisodeTrace):
        return source
    if isinstance(source, Recording):
        return trace_from_recording(source, episode)
    if hasattr(source, "act") and hasattr(source, "config"):
        return trace_from_agent(
            source, env, seed=seed, max_steps=max_steps, keep_attention=keep_attention
        )
    raise ConfigError(
        f"cannot plot a {type(source).__name__}: pass a Recording, an Agent (load_agent) or an EpisodeTrace"
    )
