"""PrediNet (Shanahan et al. 2020) as DESIGN.md describes it.

With L the (B, N, F) entities (F = features + 2 coordinates):

* K = L W_K, shared by all heads;
* per head h: Q1 = flat(L) W_Q1^h, Q2 = flat(L) W_Q2^h;
* a1 = softmax(Q1 K^T / sqrt(d)), a2 = softmax(Q2 K^T / sqrt(d)) over entities;
* E1 = a1 L, E2 = a2 L;
* D^h = E1 W_S - E2 W_S, W_S shared by all heads so that relation j means the
  same thing in every head;
* R^h = [D^h, pos(E1), pos(E2)].

Choices made here (DESIGN.md leaves them open):

* The 1/sqrt(d) in the softmax is the usual attention temperature, times
  ``attention_gain`` (ModelConfig; 1 in Table 4's network). It is the same
  function class as DESIGN's softmax(Q K^T) (W_Q absorbs the factor); it only
  sets how peaked the attention is at initialisation (uniform at gain 1).
* W_S reads the feature channels of E1 and E2, not their two coordinate
  channels: as in the thesis (section 3.2.4), D carries no position
  information; the positions are in R as pos(E1), pos(E2). D is computed as
  (E1 - E2) W_S, which equals E1 W_S - E2 W_S and is exactly antisymmetric in
  floating point.
* The heads' R vectors are concatenated, (B, H * (J + 4)), and a linear layer
  projects them to Table 4's output size (26). It is linear so that the
  output is a plain read-out of R and the R vectors stay the only relational
  features.

How it is computed (same function, same parameters, cheaper on a CPU):

* Q K^T = Q (L W_K)^T = (Q W_K) L^T: the (B, 2H, D) queries are moved into
  entity space once instead of projecting all N entities to keys (the keys'
  projection and its backward were a tenth of an update).
* Q1 and Q2 of all heads are stacked into one (B, 2H, D) tensor, so both
  attentions share one softmax and one batched product with L (small
  batched products are slow per call). W_Q1 and W_Q2 are concatenated for
  one product with flat(L): its backward is then one contiguous product
  instead of two over strided halves (PrediNet's forward and backward over
  1,352 rgw2 observations 74 -> 69 ms on one core; same numbers bit for bit).
With the encoder's channels-last convolutions these made a forward and
backward over a 1352-observation update batch 25-35 % faster on one core, and
training on rgw2 with W = 2, K = 32 went from 8.0 k to 10.7 k frames/s
(bench/train.py's fps part).
"""

from __future__ import annotations

import math

import torch
import torch.nn.functional as nnf
from torch import nn

from neurosym.agent.introspection import PrediNetIntrospection


class PrediNet(nn.Module):
    """(B, N, F) entities -> (B, output_size), optionally with the per-head internals."""

    def __init__(
        self,
        n_entities: int,
        entity_size: int,
        heads: int,
        key_size: int,
        relations: int,
        output_size: int,
        attention_gain: float = 1.0,
    ) -> None:
        super().__init__()
        assert entity_size > 2, "entities need features besides the 2 coordinates"
        self.heads, self.key_size, self.relations = heads, key_size, relations
        self.key = nn.Linear(entity_size, key_size, bias=False)  # W_K, shared
        self.query1 = nn.Linear(
            n_entities * entity_size, heads * key_size, bias=False
        )  # W_Q1^h, all heads
        self.query2 = nn.Linear(n_entities * entity_size, heads * key_size, bias=False)  # W_Q2^h
        self.embed = nn.Linear(entity_size - 2, relations, bias=False)  # W_S, shared
        self.out = nn.Linear(heads * (relations + 4), output_size)
        self.scale = attention_gain / math.sqrt(key_size)

    def forward(self, L: torch.Tensor, introspect: bool = False):
        B, N, F = L.shape
        H, D = self.heads, self.key_size
        flat = L.reshape(B, N * F)  # (B, N * F)
        w_q = torch.cat([self.query1.weight, self.query2.weight])  # (2 H D, N F): W_Q1 | W_Q2
        q = nnf.linear(flat, w_q).view(B, 2 * H, D)  # Q1, Q2 of every head
        q_in_l = (q @ self.key.weight) * self.scale  # (B, 2H, F)  Q W_K: Q K^T = (Q W_K) L^T
        a = torch.softmax(q_in_l @ L.transpose(1, 2), dim=-1)  # (B, 2H, N)
        e = a @ L  # (B, 2H, F)
        a1, a2, e1, e2 = a[:, :H], a[:, H:], e[:, :H], e[:, H:]  # (B, H, N), (B, H, F)
        rel = self.embed(e1[..., :-2] - e2[..., :-2])  # (B, H, J)  D^h
        pos1, pos2 = e1[..., -2:], e2[..., -2:]  # (B, H, 2)
        r = torch.cat([rel, pos1, pos2], dim=-1)  # (B, H, J + 4)
        out = self.out(r.reshape(B, H * (self.relations + 4)))  # (B, output_size)
        if not introspect:
            return out, None
        return out, PrediNetIntrospection(a1, a2, rel, pos1, pos2)
