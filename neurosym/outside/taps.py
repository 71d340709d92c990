"""Hook points on a user's attention layer, so its weights become neurosym's attention facts.

neurosym reads an attention module through two hook points (docs/design.md "Hook points"):
``attention`` (B, H, N, N), query x key weights, and ``head_out`` (B, H, N, D), each head's
attended values, which head ablation replaces. A module written for neurosym has them as
:class:`~neurosym.agent.networks.hooks.HookPoint` children; a torch
``nn.MultiheadAttention`` does not, so :class:`MultiheadAttentionTap` adds them from the
outside with forward hooks: while a point listens, the layer is asked for its per-head
weights (``need_weights=True, average_attn_weights=False``), the weights pass through
``attention``, the heads' values through ``head_out``, and the layer's output is computed
again from them when a hook replaced one (an ablation). The caller gets what it asked for
(averaged weights, or None). With no listener the layer runs exactly as written.
"""

from __future__ import annotations

from typing import Any

import torch
import torch.nn.functional as F_
from torch import nn

from neurosym.agent.networks.hooks import HookPoint, hook_points
from neurosym.errors import ConfigError

_MHA_ARGS = ("query", "key", "value", "key_padding_mask", "need_weights", "attn_mask",
             "average_attn_weights", "is_causal")  # fmt: skip
"""nn.MultiheadAttention.forward's parameters in order (positional ones become keywords)"""


class MultiheadAttentionTap(nn.Module):
    """Hook points ``attention`` and ``head_out`` on a user's ``nn.MultiheadAttention``.

    The layer stays the user's (it is not a submodule of the tap: state dicts do not
    change); :meth:`remove` takes the hooks off it again.
    """

    def __init__(self, layer: nn.MultiheadAttention, where: str = "attention") -> None:
        super().__init__()
        if layer.bias_k is not None or layer.add_zero_attn:
            raise ConfigError(
                f"{where}: an nn.MultiheadAttention with add_bias_kv or add_zero_attn attends "
                "to keys that are not cells; neurosym reads attention as cell to cell"
            )
        self.heads = int(layer.num_heads)
        self.hook_attention = HookPoint()  # (B, H, N, N) query x key
        self.hook_head_out = HookPoint()  # (B, H, N, E / H)
        self._layer = (layer,)  # a tuple: not registered as a submodule
        self._asked: list[tuple[bool, bool]] = []
        self._handles = [
            layer.register_forward_pre_hook(self._before, with_kwargs=True),
            layer.register_forward_hook(self._after, with_kwargs=True),
        ]

    @property
    def listening(self) -> bool:
        """Whether a hook listens at either point (only then is the layer's call changed)."""
        return self.hook_attention.active or self.hook_head_out.active

    def remove(self) -> None:
        """Take the forward hooks off the user's layer."""
        for handle in self._handles:
            handle.remove()

    def _before(self, _layer: nn.Module, args: tuple, kwargs: dict) -> Any:
        if not self.listening:
            return None
        kwargs = {**dict(zip(_MHA_ARGS, args, strict=False)), **kwargs}
        self._asked.append(
            (bool(kwargs.get("need_weights", True)), bool(kwargs.get("average_attn_weights", True)))
        )
        kwargs["need_weights"], kwargs["average_attn_weights"] = True, False
        return (), kwargs

    def _after(self, layer: nn.Module, _args: tuple, kwargs: dict, output: Any) -> Any:
        if not self._asked:  # nobody listened when the call began
            return None
        need, average = self._asked.pop()
        out, weights = output
        batched = kwargs["query"].dim() == 3
        att = weights if batched else weights.unsqueeze(0)  # (B, H, L, S)
        seen = self.hook_attention(att)
        if self.hook_head_out.active or seen is not att:
            heads = self._head_values(layer, kwargs["value"], seen, batched)  # (B, H, L, E / H)
            changed = self.hook_head_out(heads)
            if changed is not heads or seen is not att:
                out = self._output(layer, changed, batched)
        given = None if not need else (weights.mean(dim=-3) if average else weights)
        return out, given

    @staticmethod
    def _head_values(
        layer: nn.Module, value: torch.Tensor, att: torch.Tensor, batched: bool
    ) -> torch.Tensor:
        """Each head's attended values: att (B, H, L, S) @ the value projection (B, H, S, E / H)."""
        E, H = layer.embed_dim, layer.num_heads
        if layer._qkv_same_embed_dim:
            w_v = layer.in_proj_weight[2 * E :]
        else:
            w_v = layer.v_proj_weight
        b_v = None if layer.in_proj_bias is None else layer.in_proj_bias[2 * E :]
        if not batched:
            value = value.unsqueeze(0 if layer.batch_first else 1)
        if not layer.batch_first:
            value = value.transpose(0, 1)  # (B, S, E_v)
        B, S = value.shape[:2]
        v = F_.linear(value, w_v, b_v).view(B, S, H, E // H).transpose(1, 2)
        return att.to(v.dtype) @ v

    @staticmethod
    def _output(layer: nn.Module, heads: torch.Tensor, batched: bool) -> torch.Tensor:
        """The layer's output from its heads' values (B, H, L, E / H), shaped as the layer gives it."""
        B, H, L, D = heads.shape
        out = layer.out_proj(heads.transpose(1, 2).reshape(B, L, H * D))  # (B, L, E)
        if not layer.batch_first:
            out = out.transpose(0, 1)
        return out if batched else out.squeeze(1 if not layer.batch_first else 0)


def attention_tap(net: nn.Module, name: str) -> nn.Module:
    """The hook points of ``net``'s submodule ``name`` (a dotted path, ``"encoder.attn"``).

    An ``nn.MultiheadAttention`` is tapped from outside (:class:`MultiheadAttentionTap`); a
    module of the user's own with neurosym hook points ``attention`` and ``head_out`` (and an
    int attribute ``heads``) is used as it is. Anything else is refused in one line.
    """
    try:
        layer = net.get_submodule(name)
    except AttributeError:
        names = [n for n, m in net.named_modules() if n and _attention_like(m)]
        raise ConfigError(
            f"{type(net).__name__} has no submodule {name!r}; its attention modules: "
            f"{', '.join(names) or 'none'}"
        ) from None
    if isinstance(layer, nn.MultiheadAttention):
        return MultiheadAttentionTap(layer, name)
    points = hook_points(layer)
    if {"attention", "head_out"} <= set(points) and isinstance(getattr(layer, "heads", None), int):
        return layer
    raise ConfigError(
        f"{name!r} is a {type(layer).__name__}: name an nn.MultiheadAttention, or a module with "
        "neurosym hook points hook_attention (B, H, N, N) and hook_head_out (B, H, N, D) and an "
        "int attribute heads"
    )


def _attention_like(module: nn.Module) -> bool:
    return isinstance(module, nn.MultiheadAttention) or "attention" in hook_points(module)
