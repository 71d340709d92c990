"""PrediNet (Shanahan et al. 2020) as docs/design.md describes it.

With L the (B, N, F) entities (F = features + 2 coordinates):

* K = L W_K, shared by all heads;
* per head h: Q1 = flat(L) W_Q1^h, Q2 = flat(L) W_Q2^h;
* a1 = softmax(Q1 K^T / sqrt(d)), a2 = softmax(Q2 K^T / sqrt(d)) over entities;
* E1 = a1 L, E2 = a2 L;
* D^h = E1 W_S - E2 W_S, W_S shared by all heads so that relation j means the
  same thing in every head;
* R^h = [D^h, pos(E1), pos(E2)].

Choices made here (docs/design.md leaves them open):

* The 1/sqrt(d) in the softmax is the usual attention temperature, times
  ``attention_gain`` (ModelConfig; 1 in Table 4's network). It is the same
  function class as DESIGN's softmax(Q K^T) (W_Q absorbs the factor); it only
  sets how peaked the attention is at initialisation (uniform at gain 1).
* W_S reads the feature channels of E1 and E2, not their two coordinate
  channels: as in the thesis (section 3.2.4), D carries no position
  information; the positions are in R as pos(E1), pos(E2). D is computed as
  (E1 - E2) W_S, which equals E1 W_S - E2 W_S and is exactly antisymmetric in
  floating point.
* ``query="learned"`` (ModelConfig.query; "scene", DESIGN's flat(L) W_Q, is
  the default): each head's Q1, Q2 are learned vectors, the same for every
  scene, so a head selects by what an entity is and where it stands, not by
  the rest of the scene. Why it exists: with scene queries, Adam's first
  updates move every one of W_Q's inputs by about lr in the same direction
  (most of flat(L) is the same in every level: coordinates, walls,
  background), so the queries jump by the same large vector in every scene
  and the attention can saturate on fixed cells. A learned query moves by
  about lr per step. It cannot make which lock a head attends to depend on
  the colour of the held key, which bw2/bw3's chains may need.
* ``query="scene_mlp"`` (with cell keys): Q = flat(L) W_Q + MLP(flat(L)), one ReLU layer
  of :data:`QUERY_HIDDEN` units whose output layer starts at zero (the same queries as
  "scene" until trained). Why: the scene query is linear in the scene, and choosing between
  a route through a teleport and one around it (which object the agent meets next) is not;
  the RGW fact bottleneck's head 0 named the teleport on its route more often with it
  (docs/results.md, "The fact bottleneck").
* ``keys="cells"`` (ModelConfig.keys; "entities", K = L W_K, is the default):
  K = c W_K with c the (B, N, C) cells' own observation vectors, so a head
  addresses a cell by what it holds; the attended entities are still L's.
  Computed with autograd (the hand-written attention below assumes one L for
  keys and values) and without recorded queries. ``keys="cells_xy"``: the keys
  read each cell's observation and its two coordinates (L's last two features),
  so a head can single out one of two cells that hold the same thing.
* The heads' R vectors are concatenated, (B, H * (J + 4)), and a linear layer
  projects them to Table 4's output size (26). It is linear so that the
  output is a plain read-out of R and the R vectors stay the only relational
  features.
* ``relation_bits=tau`` (ModelConfig.relation_bits; None, the default, is off): the fact
  bottleneck. The read-out then sees, per head, only [D_j > tau] and [D_j < -tau] (the two
  orientations holds/5 writes with ``threshold(J, tau)``) and the observation of each
  argument's argmax cell (what attends/8 names it by; on RGW it carries the held-sword
  plane, so what the agent holds too): no relation values, no positions. The forward is
  binary; the backward goes through sigmoid(+-D_j - tau) and the soft attention a @ cells
  (straight-through). The bits are read from R^h's D part after its hook point, so a value
  put in place of D^h or R^h is what the bits are taken of.

How it is computed (same function, same parameters, cheaper on a CPU):

* Q K^T = Q (L W_K)^T = (Q W_K) L^T: the (B, 2H, D) queries are moved into
  entity space once instead of projecting all N entities to keys (the keys'
  projection and its backward were a tenth of an update).
* Q1 and Q2 of all heads are stacked into one (B, 2H, D) tensor, so both
  attentions share one softmax and one batched product with L (small
  batched products are slow per call). W_Q1 and W_Q2 are concatenated for
  one product with flat(L): its backward is then one contiguous product
  instead of two over strided halves (the same numbers bit for bit).
* The attention has a hand-written backward (:class:`PrediNetAttention`):
  L's three gradients are one batched product and one ``addmm`` instead of
  two small products, a strided add and a plain one.
* A3C acts on a rollout and then runs the model over the same observations
  with the same weights to build the update's graph: the queries acting
  computed are kept (:meth:`PrediNet.recording_queries`) and taken back by
  that forward, so the largest product of the forward runs once per
  observation, not twice.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Iterator
from typing import NamedTuple

import torch
from torch import nn

from neurosym.agent.networks.hooks import HookPoint, introspected
from neurosym.agent.networks.introspection import PrediNetIntrospection

QUERY_HIDDEN = 256
"""hidden units of the MLP queries (``query="scene_mlp"``)"""


class QueryRecord(NamedTuple):
    """Queries of forwards run without a graph, and the weights they were computed with."""

    key: tuple
    parts: list[torch.Tensor]


class PrediNetAttention(torch.autograd.Function):
    """(L, W_Q1|W_Q2, W_K, scale[, known first rows of Q]) -> attentions a (B, 2H, N), attended
    entities e (B, 2H, F), the queries Q (B, 2H D; no gradient flows back through this output)
    and the scores s (B, 2H, N) before the softmax (a loss on where a head looks reads them).

    The same function as autograd's ``q = flat(L) W_Q^T; s = scale (q W_K) L^T;
    a = softmax(s); e = a L``, with a hand-written backward: L is used three
    times (flat(L), the scores, e), and autograd summed its three gradients
    with two small batched products (inner size 2H) and a strided add (the
    scores' gradient arrives transposed): a quarter of an rgw2 update's
    backward. Here the two products are one, ``[a; g_s]^T [g_e; Q W_K]``
    (inner size 4H), and the flat path's gradient is added by the same
    ``addmm`` that computes it.
    """

    @staticmethod
    def forward(ctx, L, w_q, w_k, scale, q_head=None, q_learned=None):  # type: ignore[override]
        B, N, F = L.shape
        D = w_k.shape[0]
        flat = L.reshape(B, N * F)
        if q_learned is not None:  # ModelConfig.query "learned": the same queries for every scene
            q = q_learned.expand(B, -1).contiguous()
        elif q_head is None:
            q = flat @ w_q.t()  # (B, 2H D)
        else:  # the first rows' queries are known (acting computed them with these weights)
            q = torch.cat([q_head, flat[q_head.shape[0] :] @ w_q.t()])
        q = q.view(B, -1, D)  # (B, 2H, D)
        qk = (q @ w_k) * scale  # (B, 2H, F)
        s = qk @ L.transpose(1, 2)  # (B, 2H, N)
        a = torch.softmax(s, dim=-1)
        e = a @ L  # (B, 2H, F)
        ctx.save_for_backward(L, w_q, w_k, q, qk, a)
        ctx.scale = scale
        ctx.learned = q_learned is not None
        q_flat = q.view(B, -1)
        ctx.mark_non_differentiable(q_flat)
        return a, e, q_flat, s

    @staticmethod
    def backward(ctx, g_a, g_e, _g_q, g_scores):  # type: ignore[override]
        L, w_q, w_k, q, qk, a = ctx.saved_tensors
        B, N, F = L.shape
        if g_e is None:
            g_e = torch.zeros_like(qk)
        g_at = g_e @ L.transpose(1, 2)  # (B, 2H, N) the attention's gradient through e
        if g_a is not None:
            g_at = g_at + g_a
        g_s = a * (g_at - (g_at * a).sum(-1, keepdim=True))  # softmax backward
        if g_scores is not None:  # a loss read the scores themselves
            g_s = g_s + g_scores
        g_qk = g_s @ L  # (B, 2H, F)
        # e = a L and s = qk L^T: L's two gradients in one product
        g_l = torch.cat([a, g_s], 1).transpose(1, 2) @ torch.cat([g_e, qk], 1)  # (B, N, F)
        g_qk = g_qk * ctx.scale
        g_wk = q.reshape(-1, q.shape[-1]).t() @ g_qk.reshape(-1, F)  # (D, F)
        g_q = (g_qk @ w_k.t()).reshape(B, -1)  # (B, 2H D)
        if ctx.learned:  # no flat(L) path; the one query vector gathers every row's gradient
            return g_l, None, g_wk, None, None, g_q.sum(0)
        g_wq = g_q.t() @ L.reshape(B, N * F)  # (2H D, N F)
        g_l = torch.addmm(g_l.reshape(B, N * F), g_q, w_q).view(B, N, F)  # + flat(L)'s gradient
        return g_l, g_wq, g_wk, None, None, None


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
        query: str = "scene",
        keys: str = "entities",
        cell_size: int = 0,
        relation_bits: float | None = None,
    ) -> None:
        super().__init__()
        assert entity_size > 2, "entities need features besides the 2 coordinates"
        assert keys == "entities" or cell_size > 0, "cell keys need the cells' size"
        assert query != "scene_mlp" or keys != "entities", "MLP queries need cell keys"
        self.heads, self.key_size, self.relations = heads, key_size, relations
        self.query_mode = query
        self.keys = keys
        key_input = {"entities": entity_size, "cells": cell_size, "cells_xy": cell_size + 2}[keys]
        self.key = nn.Linear(key_input, key_size, bias=False)  # W_K, shared
        if query == "learned":
            # Q1^h, Q2^h of every head as one (2H D) vector; std 1 gives a fresh attention about
            # as peaked as the scene queries' (bw1, gain 8: largest weight 0.079 against 0.033)
            self.queries = nn.Parameter(torch.randn(2 * heads * key_size))
        else:
            self.query1 = nn.Linear(
                n_entities * entity_size, heads * key_size, bias=False
            )  # W_Q1^h, all heads
            self.query2 = nn.Linear(
                n_entities * entity_size, heads * key_size, bias=False
            )  # W_Q2^h
        if query == "scene_mlp":
            self.query_mlp = nn.Sequential(
                nn.Linear(n_entities * entity_size, QUERY_HIDDEN),
                nn.ReLU(),
                nn.Linear(QUERY_HIDDEN, 2 * heads * key_size),
            )
            nn.init.zeros_(self.query_mlp[2].weight)  # adds nothing until trained
            nn.init.zeros_(self.query_mlp[2].bias)
        self.embed = nn.Linear(entity_size - 2, relations, bias=False)  # W_S, shared
        self.relation_bits = bits_threshold(relation_bits)
        if self.relation_bits is not None:
            assert cell_size > 0, "the fact bottleneck reads the attended cells' observations"
            self.out = nn.Linear(heads * 2 * (relations + cell_size), output_size)
        else:
            self.out = nn.Linear(heads * (relations + 4), output_size)
        self.scale = attention_gain / math.sqrt(key_size)
        # hook points (neurosym.agent.networks.hooks): the scores before the softmax (B, 2H, N),
        # the attention maps a1, a2 (B, H, N) and the positions (B, H, 2) are read-only in
        # effect (E1, E2 are computed with them inside the attention); a value put in place of
        # D^h (B, H, J) or of R^h (B, H, J + 4, what ``out`` reads) is what the rest of the
        # forward uses
        self.hook_scores = HookPoint()
        self.hook_attention1, self.hook_attention2 = HookPoint(), HookPoint()
        self.hook_relations = HookPoint()
        self.hook_positions1, self.hook_positions2 = HookPoint(), HookPoint()
        self.hook_r = HookPoint()

    def weights_key(self) -> tuple:
        """Identifies the current W_Q values. A recorded query also depends on its entities, so
        a record is valid only for the same observations through the same encoder, which the
        caller guarantees (A3C: one weight load per rollout, no step until its update)."""
        if self.query_mode == "learned":
            return ((self.queries.data_ptr(), self.queries._version),)
        return tuple((w.data_ptr(), w._version) for w in (self.query1.weight, self.query2.weight))

    @contextlib.contextmanager
    def recording_queries(self) -> Iterator[QueryRecord]:
        """Keep the queries of every forward run without a graph inside the block.

        A3C acts on a rollout and then runs the model over the same observations
        again, with the same weights, to build the update's graph; the query
        projection (B x 2600 by 2600 x 256 on rgw2) is a tenth of a worker's time,
        and :meth:`forward` takes the recorded queries back (``queries=``) instead
        of computing them twice.
        """
        record = QueryRecord(self.weights_key(), [])
        self._recording = record
        try:
            yield record
        finally:
            self._recording = None

    def _scene_attention(
        self, L: torch.Tensor, queries: QueryRecord | None
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Attention with queries from flat(L), reusing a valid record and feeding an open one:
        a, e and the scores."""
        q_head = None
        if queries is not None and queries.parts and queries.key == self.weights_key():
            q_head = torch.cat(queries.parts) if len(queries.parts) > 1 else queries.parts[0]
            if q_head.shape[0] > L.shape[0]:
                q_head = None
        a, e, q, scores = PrediNetAttention.apply(
            L,
            torch.cat([self.query1.weight, self.query2.weight]),
            self.key.weight,
            self.scale,
            q_head,
        )
        recording = getattr(self, "_recording", None)
        if recording is not None and not torch.is_grad_enabled():
            if recording.key == self.weights_key():
                recording.parts.append(q)
        return a, e, scores

    def attention_logits(self, L: torch.Tensor, cells: torch.Tensor | None = None) -> torch.Tensor:
        """(B, 2H, N) the attention's scores before the softmax (the heads' first arguments, then
        their second), by plain autograd for every query and key mode: what the cell keys'
        attention computes, and what the hook point ``scores`` passes on in every mode. A loss
        on where a head looks reads these (``log_softmax``): a saturated softmax's probabilities
        carry no gradient to the cells it ignores."""
        B, N, F = L.shape
        D = self.key_size
        if self.query_mode == "learned":
            q = self.queries.view(-1, D).expand(B, -1, -1)  # (B, 2H, D)
        else:
            flat = L.reshape(B, N * F)
            w_q = torch.cat([self.query1.weight, self.query2.weight])  # (2H D, N F)
            q = (flat @ w_q.t()).view(B, -1, D)  # (B, 2H, D)
            if self.query_mode == "scene_mlp":
                q = q + self.query_mlp(flat).view(B, -1, D)
        if self.keys == "entities":
            keys = L
        elif cells is None:
            raise ValueError("PrediNet with keys='cells' needs the cells' observations")
        else:  # cells_xy: what each cell holds and where it is
            keys = torch.cat([cells, L[..., -2:]], dim=-1) if self.keys == "cells_xy" else cells
        return (q @ self.key.weight) @ keys.transpose(1, 2) * self.scale  # (B, 2H, N)

    def _cell_attention(
        self, L: torch.Tensor, cells: torch.Tensor
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Attention whose keys are the cells' observations: a (B, 2H, N), e = a L (B, 2H, F)
        and the scores."""
        scores = self.attention_logits(L, cells)
        a = torch.softmax(scores, dim=-1)
        return a, a @ L, scores

    def forward(
        self,
        L: torch.Tensor,
        introspect: bool = False,
        queries: QueryRecord | None = None,
        cells: torch.Tensor | None = None,
    ):
        """(out, None), or (out, :class:`PrediNetIntrospection` of the cached hook values) with
        ``introspect``. ``queries``: a record of this module's own earlier forwards over the
        first rows of ``L``, used only while the weights are unchanged (else recomputed).
        ``cells``: (B, N, C) each cell's observation, the keys' input when ``keys`` is a cells one
        (needed then)."""
        if not introspect:
            return self._forward(L, queries, cells), None
        return introspected(self, PrediNetIntrospection, lambda: self._forward(L, queries, cells))

    def _forward(
        self, L: torch.Tensor, queries: QueryRecord | None, cells: torch.Tensor | None
    ) -> torch.Tensor:
        B, N, F = L.shape
        H = self.heads
        if self.keys != "entities":
            if cells is None:
                raise ValueError("PrediNet with keys='cells' needs the cells' observations")
            a, e, scores = self._cell_attention(L, cells)
        elif self.query_mode == "learned":  # nothing to record or reuse: the queries are weights
            a, e, _, scores = PrediNetAttention.apply(
                L, None, self.key.weight, self.scale, None, self.queries
            )
        else:
            a, e, scores = self._scene_attention(L, queries)
        self.hook_scores(scores)  # (B, 2H, N)
        e1, e2 = e[:, :H], e[:, H:]  # (B, H, F)
        self.hook_attention1(a[:, :H])  # (B, H, N)
        self.hook_attention2(a[:, H:])
        rel = self.hook_relations(self.embed(e1[..., :-2] - e2[..., :-2]))  # (B, H, J)  D^h
        pos1 = self.hook_positions1(e1[..., -2:])  # (B, H, 2)
        pos2 = self.hook_positions2(e2[..., -2:])
        r = self.hook_r(torch.cat([rel, pos1, pos2], dim=-1))  # (B, H, J + 4)
        if self.relation_bits is not None:  # the fact bottleneck: what holds/5 says, nothing else
            if cells is None:
                raise ValueError("PrediNet with relation_bits needs the cells' observations")
            return self.out(self.fact_bits(r[..., : self.relations], a, cells).reshape(B, -1))
        return self.out(r.reshape(B, H * (self.relations + 4)))  # (B, output_size)

    def fact_bits(self, rel: torch.Tensor, a: torch.Tensor, cells: torch.Tensor) -> torch.Tensor:
        """What the read-out sees under the fact bottleneck, (B, H, 2 J + 2 C): per head the
        bits [D_j > tau], [D_j < -tau] (holds(r(J), A, B) and holds(r(J), B, A) with A, B the
        head's arguments 1 and 2) and the observations of the argmax cells of a1 and a2.

        Forward values are exactly 0/1 and the cells' own observations (``soft - soft.detach()
        + hard`` adds an exact zero); gradients are the surrogates'."""
        tau = self.relation_bits
        assert tau is not None
        up = _straight_through((rel > tau).to(rel.dtype), torch.sigmoid(rel - tau))
        down = _straight_through((rel < -tau).to(rel.dtype), torch.sigmoid(-rel - tau))
        C = cells.shape[-1]
        index = a.argmax(-1, keepdim=True).expand(-1, -1, C)  # (B, 2H, C): first of ties
        picked = _straight_through(torch.gather(cells, 1, index), a @ cells)  # (B, 2H, C)
        H = self.heads
        return torch.cat([up, down, picked[:, :H], picked[:, H:]], dim=-1)


def bits_threshold(tau: float | None) -> float | None:
    """The fact bottleneck's threshold as the forward compares it: rounded to float32 (the
    relations' dtype), so extract's ``abs:tau`` keeps exactly the bits the policy read."""
    return None if tau is None else float(torch.tensor(float(tau), dtype=torch.float32))


def _straight_through(hard: torch.Tensor, soft: torch.Tensor) -> torch.Tensor:
    """``hard`` in the forward (exactly: the zero is added to it last), ``soft``'s gradient."""
    return (soft - soft.detach()) + hard
