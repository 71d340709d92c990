"""The trained agent: :class:`Agent` (a model ready to act), :func:`load_agent`, and which env it runs on.

:func:`load_agent` reads a checkpoint through :mod:`neurosym.agent.checkpoint` (which
owns the file format and its checks). An agent runs on any environment of its family
whose observations have its shape: :func:`env_for` decides which env and which
options: on its own env, the options it was trained with; on another, that env's own
options, except those that shape the observation (``CARRIED_OPTIONS``), which carry over.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import torch

from neurosym.agent.checkpoint import build_model, check_env_fits, env_options, read_checkpoint
from neurosym.agent.config import ModelConfig
from neurosym.agent.networks.introspection import Introspection
from neurosym.agent.networks.model import ActorCritic
from neurosym.agent.rollout import select_actions
from neurosym.shipped import checkpoint_file


@dataclass(frozen=True)
class Agent:
    """A trained model ready to act (docs/interfaces.md)."""

    model: ActorCritic
    """the network, in eval mode"""
    config: ModelConfig
    env_name: str
    """short name of the env it was trained on"""
    env_kwargs: dict[str, Any]
    meta: dict[str, Any] = field(default_factory=dict)
    """everything else in the checkpoint but the tensors: frames, episodes, metrics, command, ..."""
    path: str | None = None

    def act(
        self,
        obs: np.ndarray,
        greedy: bool = True,
        introspect: bool = False,
        generator: torch.Generator | None = None,
    ) -> tuple[np.ndarray, Introspection | None]:
        """Actions (B,) for a batch of observations (B, C, H, W); a single (C, H, W) counts as B = 1.

        ``greedy`` takes the most likely action, otherwise one is sampled from
        the policy with ``generator``. With ``introspect`` the second value is
        the module's introspection record with numpy arrays.
        """
        x = torch.as_tensor(np.asarray(obs))
        if x.dim() == 3:
            x = x.unsqueeze(0)  # (1, C, H, W)
        with torch.inference_mode():
            out = self.model(x, introspect=introspect)
            actions = select_actions(out[0], greedy, generator)
        return actions.numpy(), (out[2].numpy() if introspect else None)


def load_agent(
    path: str | os.PathLike[str],
    env: str | None = None,
    config: ModelConfig | None = None,
    play_env: str | None = None,
) -> Agent:
    """Load a checkpoint as an :class:`Agent` (CheckpointError, one line, for every bad file).

    ``env`` and ``config`` are optional expectations, see :func:`read_checkpoint`. An agent
    trained elsewhere (``FILE.py:FUNCTION``, an SB3 ``.zip``) loads through
    :func:`neurosym.outside.load_outside`; ``play_env`` (a command's ``--env``) is the env an
    SB3 model plays, whose file does not say which (ignored for a checkpoint).
    """
    from neurosym.outside.load import load_outside, outside_spec

    if config is None and outside_spec(path) is not None:
        return load_outside(str(path), env or play_env)
    path = checkpoint_file(path)
    payload = read_checkpoint(path, env=env, config=config)
    model = build_model(payload, path)
    model.eval()
    meta = {
        k: v for k, v in payload.items() if k not in ("state_dict", "optimizer", "model_config")
    }
    meta["train_config"] = payload.get("train_config")
    return Agent(
        model=model,
        config=payload["model_config"],
        env_name=payload["env"],
        env_kwargs=dict(payload["env_kwargs"]),
        meta=meta,
        path=str(path),
    )


def env_for(
    agent: Agent | Any, env: str | None = None, overrides: dict[str, Any] | None = None
) -> tuple[str, dict[str, Any]]:
    """(short env name, options) to run ``agent`` on: its own env by default, or ``env``.

    ``env`` may be any env of the agent's family whose observations have its
    shape (checked; CheckpointError otherwise); ``overrides`` are options of
    the user's (e.g. ``{"map": "my_map.txt"}``) on top of :func:`env_options`.
    """
    from neurosym.envs import canonical_name

    name = canonical_name(env if env is not None else agent.env_name)
    kwargs = env_options(agent, name, overrides)
    if name != canonical_name(agent.env_name) or overrides:
        label = getattr(agent, "path", None) or "the agent"
        check_env_fits(label, agent.env_name, agent.config.obs_shape, name, kwargs)
    return name, kwargs
