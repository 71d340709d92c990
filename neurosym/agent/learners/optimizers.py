"""Optimisers whose statistics live in shared memory, and a learner's private copy of them.

The A3C workers step one shared model with one shared optimiser (Hogwild:
no locks); a synchronous learner (PPO, DAgger) trains a private copy on its
device and copies weights and statistics back after each update, so that the
trainer's evaluation and checkpoints see them.
"""

from __future__ import annotations

import copy
from collections.abc import Iterable

import torch

from neurosym.agent.config import TrainConfig


class _SharedState:
    """Optimiser statistics created up front (torch makes them lazily, per process) so that
    :meth:`share_memory` can move them to shared memory before the learners start."""

    STATE_KEYS: tuple[str, ...] = ()
    """the per-parameter statistics besides ``step``"""

    def _init_state(self) -> None:
        for group in self.param_groups:  # type: ignore[attr-defined]
            for p in group["params"]:
                state = self.state[p]  # type: ignore[attr-defined]
                if not state:
                    state["step"] = torch.zeros(())
                    for key in self.STATE_KEYS:
                        state[key] = torch.zeros_like(p, memory_format=torch.preserve_format)

    def share_memory(self):  # returns self, for chaining
        """Move the statistics to shared memory (call again after load_state_dict)."""
        for state in self.state.values():  # type: ignore[attr-defined]
            for value in state.values():
                value.share_memory_()
        return self


class SharedAdam(_SharedState, torch.optim.Adam):
    """Adam whose moment estimates are created eagerly and can live in shared memory.

    The usual optimiser of A3C implementations (e.g. ikostrikov's pytorch-a3c):
    its per-weight step is about ``lr`` whatever the gradient's size, so layers
    whose gradients start tiny (encoder, attention) move as fast as the policy head.
    """

    STATE_KEYS = ("exp_avg", "exp_avg_sq")

    def __init__(self, params: Iterable[torch.nn.Parameter], lr: float, eps: float) -> None:
        super().__init__(params, lr=lr, eps=eps, foreach=False)
        self._init_state()

    def set_hyperparameters(self, lr: float, eps: float) -> None:
        for group in self.param_groups:
            group.update(lr=lr, eps=eps)


class SharedRMSprop(_SharedState, torch.optim.RMSprop):
    """RMSprop without momentum whose statistics are created eagerly and can live in shared memory."""

    STATE_KEYS = ("square_avg",)

    def __init__(
        self, params: Iterable[torch.nn.Parameter], lr: float, alpha: float, eps: float
    ) -> None:
        super().__init__(
            params, lr=lr, alpha=alpha, eps=eps, momentum=0.0, centered=False, foreach=False
        )
        self._init_state()

    def set_hyperparameters(self, lr: float, alpha: float, eps: float) -> None:
        """Apply settings after loading a state dict (which carries the old ones)."""
        for group in self.param_groups:
            group.update(lr=lr, alpha=alpha, eps=eps)


SharedOptimizer = SharedAdam | SharedRMSprop


def shared_optimizer(params: Iterable[torch.nn.Parameter], config: TrainConfig) -> SharedOptimizer:
    """The optimiser ``config.optimizer`` names, with its statistics created up front."""
    if config.optimizer == "adam":
        return SharedAdam(params, config.lr, config.adam_eps)
    return SharedRMSprop(params, config.lr, config.rms_alpha, config.rms_eps)


def set_optimizer_hyperparameters(optimizer: SharedOptimizer, config: TrainConfig) -> None:
    """Apply ``config``'s settings after loading a state dict (which carries the old ones)."""
    if isinstance(optimizer, SharedAdam):
        optimizer.set_hyperparameters(config.lr, config.adam_eps)
    else:
        optimizer.set_hyperparameters(config.lr, config.rms_alpha, config.rms_eps)


@torch.no_grad()
def copy_into_shared(
    local: torch.nn.Module,
    local_opt: torch.optim.Optimizer,
    shared: torch.nn.Module,
    shared_opt: torch.optim.Optimizer,
) -> None:
    """The learner's weights and optimiser statistics into the trainer's shared ones."""
    for dst, src in zip(shared.parameters(), local.parameters(), strict=True):
        dst.copy_(src)
    for dst, src in zip(shared.buffers(), local.buffers(), strict=True):
        dst.copy_(src)
    for g_dst, g_src in zip(shared_opt.param_groups, local_opt.param_groups, strict=True):
        for p_dst, p_src in zip(g_dst["params"], g_src["params"], strict=True):
            s_dst, s_src = shared_opt.state[p_dst], local_opt.state[p_src]
            for key, value in s_src.items():
                if torch.is_tensor(value) and key in s_dst:
                    s_dst[key].copy_(value)


def private_copy(
    shared: torch.nn.Module,
    optimizer: torch.optim.Optimizer,
    train_config: TrainConfig,
    device: torch.device,
) -> tuple[torch.nn.Module, torch.optim.Optimizer]:
    """A synchronous learner's own model and optimiser on ``device``, from the shared ones.

    It trains these and copies them back (:func:`copy_into_shared`) after
    each update, so that the trainer's evaluation and checkpoints see them.
    """
    local = copy.deepcopy(shared).to(device)
    local_opt = shared_optimizer(local.parameters(), train_config)
    local_opt.load_state_dict(optimizer.state_dict())
    return local, local_opt
