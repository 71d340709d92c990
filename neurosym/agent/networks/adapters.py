"""One adapter per relational module, registered by name: everything outside the networks
reads a module through its adapter and never asks which module it is.

An adapter class says what its module shows and does the module-specific work:

* :meth:`RelationalAdapter.build` makes the module from a ModelConfig;
* the one producer of a state's network facts: :meth:`~RelationalAdapter.keep`
  reduces a batch of states' introspection (a cache of hook values) to small
  per-state arrays, and :meth:`~RelationalAdapter.rows` turns kept arrays of any
  batch of states into the rows of the recording's tables (``attends``,
  ``relations``, ``r_vectors`` or ``attention``). The recorder calls them batched
  (keep per step, rows once at the end), the Prolog agent on the live states;
* per-head vectors for the probes and head ablation, as hooks on the module's
  :attr:`~RelationalAdapter.head_point` (:meth:`capture_heads`, :meth:`ablate_heads`).

A new module is one file with its ``nn.Module`` (hook points from
:mod:`neurosym.agent.networks.hooks`, ``forward(x, introspect=False) -> (out,
intro)``) and an adapter subclass passed to :func:`register`; an attention module
can reuse :class:`AttentionAdapter` (its facts are ``attention/6``).
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator, Mapping
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from neurosym.errors import ConfigError

if TYPE_CHECKING:  # torch is imported where a module runs: reading a recording needs none
    import torch
    from torch import nn

Columns = dict[str, np.ndarray]
"""one table's columns, all of one length"""

BACKGROUND = ("empty", "wall")
"""entities that are never attention queries in the ``attention`` table (too many, too dull)"""

_REGISTRY: dict[str, type[RelationalAdapter]] = {}


def register(adapter: type[RelationalAdapter]) -> type[RelationalAdapter]:
    """Make ``adapter.name`` a module name ModelConfig accepts (usable as a class decorator)."""
    if not adapter.name or not adapter.name.isidentifier():
        raise ConfigError(f"an adapter's name must be an identifier, got {adapter.name!r}")
    _REGISTRY[adapter.name] = adapter
    return adapter


def unregister(name: str) -> None:
    """Forget the module registered as ``name`` (a test's module, say)."""
    _REGISTRY.pop(name, None)


def module_names() -> tuple[str, ...]:
    """The registered modules' names, in registration order."""
    return tuple(_REGISTRY)


def adapter_class(name: Any) -> type[RelationalAdapter]:
    """The adapter of the module named ``name`` (a ModelConfig's or a recording's meta)."""
    adapter = _REGISTRY.get(str(name))
    if adapter is None:
        raise ConfigError(f"unknown module {name!r}; expected one of {', '.join(_REGISTRY)}")
    return adapter


def module_has(name: Any, table: str) -> bool:
    """Whether recordings of the module named ``name`` have ``table`` (False for a name no
    adapter is registered under, such as an edited recording's)."""
    adapter = _REGISTRY.get(str(name))
    return adapter is not None and adapter.has(table)


def adapter_of(model: nn.Module) -> RelationalAdapter:
    """The adapter of an ActorCritic's relational module, bound to it."""
    return adapter_class(model.config.module)(model.relational)


