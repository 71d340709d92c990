"""Multi-head dot-product attention over entities (Zambaldi et al. 2019), max-pooled.

One attention block: per head h, queries x W_Q^h, keys x W_K^h and values
x W_V^h from each entity (Table 4: 4 heads, query/key 32 RGW / 64 BW, value
64); softmax of the scaled dot products over keys; the heads' outputs
concatenated and projected back to the entity width by W_O; residual and layer
norm; a two-layer ReLU MLP of the entity width, residual and layer norm; then a
max over entities ("pooling stride 1x1" in Table 4 is that per-feature max).
The pooled vector has the entity width (26); a linear layer maps it to
``output_size`` only when that differs.

Folded products. The entity width F (26) is smaller than the key size (32/64)
and the value size (64), so the forward pass multiplies the weight matrices
first: Q K^T = x (W_Q^h W_K^h^T) x^T and concat_h(A^h x W_V^h) W_O =
sum_h A^h x (W_V^h W_O^h). This is the same function of the same parameters
(and the same gradients, up to float rounding) at about half the cost.

The output goes through torch's fused ``scaled_dot_product_attention``
(about twice as fast as materialising the (B, H, N, N) weights, forward and
backward) in both the plain and the introspecting pass, so the two give
bit-identical logits; the introspecting pass additionally computes the
weights explicitly to report them (they agree with the fused kernel's to
float rounding).
"""

from __future__ import annotations

import math

import torch
import torch.nn.functional as F_
from torch import nn

from neurosym.agent.networks.hooks import HookPoint, introspected
from neurosym.agent.networks.introspection import MHDPAIntrospection


class MHDPA(nn.Module):
    """(B, N, F) entities -> (B, output_size), optionally with the attention weights."""

    def __init__(
        self,
        entity_size: int,
        heads: int,
        key_size: int,
        value_size: int,
        output_size: int,
        attention_gain: float = 1.0,
    ) -> None:
        super().__init__()
        self.heads, self.key_size, self.value_size = heads, key_size, value_size
        self.query = nn.Linear(entity_size, heads * key_size, bias=False)  # W_Q^h, all heads
        self.key = nn.Linear(entity_size, heads * key_size, bias=False)  # W_K^h
        self.value = nn.Linear(entity_size, heads * value_size, bias=False)  # W_V^h
        self.proj = nn.Linear(heads * value_size, entity_size)  # W_O
        self.norm1 = nn.LayerNorm(entity_size)
        self.mlp = nn.Sequential(
            nn.Linear(entity_size, entity_size), nn.ReLU(), nn.Linear(entity_size, entity_size)
        )
        self.norm2 = nn.LayerNorm(entity_size)
        self.out = (
            nn.Identity() if output_size == entity_size else nn.Linear(entity_size, output_size)
        )
        self.scale = attention_gain / math.sqrt(key_size)
        # hook points (neurosym.agent.networks.hooks), computed explicitly only when a hook
        # listens: the attention maps (B, H, N, N) and each head's output A^h x W_V^h W_O^h
        # (B, H, N, F); a value put in place of a head's output moves the residual x +
        # attended (B, N, F, the point resid_mid, what norm1 reads) by the difference
        self.hook_attention = HookPoint()
        self.hook_head_out = HookPoint()
        self.hook_resid_mid = HookPoint()

    def folded_weights(self) -> tuple[torch.Tensor, torch.Tensor]:
        """(F, H * F) W_Q^h W_K^h^T * scale and (F, H * F) W_V^h W_O^h, heads side by side."""
        H, D, V = self.heads, self.key_size, self.value_size
        F = self.query.in_features
        wq = self.query.weight.view(H, D, F)  # (H, D, F)
        wk = self.key.weight.view(H, D, F)  # (H, D, F)
        qk = wq.transpose(1, 2) @ wk * self.scale  # (H, F, F)
        wv = self.value.weight.view(H, V, F)  # (H, V, F)
        wo = self.proj.weight.view(F, H, V).permute(1, 2, 0)  # (H, V, F)
        vo = wv.transpose(1, 2) @ wo  # (H, F, F)
        return qk.permute(1, 0, 2).reshape(F, H * F), vo.permute(1, 0, 2).reshape(F, H * F)

    def forward(self, x: torch.Tensor, introspect: bool = False):
        """(out, None), or (out, :class:`MHDPAIntrospection` of the cached attention maps)."""
        if not introspect:
            return self._forward(x), None
        return introspected(self, MHDPAIntrospection, lambda: self._forward(x))

    def _forward(self, x: torch.Tensor) -> torch.Tensor:
        B, N, F = x.shape
        H = self.heads
        w_qk, w_vo = self.folded_weights()
        xq = (x @ w_qk).view(B, N, H, F).transpose(1, 2)  # (B, H, N, F)  x W_Q^h W_K^h^T
        xv = (x @ w_vo).view(B, N, H, F).transpose(1, 2)  # (B, H, N, F)  x W_V^h W_O^h
        keys = x.unsqueeze(1).expand(B, H, N, F)  # (B, H, N, F)
        heads_out = F_.scaled_dot_product_attention(xq, keys, xv, scale=1.0)  # (B, H, N, F)
        attended = heads_out.sum(dim=1) + self.proj.bias  # (B, N, F)
        resid = x + attended
        if self.hook_attention.active or self.hook_head_out.active:
            delta = self._explicit_heads(xq, keys, xv)
            if delta is not None:
                resid = resid + delta
        x = self.norm1(self.hook_resid_mid(resid))  # (B, N, F)
        x = self.norm2(x + self.mlp(x))  # (B, N, F)
        return self.out(x.amax(dim=1))  # (B, output_size)

    def _explicit_heads(
        self, xq: torch.Tensor, keys: torch.Tensor, xv: torch.Tensor
    ) -> torch.Tensor | None:
        """Pass the explicit attention and head outputs through their points; the change
        the head-output hooks made, summed over the changed heads (None if none)."""
        att = self.hook_attention(torch.softmax(xq @ keys.transpose(-1, -2), dim=-1))
        if not self.hook_head_out.active:
            return None
        with torch.no_grad():  # what the fused kernel computes; never part of a training graph
            heads = att @ xv  # (B, H, N, F)
        new = self.hook_head_out(heads)
        if new is heads:
            return None
        changed = [h for h in range(self.heads) if not torch.equal(new[:, h], heads[:, h])]
        return new[:, changed].sum(1) - heads[:, changed].sum(1)  # (B, N, F)
