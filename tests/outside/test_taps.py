"""The attention tap on a user's nn.MultiheadAttention: the layer's own weights, exact
ablation, and the caller still gets what it asked for."""

from __future__ import annotations

import pytest
import torch
from torch import nn

from neurosym.agent.networks.hooks import cache, hooked
from neurosym.errors import ConfigError
from neurosym.outside.taps import MultiheadAttentionTap, attention_tap


def _layer(batch_first: bool) -> nn.MultiheadAttention:
    torch.manual_seed(0)
    return nn.MultiheadAttention(8, 2, batch_first=batch_first).eval()


@pytest.mark.parametrize("batch_first", [True, False])
def test_the_tap_shows_per_head_weights_and_an_ablation_recomputes_the_output(
    batch_first: bool,
) -> None:
    layer = _layer(batch_first)
    tap = MultiheadAttentionTap(layer)
    x = torch.randn(3, 5, 8)  # (B, N, E)
    seq = x if batch_first else x.transpose(0, 1)
    plain, averaged = layer(seq, seq, seq)  # nobody listens: the layer as written
    _, per_head = layer(seq, seq, seq, average_attn_weights=False)
    with cache(tap, ["attention", "head_out"]) as seen:
        out, given = layer(seq, seq, seq)
    torch.testing.assert_close(seen["attention"], per_head)
    torch.testing.assert_close(given, averaged)  # the caller asked for averaged weights
    torch.testing.assert_close(out, plain)  # listening changes nothing
    heads = seen["head_out"]  # (B, H, N, E / H)

    def zero_head_1(value: torch.Tensor) -> torch.Tensor:
        value = value.clone()
        value[:, 1] = 0.0
        return value

    with hooked(tap, [("head_out", zero_head_1)]):
        ablated, none = layer(seq, seq, seq, need_weights=False)
    kept = heads.clone()
    kept[:, 1] = 0.0
    expected = layer.out_proj(kept.transpose(1, 2).reshape(3, 5, 8))
    expected = expected if batch_first else expected.transpose(0, 1)
    torch.testing.assert_close(ablated, expected)
    assert none is None  # need_weights=False: no weights, as asked
    assert not torch.allclose(ablated, plain)
    tap.remove()
    with cache(tap, ["attention"]) as seen:
        layer(seq, seq, seq)
    assert seen == {}  # the hooks are off the layer


def test_a_layer_that_is_no_attention_is_refused_naming_the_attention_layers() -> None:
    net = nn.Sequential(nn.Linear(8, 8), nn.MultiheadAttention(8, 2))
    with pytest.raises(ConfigError, match=r"^'0' is a Linear: name an nn.MultiheadAttention"):
        attention_tap(net, "0")
    with pytest.raises(
        ConfigError, match=r"^Sequential has no submodule 'attn'; its attention modules: 1$"
    ):
        attention_tap(net, "attn")
    with pytest.raises(ConfigError, match="add_bias_kv or add_zero_attn"):
        MultiheadAttentionTap(nn.MultiheadAttention(8, 2, add_bias_kv=True))
