"""Per-head vectors of a network at recorded states, and head ablation, from outside the model.

The model files are not touched: everything here works through forward hooks
and pre-hooks on the relational module's submodules.

* PrediNet: the heads' R vectors are concatenated, (B, H * (J + 4)), and enter
  the ``out`` linear layer. A forward pre-hook on ``relational.out`` reads them
  (:func:`head_vectors`) or replaces head h's slice (:func:`ablate_heads`).
* MHDPA: the heads' outputs A^h x W_V^h W_O^h are summed into the residual
  that enters ``relational.norm1``. A pre-hook on the MHDPA module keeps its
  input x; the per-head outputs are recomputed from x with the module's own
  folded weights (:func:`mhdpa_head_outputs`), and a pre-hook on ``norm1``
  swaps head h's output for its replacement. A head's *vector* is its output
  max-pooled over entities (the module pools its own output the same way).

Observations are not stored in a recording; :func:`replay_observations` gets
them back by replaying each episode's recorded actions from its seed on the
batched env (the envs are deterministic given the seed), and checks the agent's
cell against the recorded positions at every state.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from typing import Any

import numpy as np
import pandas as pd
import torch
from torch import nn

from neurosym.errors import ConfigError


def relational(model: nn.Module) -> nn.Module:
    """The model's relational module (PrediNet or MHDPA)."""
    return model.relational


def module_kind(model: nn.Module) -> str:
    """``"predinet"`` or ``"mhdpa"``."""
    return str(model.config.module)


def replay_observations(
    recording: Any, env_name: str, env_kwargs: Mapping[str, Any] | None = None, batch: int = 256
) -> np.ndarray:
    """(S, C, H, W) uint8 observations of the acted states, in :func:`acted_states` order.

    Episode k is reset with its recorded seed and fed its recorded actions;
    ConfigError when the replay leaves the recorded trace (another env or map).
    """
    from neurosym.envs import ACTION_NAMES, make_batched
    from neurosym.meaning.predicates import acted_states

    eps = recording.episodes
    states = acted_states(eps)
    steps = recording.steps
    codes = pd.Categorical(steps["action"], categories=list(ACTION_NAMES)).codes
    if (codes < 0).any():
        raise ConfigError("the recording has actions that are not up, right, down or left")
    row_of = pd.MultiIndex.from_arrays([states["episode"], states["t"]]).get_indexer(
        pd.MultiIndex.from_arrays([steps["episode"], steps["t"]])
    )
    actions = np.zeros(len(states), dtype=np.int64)
    actions[row_of[row_of >= 0]] = codes[row_of >= 0]
    pos = recording.positions.loc[recording.positions["object"] == "agent"]
    agent_rows = pd.MultiIndex.from_arrays([states["episode"], states["t"]]).get_indexer(
        pd.MultiIndex.from_arrays([pos["episode"], pos["t"]])
    )
    expected = np.full(len(states), -1, dtype=np.int64)
    ok = agent_rows >= 0
    n_steps = eps["steps"].to_numpy(dtype=np.int64)
    offsets = np.cumsum(n_steps) - n_steps
    seeds = eps["seed"].to_numpy(dtype=np.int64)
    obs_out: np.ndarray | None = None
    venvs: dict[int, Any] = {}
    try:
        for start in range(0, len(eps), batch):
            n = min(batch, len(eps) - start)
            venv = venvs.get(n) or venvs.setdefault(
                n, make_batched(env_name, n, **dict(env_kwargs or {}))
            )
            if start == 0:  # the agent's recorded cell, row-major, at every state
                width = venv.entity_grid().shape[-1]
                expected[agent_rows[ok]] = (
                    pos["row"].to_numpy()[ok] * width + pos["col"].to_numpy()[ok]
                )
                agent_code = list(venv.entity_names).index("agent")
            obs, _ = venv.reset(seed=[int(s) for s in seeds[start : start + n]])
            if obs_out is None:
                obs_out = np.zeros((len(states), *obs.shape[1:]), dtype=obs.dtype)
            length = n_steps[start : start + n]
            base = offsets[start : start + n]
            for t in range(int(length.max(initial=0))):
                live = np.flatnonzero(length > t)
                rows = base[live] + t
                obs_out[rows] = obs[live]
                cell = (venv.entity_grid().reshape(n, -1)[live] == agent_code).argmax(axis=1)
                bad = (expected[rows] >= 0) & (cell != expected[rows])
                if bad.any():
                    e = int(states["episode"].iat[int(rows[bad][0])])
                    raise ConfigError(
                        f"episode {e} does not replay on {env_name} at step {t}: "
                        "the recording was made on another env or map"
                    )
                act = np.zeros(n, dtype=np.int64)
                act[live] = actions[rows]
                obs, *_ = venv.step(act)
    finally:
        for venv in venvs.values():
            venv.close()
    assert obs_out is not None
    return obs_out