class RelationalAdapter:
    """What outside code needs of one relational module; subclasses fill the class fields."""

    name: ClassVar[str] = ""
    """the module's name in ModelConfig.module and a recording's meta"""
    label: ClassVar[str] = ""
    """the module's name for people: "PrediNet\""""
    article: ClassVar[str] = ""
    """the module in a sentence, with its article: "a PrediNet\""""
    tables: ClassVar[tuple[str, ...]] = ()
    """the recording tables :meth:`rows` fills (and so the fact predicates it has)"""
    size_fields: ClassVar[tuple[str, ...]] = ()
    """ModelConfig fields only this module uses that size one of its layers"""
    head_point: ClassVar[str] = ""
    """the hook point of each head's contribution, (B, H, ...): what ablation replaces"""
    keep_graph_envs: ClassVar[int | None] = None
    """A3C: from this many envs up a worker keeps each acting step's graph instead of running
    a second forward over the rollout (None: never)"""
    head_term: ClassVar[str] = "head_output"
    """what the head point holds, in the experiments' terms (``replaced(head_output, ...)``)"""

    def __init__(self, module: nn.Module) -> None:
        self.module = module

    # ------------------------------------------------------------ the module

    @classmethod
    def build(cls, config: Any) -> nn.Module:
        """The module for a ModelConfig."""
        raise NotImplementedError

    @classmethod
    def relation_count(cls, config: Any) -> int:
        """Relations J per head (relation/7's j), 0 for a module without them."""
        return 0

    @classmethod
    def has(cls, table: str) -> bool:
        """Whether the module's recordings have ``table`` (``attends``, ``attention``...)."""
        return table in cls.tables

    # ------------------------------------------------------------ facts

    @classmethod
    def keep(cls, intro: Any, grid: np.ndarray, top_keys: int = 1) -> Columns:
        """Per-state arrays (first axis: the m states) kept from a numpy introspection of m
        states and their (m, N) entity codes before the step."""
        raise NotImplementedError

    @classmethod
    def rows(
        cls, kept: Columns, ep: np.ndarray, t: np.ndarray, names: np.ndarray, width: int
    ) -> dict[str, Columns]:
        """Table name -> columns for the states of ``kept`` (episode ``ep``, step ``t``), rows in
        state order; ``names`` the env's entity names by code, ``width`` the grid's."""
        raise NotImplementedError

    # ------------------------------------------------------------ heads

    def head_vector(self, value: torch.Tensor) -> torch.Tensor:
        """(B, H, D) the probes' vector of each head, from the value at :attr:`head_point`."""
        return value.detach().clone()

    def head_mean(self, model: nn.Module, obs: np.ndarray, batch: int) -> torch.Tensor:
        """(H, ...) each head's mean value at :attr:`head_point` over ``obs``: the replacement
        that ablates it."""
        import torch

        total: torch.Tensor | None = None
        with self.capture(self.head_point) as got, torch.inference_mode():
            for start in range(0, len(obs), batch):
                model(torch.from_numpy(np.ascontiguousarray(obs[start : start + batch])))
                out = got.pop().double().sum(0)
                total = out if total is None else total + out
        if total is None:
            raise ConfigError("no states to compute head means on")
        return (total / len(obs)).float()

    @contextlib.contextmanager
    def capture(self, point: str) -> Iterator[list[torch.Tensor]]:
        """Each forward's value at ``point`` appended to the yielded list."""
        from neurosym.agent.networks.hooks import hooked

        got: list[torch.Tensor] = []
        with hooked(self.module, [(point, got.append)]):
            yield got

    @contextlib.contextmanager
    def capture_heads(self) -> Iterator[list[torch.Tensor]]:
        """Each forward's per-head vectors (B, H, D) appended to the yielded list (after any
        ablation entered before)."""
        from neurosym.agent.networks.hooks import hooked

        got: list[torch.Tensor] = []
        with hooked(self.module, [(self.head_point, lambda v: got.append(self.head_vector(v)))]):
            yield got

    @contextlib.contextmanager
    def ablate_heads(self, replacement: Mapping[int, torch.Tensor]) -> Iterator[None]:
        """Head h's value at :attr:`head_point` is ``replacement[h]`` in every forward of the block."""
        from neurosym.agent.networks.hooks import hooked, replace_heads

        heads = self.module.heads
        for h in sorted(int(h) for h in replacement):
            if not 0 <= h < heads:
                raise ConfigError(f"head {h} does not exist; the model has heads 0..{heads - 1}")
        swap = {int(h): v for h, v in replacement.items()}
        with hooked(self.module, [(self.head_point, lambda v: replace_heads(v, swap))]):
            yield


