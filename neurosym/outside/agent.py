"""Agents trained outside neurosym, wrapped so that every command reads them like its own.

neurosym's commands ask an agent for a few things (docs/interfaces.md): ``act`` on a batch of
observations (actions, and with ``introspect`` the attention weights), ``model`` (a module
whose ``forward(obs)`` gives action logits and a value, with a ``config`` naming the
relational adapter and a ``relational`` module holding the hook points), ``config``,
``env_name``, ``env_kwargs``, ``meta`` and ``path``. :class:`OutsideAgent` gives them for any
``nn.Module`` and a function that says how it acts:

    agent = TorchAgent(net, env="rgw2", attention="attn")        # net(obs) -> logits
    agent = TorchAgent(net, env="rgw2", act=lambda net, obs: net.pi(obs))

The network's module is then ``outside_attention`` (attention/6 facts from the named layer)
or, with no ``attention``, ``outside`` (behaviour facts only).
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import torch
from torch import nn

from neurosym.agent.networks.introspection import MHDPAIntrospection
from neurosym.agent.rollout import select_actions
from neurosym.errors import ConfigError

ActFn = Callable[[nn.Module, torch.Tensor], Any]
"""(the user's network, obs (B, *shape) float32 in the env's raw values) -> logits (B, A), or
(logits, value), or actions (B,) of an integer dtype"""

CHOSEN_LOGIT = 0.0
OTHER_LOGIT = -30.0
"""logits given to an agent that returns actions only: the chosen action takes all the
probability (exp(-30) ~ 1e-13), so greedy and sampled play agree and KLs stay finite"""


@dataclass(frozen=True)
class OutsideConfig:
    """What neurosym's commands read of a model's config, for an agent trained elsewhere."""

    module: str
    """the adapter: ``outside_attention`` or ``outside`` (no network facts)"""
    heads: int
    obs_shape: tuple[int, ...]
    n_actions: int
    relations: int = 0

    def to_dict(self) -> dict[str, Any]:
        return {"module": self.module, "heads": self.heads, "obs_shape": list(self.obs_shape),
                "n_actions": self.n_actions}  # fmt: skip


class OutsideModel(nn.Module):
    """``forward(obs, introspect=False) -> (logits, value[, intro])`` around a user's network.

    ``value`` is zeros when the network gives none. ``relational`` is the attention layer's
    hook points (:func:`neurosym.outside.taps.attention_tap`) or an empty module.
    """

    def __init__(self, net: nn.Module, act: ActFn, config: OutsideConfig, tap: nn.Module | None):
        super().__init__()
        self.net = net
        self.act_fn = act
        self.config = config
        self.relational = tap if tap is not None else NoHeads()

    def forward(self, obs: torch.Tensor, introspect: bool = False) -> tuple[Any, ...]:
        if (
            obs.dim() != len(self.config.obs_shape) + 1
            or tuple(obs.shape[1:]) != self.config.obs_shape
        ):
            raise ConfigError(
                f"observation batch must have shape (B, {', '.join(map(str, self.config.obs_shape))}), "
                f"got {tuple(obs.shape)}"
            )
        x = obs.to(torch.float32)
        if not introspect or self.config.heads == 0:
            logits, value = self._act(x)
            return (logits, value, None) if introspect else (logits, value)
        from neurosym.agent.networks.hooks import cache

        with cache(self.relational, ["attention"]) as seen:
            logits, value = self._act(x)
        if "attention" not in seen:
            raise ConfigError(
                "the attention layer named for this agent did not run when it acted; name the "
                "layer its forward uses"
            )
        return logits, value, MHDPAIntrospection(seen["attention"])

    def _act(self, x: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        out = self.act_fn(self.net, x)
        value = None
        if isinstance(out, tuple | list):
            if len(out) != 2:
                raise ConfigError(
                    f"an agent's act gave {len(out)} values; give logits, (logits, value) or actions"
                )
            out, value = out
        out = torch.as_tensor(out)
        B, A = x.shape[0], self.config.n_actions
        if not out.is_floating_point() and tuple(out.shape) == (B,):  # actions
            if out.numel() and (int(out.min()) < 0 or int(out.max()) >= A):
                raise ConfigError(f"an agent's act gave actions outside 0..{A - 1}")
            logits = torch.full((B, A), OTHER_LOGIT)
            logits[torch.arange(B), out.long()] = CHOSEN_LOGIT
        elif out.is_floating_point() and tuple(out.shape) == (B, A):
            logits = out.float()
        else:
            raise ConfigError(
                f"an agent's act gave a {out.dtype} tensor of shape {tuple(out.shape)}; expected "
                f"logits ({B}, {A}), (logits, value) or integer actions ({B},)"
            )
        value = torch.zeros(B) if value is None else torch.as_tensor(value).float().reshape(B)
        if self.config.heads == 0:  # the head point of a network without heads: (B, 0, 1)
            self.relational.hook_head_out(torch.zeros(B, 0, 1))
        return logits, value


class NoHeads(nn.Module):
    """The relational module of an agent whose attention nobody named: no heads, and a head
    point that shows (B, 0, 1) per forward, so head vectors and ablations are empty, not errors."""

    heads = 0

    def __init__(self) -> None:
        super().__init__()
        from neurosym.agent.networks.hooks import HookPoint

        self.hook_head_out = HookPoint()


def default_act(net: nn.Module, obs: torch.Tensor) -> Any:
    """The network called on the observations: ``net(obs)``."""
    return net(obs)


@dataclass(frozen=True)
class OutsideAgent:
    """An agent trained elsewhere, shaped like :class:`neurosym.agent.checkpoint.Agent`."""

    model: OutsideModel
    config: OutsideConfig
    env_name: str
    env_kwargs: dict[str, Any] = field(default_factory=dict)
    meta: dict[str, Any] = field(default_factory=dict)
    path: str | None = None

    def act(
        self,
        obs: np.ndarray,
        greedy: bool = True,
        introspect: bool = False,
        generator: torch.Generator | None = None,
    ) -> tuple[np.ndarray, Any]:
        """Actions (B,) for a batch of observations; with ``introspect`` the attention too."""
        x = torch.as_tensor(np.asarray(obs))
        if x.dim() == len(self.config.obs_shape):
            x = x.unsqueeze(0)
        with torch.inference_mode():
            out = self.model(x, introspect=introspect)
            actions = select_actions(out[0], greedy, generator)
        intro = out[2] if introspect else None
        return actions.numpy(), (intro.numpy() if intro is not None else None)

    def untrained(self, seed: int) -> OutsideModel:
        """A copy of the model with every layer that can re-initialise itself re-initialised
        (seeded): the probes' untrained baseline."""
        model = copy.deepcopy(self.model)  # the tap's hooks are copied onto the copied layer
        with torch.random.fork_rng():
            torch.manual_seed(seed)
            for layer in model.net.modules():
                reset = getattr(layer, "reset_parameters", None)
                if callable(reset):
                    reset()
        return model.eval()

    def with_path(self, path: str) -> OutsideAgent:
        """The same agent named ``path`` (what recordings and KBs say it was)."""
        return OutsideAgent(
            self.model, self.config, self.env_name, self.env_kwargs, self.meta, path
        )


