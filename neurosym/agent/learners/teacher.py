"""A trained agent as DAgger's teacher (``--algo imitate --set teacher=CHECKPOINT``).

Why: Box-World has no planner here, and a network whose policy reads only its own facts
(``ModelConfig.relation_bits``) learns slowly from rewards (docs/results.md, "The fact
bottleneck"). Taught a trained agent's action probabilities instead, it learns that agent's
policy through its facts: knowledge distillation (Hinton et al., 2015) on the states DAgger
visits, so that the student is taught where its own mistakes lead.

The teacher is anything :func:`neurosym.agent.agent.load_agent` reads: a checkpoint, a
shipped agent's name, an SB3 ``.zip``. Its value, in returns (a neurosym checkpoint's critic
is divided by the reward scale it was trained with), is the critic's target; an agent
without a critic gives 0.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import torch

from neurosym.errors import CheckpointError, ConfigError


class Teacher:
    """Labels states with a trained agent's action probabilities and value."""

    def __init__(self, agent: Any, device: torch.device | str = "cpu") -> None:
        self.model = agent.model.to(device).eval()
        self.device = torch.device(device)
        train = (agent.meta or {}).get("train_config") or {}
        self.reward_scale = float(train.get("reward_scale", 1.0)) or 1.0

    def labels(self, obs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(n, A) float32 action probabilities and (n,) float32 values in returns."""
        with torch.inference_mode():
            logits, value = self.model(torch.from_numpy(obs).to(self.device))[:2]
            probs = torch.softmax(logits.float(), dim=-1)
        values = value.float() / self.reward_scale
        return probs.cpu().numpy(), values.cpu().numpy()


def load_teacher(
    spec: str, env: str, obs_shape: tuple[int, ...], n_actions: int, device: Any = "cpu"
) -> Teacher:
    """The teacher named ``spec`` for a student on ``env`` with these observations and actions;
    ConfigError, one line, when it cannot teach it."""
    from neurosym.agent.agent import load_agent

    try:
        agent = load_agent(spec, env=env, play_env=env)
    except CheckpointError as exc:
        raise ConfigError(f"--set teacher={spec}: {exc}") from None
    theirs = (tuple(int(v) for v in agent.config.obs_shape), int(agent.config.n_actions))
    if theirs != (tuple(obs_shape), int(n_actions)):
        raise ConfigError(
            f"--set teacher={spec}: it sees observations {theirs[0]} and has {theirs[1]} "
            f"actions; this run's {env} has {tuple(obs_shape)} and {n_actions}: pick a teacher "
            f"trained on the same observations"
        )
    return Teacher(agent, device)
