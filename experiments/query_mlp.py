"""Can head 0 tell a route through a teleport if its query is not linear in the scene?

PrediNet's queries are a linear read-out of the flattened entities (W_Q flat(L)). The RGW
fact bottleneck's head 0 misses the next object mostly where the route goes through a
teleport (it names the object past it), a choice between two route lengths. This study adds
a residual MLP to the queries, Q = W_Q flat(L) + MLP(flat(L)), its last layer zero so that
the network starts exactly where its source was, and trains on as before:

    python experiments/query_mlp.py init SOURCE.pt INIT.pt          # the source plus the MLP
    python experiments/query_mlp.py train --init-from INIT.pt ...   # any neurosym command

Every other command runs ``neurosym`` with the MLP in every PrediNet with scene queries and
cell keys (the RGW bottleneck's; the entity keys' attention does not read these scores), so the
run's checkpoints (which hold the MLP's weights) load, play, extract and induce only
through this script; the checkpoint's config does not record the change.
"""

from __future__ import annotations

import sys

import torch
from torch import nn

from neurosym.agent.networks import predinet
from neurosym.cli import main

HIDDEN = 256
"""the MLP's hidden width"""

_init = predinet.PrediNet.__init__
_logits = predinet.PrediNet.attention_logits


def query_mlp(flat: int, out: int) -> nn.Sequential:
    """flat(L) -> all 2H queries, its last layer zero (adds nothing until trained)."""
    mlp = nn.Sequential(nn.Linear(flat, HIDDEN), nn.ReLU(), nn.Linear(HIDDEN, out))
    nn.init.zeros_(mlp[2].weight)
    nn.init.zeros_(mlp[2].bias)
    return mlp


def __init__(self, *args, **kwargs) -> None:  # type: ignore[no-untyped-def]
    _init(self, *args, **kwargs)
    if self.query_mode == "scene":
        self.query_mlp = query_mlp(self.query1.weight.shape[1], 2 * self.heads * self.key_size)


def attention_logits(self, L, cells=None):  # type: ignore[no-untyped-def]
    """The library's scores plus the MLP's share of each query, (q_mlp W_K) keys^T * scale."""
    scores = _logits(self, L, cells)
    if self.query_mode != "scene":
        return scores
    B, N, F = L.shape
    q = self.query_mlp(L.reshape(B, N * F)).view(B, 2 * self.heads, self.key_size)
    if self.keys == "entities":
        keys = L
    elif self.keys == "cells_xy":
        keys = torch.cat([cells, L[..., -2:]], dim=-1)
    else:
        keys = cells
    return scores + (q @ self.key.weight) @ keys.transpose(1, 2) * self.scale


def add_mlp(source: str, out: str) -> None:
    """Write ``source``'s checkpoint with the MLP's weights added (its last layer zero)."""
    ck = torch.load(source, map_location="cpu", weights_only=False)
    state = ck["state_dict"]
    mlp = query_mlp(state["relational.query1.weight"].shape[1], 2 * state["relational.query1.weight"].shape[0])
    dtype = state["relational.query1.weight"].dtype
    for name, value in mlp.state_dict().items():
        state[f"relational.query_mlp.{name}"] = value.to(dtype)
    ck.pop("optimizer", None)
    torch.save(ck, out)


predinet.PrediNet.__init__ = __init__
predinet.PrediNet.attention_logits = attention_logits

if __name__ == "__main__":
    if sys.argv[1:2] == ["init"]:
        add_mlp(sys.argv[2], sys.argv[3])
        sys.exit(0)
    sys.exit(main(sys.argv[1:]))