@register
class PrediNetAdapter(RelationalAdapter):
    """PrediNet: each head's two attended cells (attends/8), relations (relation/7, holds/5)
    and R vector; the head vector is R^h (J + 4)."""

    name = "predinet"
    label = "PrediNet"
    article = "a PrediNet"
    tables = ("attends", "relations", "r_vectors")
    size_fields = ("relations",)
    head_point = "r"
    head_term = "r_vector"

    @classmethod
    def build(cls, config: Any) -> nn.Module:
        from neurosym.agent.networks.predinet import PrediNet

        return PrediNet(
            config.n_entities,
            config.entity_size,
            config.heads,
            config.key_size,
            config.relations,
            config.output_size,
            config.attention_gain,
            config.query,
            config.keys,
            config.obs_shape[0],
            getattr(config, "relation_bits", None),
        )

    @classmethod
    def relation_count(cls, config: Any) -> int:
        return int(config.relations)

    @classmethod
    def keep(cls, intro: Any, grid: np.ndarray, top_keys: int = 1) -> Columns:
        a1 = np.asarray(intro.attention1)  # (m, H, N)
        a2 = np.asarray(intro.attention2)
        i1, i2 = a1.argmax(-1), a2.argmax(-1)  # (m, H)
        return {
            "i1": i1,
            "i2": i2,
            "w1": np.take_along_axis(a1, i1[..., None], -1)[..., 0],
            "w2": np.take_along_axis(a2, i2[..., None], -1)[..., 0],
            "e1": np.take_along_axis(grid, i1, 1),
            "e2": np.take_along_axis(grid, i2, 1),
            "rel": np.asarray(intro.relations),  # (m, H, J)
            "rvec": np.asarray(intro.r_vectors()),  # (m, H, J + 4)
        }

    @classmethod
    def rows(
        cls, kept: Columns, ep: np.ndarray, t: np.ndarray, names: np.ndarray, width: int
    ) -> dict[str, Columns]:
        i1, i2, rel, rvec = kept["i1"], kept["i2"], kept["rel"], kept["rvec"]
        S, H = i1.shape
        J, R = rel.shape[-1], rvec.shape[-1]
        idx = np.stack([i1, i2], axis=-1)  # (S, H, 2): argument 1 then 2 of each head
        ent = np.stack([kept["e1"], kept["e2"]], axis=-1)
        wgt = np.stack([kept["w1"], kept["w2"]], axis=-1)
        attends = {
            "episode": np.repeat(ep, H * 2),
            "t": np.repeat(t, H * 2),
            "head": np.tile(np.repeat(np.arange(H), 2), S),
            "arg": np.tile(np.array([1, 2]), S * H),
            "entity": names[ent.reshape(-1)],
            "row": idx.reshape(-1) // width,
            "col": idx.reshape(-1) % width,
            "weight": wgt.reshape(-1).astype(np.float64),
        }
        relations = {
            "episode": np.repeat(ep, H * J),
            "t": np.repeat(t, H * J),
            "head": np.tile(np.repeat(np.arange(H), J), S),
            "j": np.tile(np.arange(J), S * H),
            "a": names[np.repeat(kept["e1"].reshape(-1), J)],
            "b": names[np.repeat(kept["e2"].reshape(-1), J)],
            "value": rel.reshape(-1).astype(np.float64),
        }
        r_vectors = {
            "episode": np.repeat(ep, H * R),
            "t": np.repeat(t, H * R),
            "head": np.tile(np.repeat(np.arange(H), R), S),
            "j": np.tile(np.arange(R), S * H),
            "value": rvec.reshape(-1).astype(np.float64),
        }
        return {"attends": attends, "relations": relations, "r_vectors": r_vectors}

    def head_mean(self, model: nn.Module, obs: np.ndarray, batch: int) -> torch.Tensor:
        import torch

        vecs: list[np.ndarray] = []
        with self.capture_heads() as got, torch.inference_mode():
            for start in range(0, len(obs), batch):
                model(torch.from_numpy(np.ascontiguousarray(obs[start : start + batch])))
                vecs.append(got.pop().numpy())
        if not vecs:
            raise ConfigError("no states to compute head means on")
        return torch.from_numpy(np.concatenate(vecs).astype(np.float64).mean(axis=0)).float()


