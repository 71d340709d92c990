"""Per-head vectors of a network at recorded states, and head ablation, through hooks.

Both go through the relational module's adapter
(:mod:`neurosym.agent.networks.adapters`): a hook on its head point reads each
head's value or puts a replacement in its place.

* PrediNet: the head point is R^h, (B, H, J + 4), what the ``out`` layer reads.
* MHDPA: it is each head's output A^h x W_V^h W_O^h, (B, H, N, F), which the
  module sums into its residual; a replacement moves the residual by the
  difference. A head's *vector* is its output max-pooled over entities (the
  module pools its own output the same way).

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

from neurosym.agent.networks.adapters import adapter_of
from neurosym.errors import ConfigError


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


@contextmanager
def capture_heads(model: nn.Module) -> Iterator[list[torch.Tensor]]:
    """Collect each forward pass's per-head vectors, (B, H, D), into the yielded list.

    The module's adapter reads them at its head hook point (after any ablation
    entered earlier): PrediNet R^h (D = J + 4), MHDPA each head's output
    max-pooled over entities (D = F).
    """
    with adapter_of(model).capture_heads() as got:
        yield got


@contextmanager
def ablate_heads(model: nn.Module, replacement: Mapping[int, torch.Tensor]) -> Iterator[None]:
    """Replace head h's contribution by ``replacement[h]`` in every forward pass: a hook on
    the module's head point (PrediNet: R^h (J + 4,); MHDPA: the head's output (N, F)).
    Other heads are untouched. Enter before :func:`capture_heads` so the capture sees it."""
    with adapter_of(model).ablate_heads(replacement):
        yield


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
    mean = adapter_of(model).head_mean(model, obs, batch)  # (H, ...)
    return {h: mean[h] for h in range(mean.shape[0])}