def mhdpa_head_outputs(module: nn.Module, x: torch.Tensor) -> torch.Tensor:
    """(B, H, N, F) each head's output A^h x W_V^h W_O^h, as MHDPA sums them into the residual.

    Recomputed from the module's input x with its own folded weights (see
    neurosym/agent/networks/mhdpa.py); tests check that the heads' sum plus the
    projection's bias is exactly what enters ``norm1``, minus x.
    """
    B, N, F = x.shape
    H = module.heads
    with torch.no_grad():  # analysis only: never part of a training graph
        w_qk, w_vo = module.folded_weights()
        xq = (x @ w_qk).view(B, N, H, F).transpose(1, 2)  # (B, H, N, F)
        xv = (x @ w_vo).view(B, N, H, F).transpose(1, 2)  # (B, H, N, F)
        att = torch.softmax(xq @ x.unsqueeze(1).transpose(-1, -2), dim=-1)  # (B, H, N, N)
        return att @ xv  # (B, H, N, F)


@contextmanager
def capture_heads(model: nn.Module) -> Iterator[list[torch.Tensor]]:
    """Collect each forward pass's per-head vectors, (B, H, D), into the yielded list.

    PrediNet: D = J + 4, R^h as it enters ``out`` (after any ablation hook
    registered earlier). MHDPA: D = F, each head's output max-pooled over
    entities (after ablation, the replaced output).
    """
    rel = relational(model)
    got: list[torch.Tensor] = []
    handles = []
    if module_kind(model) == "predinet":
        H = rel.heads

        def grab(_mod: nn.Module, args: tuple[torch.Tensor, ...]) -> None:
            r = args[0]
            got.append(r.detach().reshape(r.shape[0], H, -1).clone())

        handles.append(rel.out.register_forward_pre_hook(grab))
    else:
        state: dict[str, torch.Tensor] = {}

        def keep(_mod: nn.Module, args: tuple[torch.Tensor, ...]) -> None:
            state["x"] = args[0]

        def grab_mhdpa(_mod: nn.Module, args: tuple[torch.Tensor, ...]) -> None:
            out = mhdpa_head_outputs(rel, state["x"])  # (B, H, N, F)
            swap = getattr(rel, "_neurosym_ablation", None)
            if swap is not None:
                out = swap(out)
            got.append(out.detach().amax(dim=2))

        handles.append(rel.register_forward_pre_hook(keep))
        handles.append(rel.norm1.register_forward_pre_hook(grab_mhdpa))
    try:
        yield got
    finally:
        for h in handles:
            h.remove()


