"""The actor-critic network: encoder -> relational module (PrediNet, MHDPA, any registered) -> MLP -> policy logits and value.

Table 4: the relational module's 26-wide output goes through 26 -> 256 -> 128
-> 64 (ReLU) and then two linear heads, 4 policy logits and 1 value. The
policy head starts with small weights (std 0.01 orthogonal) so the initial
policy is close to uniform, which is what exploration on RGW needs. With
``config.init == "orthogonal"`` the MLP (gain sqrt 2), the value head and
PrediNet's read-out (gain 1) start orthogonal too, so that the value and the
policy's hidden features vary with the observation from the first update.
"""

from __future__ import annotations

import contextlib
import math

import torch
from torch import nn

from neurosym.agent.config import ModelConfig
from neurosym.agent.networks.adapters import adapter_class
from neurosym.agent.networks.encoder import Encoder
from neurosym.agent.networks.introspection import Introspection
from neurosym.agent.networks.predinet import PrediNet, QueryRecord
from neurosym.errors import ConfigError


def build_relational(config: ModelConfig) -> nn.Module:
    """The relational module named by ``config.module``, built by its registered adapter."""
    return adapter_class(config.module).build(config)


class ActorCritic(nn.Module):
    """``forward(obs, introspect=False)`` per docs/interfaces.md."""

    def __init__(self, config: ModelConfig) -> None:
        super().__init__()
        self.config = config
        C, H, W = config.obs_shape
        self.encoder = Encoder(
            C, H, W, config.conv_channels, config.kernel_size, norm=config.entity_norm
        )
        self.relational = build_relational(config)
        layers: list[nn.Module] = []
        width = config.output_size
        for size in config.hidden_sizes:
            layers += [nn.Linear(width, size), nn.ReLU()]
            width = size
        self.body = nn.Sequential(*layers)
        self.policy = nn.Linear(width, config.n_actions)
        self.value = nn.Linear(width, 1)
        nn.init.orthogonal_(self.policy.weight, gain=0.01)
        nn.init.zeros_(self.policy.bias)
        if config.init == "orthogonal":
            self._orthogonal_init()

    def _orthogonal_init(self) -> None:
        """CleanRL/SB3's layer init: keeps a signal's spread through the ReLU layers."""
        for layer in self.body:
            if isinstance(layer, nn.Linear):
                nn.init.orthogonal_(layer.weight, gain=math.sqrt(2))
                nn.init.zeros_(layer.bias)
        readout = getattr(self.relational, "out", None)
        for layer in (self.value, readout):
            if isinstance(layer, nn.Linear):
                nn.init.orthogonal_(layer.weight, gain=1.0)
                nn.init.zeros_(layer.bias)

    def recording(self) -> contextlib.AbstractContextManager[QueryRecord | None]:
        """A block whose graph-free forwards the relational module remembers, for a later
        ``forward(..., queries=record)`` over the same observations first (PrediNet's
        queries; other modules record nothing and yield None)."""
        if isinstance(self.relational, PrediNet) and self.config.keys == "entities":
            return self.relational.recording_queries()
        return contextlib.nullcontext()

    def forward(
        self, obs: torch.Tensor, introspect: bool = False, queries: QueryRecord | None = None
    ) -> tuple[torch.Tensor, torch.Tensor] | tuple[torch.Tensor, torch.Tensor, Introspection]:
        """obs (B, C, H, W), uint8 or float in the env's raw scale -> logits (B, 4), value (B,)[, intro].

        ``queries``: what :meth:`recording` kept while acting on the first rows of ``obs`` with
        the same weights (saves computing them again; ignored when the weights changed)."""
        if obs.dim() != 4 or tuple(obs.shape[1:]) != self.config.obs_shape:
            raise ConfigError(
                f"observation batch must have shape (B, {', '.join(map(str, self.config.obs_shape))}), "
                f"got {tuple(obs.shape)}"
            )
        x = obs.to(torch.float32) * self.config.obs_scale  # (B, C, H, W)
        entities = self.encoder(x)  # (B, N, F)
        if self.config.keys != "entities" or self.config.relation_bits is not None:
            # keys from what each cell holds (ModelConfig.keys), or the fact bottleneck's cells
            B, C, H, W = x.shape
            cells = x.permute(0, 2, 3, 1).reshape(B, H * W, C)  # (B, N, C), row-major
            features, intro = self.relational(entities, introspect, queries, cells)
        elif queries is not None and isinstance(self.relational, PrediNet):
            features, intro = self.relational(entities, introspect, queries)  # (B, output_size)
        else:
            features, intro = self.relational(entities, introspect)  # (B, output_size)
        h = self.body(features)  # (B, hidden[-1])
        logits = self.policy(h)  # (B, n_actions)
        value = self.value(h).squeeze(-1)  # (B,)
        if introspect:
            return logits, value, intro
        return logits, value

    def parameter_count(self) -> int:
        return sum(p.numel() for p in self.parameters())