class AttentionAdapter(RelationalAdapter):
    """A self-attention module over the cells with an ``attention`` point (B, H, N, N), query x
    key: each query cell's strongest keys (attention/6). Head vectors and ablation go through
    ``head_point``; a subclass names it and builds the module."""

    tables = ("attention",)

    @classmethod
    def keep(cls, intro: Any, grid: np.ndarray, top_keys: int = 1) -> Columns:
        att = np.asarray(intro.attention)  # (m, H, N, N) query x key
        k = min(top_keys, att.shape[-1])
        if k == 1:
            top = att.argmax(-1)[..., None]  # (m, H, N, 1)
        else:  # the k largest, strongest first
            part = np.argpartition(-att, k - 1, axis=-1)[..., :k]
            order = np.argsort(-np.take_along_axis(att, part, -1), axis=-1, kind="stable")
            top = np.take_along_axis(part, order, -1)  # (m, H, N, k)
        return {"top": top, "weight": np.take_along_axis(att, top, -1), "grid": grid}

    @classmethod
    def rows(
        cls, kept: Columns, ep: np.ndarray, t: np.ndarray, names: np.ndarray, width: int
    ) -> dict[str, Columns]:
        top, weight, grid = kept["top"], kept["weight"], kept["grid"]  # (S, H, N, k), (S, N)
        S, H, N, k = top.shape
        query_code = np.broadcast_to(grid[:, None, :, None], (S, H, N, k))
        key_code = np.take_along_axis(
            np.broadcast_to(grid[:, None, :], (S, H, N)), top.reshape(S, H, N * k), -1
        )
        query_cell = np.broadcast_to(np.arange(N)[None, None, :, None], (S, H, N, k))
        keep = ~np.isin(names, BACKGROUND)[query_code].reshape(-1)
        flat_q = query_cell.reshape(-1)[keep]
        flat_k = top.reshape(-1)[keep]
        attention = {
            "episode": np.repeat(ep, H * N * k)[keep],
            "t": np.repeat(t, H * N * k)[keep],
            "head": np.tile(np.repeat(np.arange(H), N * k), S)[keep],
            "query": names[query_code.reshape(-1)[keep]],
            "key": names[key_code.reshape(-1)[keep]],
            "weight": weight.reshape(-1)[keep].astype(np.float64),
            "query_row": flat_q // width,
            "query_col": flat_q % width,
            "key_row": flat_k // width,
            "key_col": flat_k % width,
        }
        return {"attention": attention}


@register
class MHDPAAdapter(AttentionAdapter):
    """MHDPA: the head vector is head h's output A^h x W_V^h W_O^h (N, F) max-pooled over
    entities (the module pools its own output so); ablation replaces the output (N, F)."""

    name = "mhdpa"
    label = "MHDPA"
    article = "an MHDPA"
    size_fields = ("value_size",)
    head_point = "head_out"
    # its cost is per-sample attention, cheapest in small batches: from 8 envs up, keeping
    # each acting step's graph beats a second forward over the rollout
    keep_graph_envs = 8

    @classmethod
    def build(cls, config: Any) -> nn.Module:
        from neurosym.agent.networks.mhdpa import MHDPA

        return MHDPA(
            config.entity_size,
            config.heads,
            config.key_size,
            config.value_size,
            config.output_size,
            config.attention_gain,
        )

    def head_vector(self, value: torch.Tensor) -> torch.Tensor:
        return value.detach().amax(dim=2)


@register
class OutsideAttentionAdapter(AttentionAdapter):
    """An agent trained outside neurosym whose named attention layer is tapped
    (:mod:`neurosym.outside`): attention/6 from its weights, each head's attended values
    (N, D) as its head point, max-pooled over cells for the probes. It is built by the
    user's own code, never from a ModelConfig."""

    name = "outside_attention"
    label = "outside attention"
    article = "an outside attention"
    head_point = "head_out"

    @classmethod
    def build(cls, config: Any) -> nn.Module:
        raise ConfigError(
            "an outside agent's network is built by its own code (neurosym.outside), not from a "
            "model config"
        )

    @classmethod
    def keep(cls, intro: Any, grid: np.ndarray, top_keys: int = 1) -> Columns:
        att = np.asarray(intro.attention)
        cells = grid.shape[1]
        if att.shape[-2:] != (cells, cells):
            raise ConfigError(
                f"the agent's attention is over {att.shape[-2]} queries x {att.shape[-1]} keys; "
                f"neurosym reads attention as cell to cell over the env's {cells} grid cells "
                "(entity k is cell k, row-major): name a layer whose tokens are the cells"
            )
        return super().keep(intro, grid, top_keys)

    def head_vector(self, value: torch.Tensor) -> torch.Tensor:
        return value.detach().amax(dim=2)


@register
class OutsideAdapter(RelationalAdapter):
    """An agent trained outside neurosym with no attention layer named: its recordings have
    behaviour only (no network tables, no heads)."""

    name = "outside"
    label = "outside agent"
    article = "an outside agent"
    head_point = "head_out"

    @classmethod
    def build(cls, config: Any) -> nn.Module:
        return OutsideAttentionAdapter.build(config)

    @classmethod
    def keep(cls, intro: Any, grid: np.ndarray, top_keys: int = 1) -> Columns:
        return {}

    @classmethod
    def rows(
        cls, kept: Columns, ep: np.ndarray, t: np.ndarray, names: np.ndarray, width: int
    ) -> dict[str, Columns]:
        return {}