@contextmanager
def ablate_heads(model: nn.Module, replacement: Mapping[int, torch.Tensor]) -> Iterator[None]:
    """Replace head h's contribution by ``replacement[h]`` in every forward pass.

    PrediNet: ``replacement[h]`` is an R vector (J + 4,) put in head h's slice
    of the input of ``out``. MHDPA: it is a head output (N, F) put in place of
    head h's output in the residual that enters ``norm1``. Other heads are
    untouched. Register before :func:`capture_heads` so the capture sees it.
    """
    rel = relational(model)
    handles = []
    heads = sorted(int(h) for h in replacement)
    for h in heads:
        if not 0 <= h < rel.heads:
            raise ConfigError(f"head {h} does not exist; the model has heads 0..{rel.heads - 1}")
    if module_kind(model) == "predinet":
        H = rel.heads

        def swap_r(_mod: nn.Module, args: tuple[torch.Tensor, ...]) -> tuple[torch.Tensor, ...]:
            r = args[0]
            B = r.shape[0]
            r = r.reshape(B, H, -1).clone()  # (B, H, J + 4)
            for h in heads:
                r[:, h] = replacement[h].to(r.dtype)
            return (r.reshape(B, -1), *args[1:])

        handles.append(rel.out.register_forward_pre_hook(swap_r))
    else:
        state: dict[str, torch.Tensor] = {}

        def keep(_mod: nn.Module, args: tuple[torch.Tensor, ...]) -> None:
            state["x"] = args[0]

        def swap_out(out: torch.Tensor) -> torch.Tensor:
            out = out.clone()
            for h in heads:
                out[:, h] = replacement[h].to(out.dtype)
            return out

        def swap_residual(
            _mod: nn.Module, args: tuple[torch.Tensor, ...]
        ) -> tuple[torch.Tensor, ...]:
            out = mhdpa_head_outputs(rel, state["x"])  # (B, H, N, F)
            delta = swap_out(out)[:, heads].sum(1) - out[:, heads].sum(1)  # (B, N, F)
            return (args[0] + delta, *args[1:])

        handles.append(rel.register_forward_pre_hook(keep))
        handles.append(rel.norm1.register_forward_pre_hook(swap_residual))
        rel._neurosym_ablation = swap_out
    try:
        yield
    finally:
        for h in handles:
            h.remove()
        if hasattr(rel, "_neurosym_ablation"):
            del rel._neurosym_ablation


def head_vectors(
    model: nn.Module, obs: np.ndarray, batch: int = 2048
) -> tuple[np.ndarray, np.ndarray]:
    """(S, H, D) per-head vectors and (S, A) action probabilities of ``model`` on ``obs``.

    Runs under whatever ablation hooks are registered on the model.
    """
    vecs: list[np.ndarray] = []
    probs: list[np.ndarray] = []
    with torch.inference_mode(), capture_heads(model) as got:
        for start in range(0, len(obs), batch):
            x = torch.from_numpy(np.ascontiguousarray(obs[start : start + batch]))
            logits = model(x)[0]
            probs.append(torch.softmax(logits.float(), dim=-1).numpy())
            vecs.append(got.pop().numpy())
    if not vecs:
        raise ConfigError("no states to compute head vectors on")
    return np.concatenate(vecs), np.concatenate(probs)


def head_means(model: nn.Module, obs: np.ndarray, batch: int = 2048) -> dict[int, torch.Tensor]:
    """Each head's mean replacement over ``obs``: PrediNet R^h (J + 4,), MHDPA output (N, F)."""
    rel = relational(model)
    if module_kind(model) == "predinet":
        vecs, _ = head_vectors(model, obs, batch)
        mean = torch.from_numpy(vecs.astype(np.float64).mean(axis=0)).float()  # (H, J + 4)
        return {h: mean[h] for h in range(rel.heads)}
    total: torch.Tensor | None = None
    state: dict[str, torch.Tensor] = {}

    def keep(_mod: nn.Module, args: tuple[torch.Tensor, ...]) -> None:
        state["x"] = args[0]

    handle = rel.register_forward_pre_hook(keep)
    try:
        with torch.inference_mode():
            for start in range(0, len(obs), batch):
                model(torch.from_numpy(np.ascontiguousarray(obs[start : start + batch])))
                out = mhdpa_head_outputs(rel, state["x"]).double().sum(0)  # (H, N, F)
                total = out if total is None else total + out
    finally:
        handle.remove()
    assert total is not None
    mean = (total / len(obs)).float()
    return {h: mean[h] for h in range(rel.heads)}