def observation_shape(
    env: str, env_kwargs: dict[str, Any] | None = None
) -> tuple[tuple[int, ...], int]:
    """(observation shape, action count) of a neurosym env made with ``env_kwargs``."""
    from neurosym.envs import make

    probe = make(env, **(env_kwargs or {}))
    try:
        return tuple(int(v) for v in probe.observation_space.shape), int(probe.action_space.n)
    finally:
        probe.close()


def TorchAgent(  # noqa: N802 (reads as the class it makes)
    net: nn.Module,
    env: str,
    *,
    act: ActFn | None = None,
    attention: str | None = None,
    env_kwargs: dict[str, Any] | None = None,
    meta: dict[str, Any] | None = None,
) -> OutsideAgent:
    """A user's PyTorch network as a neurosym agent.

    ``env``: the neurosym env it plays (short name or id; any env of that family with the
    same observation shape plays it too). ``act(net, obs)``: how it acts, from a float32 batch
    of the env's raw observations to logits (B, A), (logits, value) or actions (B,); default
    ``net(obs)``. ``attention``: the dotted name of its attention layer (an
    ``nn.MultiheadAttention`` over the grid's cells, entity k = cell k row-major, or a module
    with neurosym hook points): its weights become attention/6 facts and its heads can be
    ablated; None records behaviour only.
    """
    from neurosym.envs import canonical_name

    if not isinstance(net, nn.Module):
        raise ConfigError(f"an agent's network must be a torch nn.Module, got {type(net).__name__}")
    name = canonical_name(env)
    kwargs = dict(env_kwargs or {})
    shape, n_actions = observation_shape(name, kwargs)
    tap = None
    if attention is not None:
        from neurosym.outside.taps import attention_tap

        tap = attention_tap(net, attention)
    config = OutsideConfig(
        module="outside_attention" if tap is not None else "outside",
        heads=int(tap.heads) if tap is not None else 0,
        obs_shape=shape,
        n_actions=n_actions,
    )
    model = OutsideModel(net.eval(), act or default_act, config, tap).eval()
    return OutsideAgent(
        model, config, name, kwargs, dict(meta or {"train_config": {"algo": "own code"}})
    )
