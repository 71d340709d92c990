"""An :class:`EpisodeTrace` from a saved :class:`~neurosym.record.recording.Recording`.

The recording's attention tables keep only the strongest cells (PrediNet: the
argmax of a1 and a2; MHDPA: the top keys of each non-background query), so the
trace marks every other weight as NaN.

The grid of a recorded state is rebuilt from the ``positions`` table over the
environment's layout after ``reset(seed=episode seed)`` (how the recorder plays
episode k); when that layout does not agree with the recorded objects (or the
environment cannot be built), the cells nobody recorded are drawn as ``empty``.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any

import numpy as np
import pandas as pd

from neurosym.agent.networks.adapters import adapter_class, module_names
from neurosym.errors import ConfigError
from neurosym.record.recording import Recording
from neurosym.viz.trace import DOOR_COLUMNS, OBJECT_COLUMNS, POSITION_COMPONENTS, EpisodeTrace


def trace_from_recording(rec: Recording, episode: int | None = None) -> EpisodeTrace:
    """The trace of one recorded episode (default: the first one in the recording)."""
    episodes = rec.episodes
    if episodes.empty:
        raise ConfigError("the recording holds no episodes")
    known = sorted(int(e) for e in episodes["episode"])
    if episode is None:
        episode = known[0]
    if episode not in known:
        raise ConfigError(
            f"--episode {episode} is not in the recording: it has episodes {_list(known)}"
        )
    meta = dict(rec.meta)
    module = str(meta.get("module", ""))
    if module not in module_names():
        raise ConfigError(
            f"the recording names an unknown module {module!r}: expected "
            f"{' or '.join(module_names())}"
        )
    adapter = adapter_class(module)
    row = episodes.loc[episodes["episode"] == episode].iloc[0]
    steps_tab = _episode_rows(rec.steps, episode).sort_values("t")
    n_steps = int(row["steps"])
    if len(steps_tab) != n_steps:
        raise ConfigError(
            f"the recording is inconsistent: episode {episode} has {n_steps} steps "
            f"but {len(steps_tab)} step rows"
        )
    seed = None if pd.isna(row.get("seed", np.nan)) else int(row["seed"])
    positions = _episode_rows(rec.positions, episode)
    attends = _episode_rows(rec.attends, episode)
    attention = _episode_rows(rec.attention, episode)
    r_vectors = _episode_rows(rec.r_vectors, episode)
    env_name = str(meta.get("env", ""))
    base = _reset_layout(env_name, seed, meta.get("env_kwargs") or {})
    shape = base.shape if base is not None else _shape_from_tables(positions, attends, attention)
    grids = _grids_from_positions(positions, n_steps, shape, base)
    heads = _head_numbers(meta, attends, attention, r_vectors)
    relations = int(meta.get("relations", 0) or 0) if adapter.has("relations") else 0
    common = dict(
        checkpoint=str(meta.get("checkpoint", "")),
        env=env_name,
        module=module,
        episode=int(episode),
        seed=seed,
        grids=grids,
        actions=tuple(str(a) for a in steps_tab["action"]),
        rewards=steps_tab["reward"].to_numpy(dtype=float),
        events=_episode_rows(rec.events, episode)[["t", "event"]].reset_index(drop=True),
        outcome=None if pd.isna(row.get("outcome")) else str(row["outcome"]),
        heads=heads,
        relations=relations,
        complete=False,
        objects=positions[OBJECT_COLUMNS].reset_index(drop=True),
        **_minigrid_state(rec, episode, positions, n_steps),
    )
    if adapter.has("attends"):
        a1, a2 = _sparse_argument_maps(attends, n_steps, heads, shape)
        r = _r_vector_array(r_vectors, n_steps, heads, relations)
        return EpisodeTrace(**common, attention1=a1, attention2=a2, r_vectors=r)
    lazy = _RecordedAttention(attention, n_steps, heads, shape)
    focus = _recorded_focus(attention, grids, heads, shape, n_steps)
    return EpisodeTrace(**common, mhdpa=lazy, mhdpa_focus=focus)


def _minigrid_state(
    rec: Recording, episode: int, positions: pd.DataFrame, n_steps: int
) -> dict[str, Any]:
    """Minigrid's agent direction per state and its doors' states with their cells (nothing for
    the other envs, whose recordings have no facing or door rows)."""
    facing = _episode_rows(rec.facing, episode).sort_values("t")
    out: dict[str, Any] = {}
    if len(facing) == n_steps + 1:
        out["facing"] = tuple(str(d) for d in facing["direction"])
    doors = _episode_rows(rec.doors, episode)
    if not doors.empty:
        cells = positions[["t", "object", "row", "col"]].rename(columns={"object": "id"})
        placed = doors[["t", "id", "state"]].merge(cells, on=["t", "id"])
        out["doors"] = placed[DOOR_COLUMNS].astype({"state": str}).reset_index(drop=True)
    return out


def _episode_rows(table: pd.DataFrame, episode: int) -> pd.DataFrame:
    return table.loc[table["episode"] == episode]


def _list(values: list[int]) -> str:
    if len(values) > 8:
        return (
            f"{values[0]}..{values[-1]}"
            if values == list(range(values[0], values[-1] + 1))
            else (", ".join(map(str, values[:8])) + ", ...")
        )
    return ", ".join(map(str, values))


def _reset_layout(env_name: str, seed: int | None, kwargs: dict[str, Any]) -> np.ndarray | None:
    """(H, W) entity names right after ``reset(seed)``, or None when the env cannot be built.

    Env options come from ``meta["env_kwargs"]`` when the recording has them
    (a checkpoint trained on a custom map); without them the registered env is used.
    """
    import gymnasium

    from neurosym.envs import make
    from neurosym.errors import NeurosymError

    try:
        env = make(env_name, **kwargs)
        env.reset(seed=seed)
    except (NeurosymError, gymnasium.error.Error, TypeError, OSError):
        return None  # an env of another version, a map file that moved: draw without terrain
    base = env.unwrapped
    grid = np.asarray(base.entity_names, dtype=object)[np.asarray(base.entity_grid())]
    env.close()
    return grid


def _shape_from_tables(*tables: pd.DataFrame) -> tuple[int, int]:
    rows, cols = 0, 0
    for tab in tables:
        for rcol, ccol in (("row", "col"), ("query_row", "query_col"), ("key_row", "key_col")):
            if not tab.empty and rcol in tab:
                rows = max(rows, int(tab[rcol].max()) + 1)
                cols = max(cols, int(tab[ccol].max()) + 1)
    if rows == 0:
        raise ConfigError("cannot tell the grid's size: the recording has no positions")
    return rows, cols


def _grids_from_positions(
    positions: pd.DataFrame, n_steps: int, shape: tuple[int, int], base: np.ndarray | None
) -> np.ndarray:
    """(S+1, H, W) entity names: the reset layout with the recorded objects painted per state."""
    h, w = shape
    grids = np.full((n_steps + 1, h, w), "empty", dtype=object)
    if positions.empty:
        if base is not None:
            grids[:] = base
        return grids
    t = positions["t"].to_numpy(dtype=np.int64)
    r = positions["row"].to_numpy(dtype=np.int64)
    c = positions["col"].to_numpy(dtype=np.int64)
    kind = positions["type"].astype(str).to_numpy(dtype=object)
    inside = (t >= 0) & (t <= n_steps) & (r >= 0) & (r < h) & (c >= 0) & (c < w)
    t, r, c, kind = t[inside], r[inside], c[inside], kind[inside]
    agent = kind == "agent"
    if base is not None and _layout_agrees(base, t, r, c, kind):
        layout = base.copy()
        # recorded objects (a sword that gets picked up) are painted per state below;
        # the agent's cells keep what lies under it (mountains it crosses)
        layout[r[~agent], c[~agent]] = "empty"
        layout[layout == "agent"] = "empty"
        grids[:] = layout
    grids[t[~agent], r[~agent], c[~agent]] = kind[~agent]
    grids[t[agent], r[agent], c[agent]] = "agent"  # the agent's own cell is agent
    return grids


def _layout_agrees(
    base: np.ndarray, t: np.ndarray, r: np.ndarray, c: np.ndarray, kind: np.ndarray
) -> bool:
    first = (t == 0) & (kind != "agent")
    return bool(np.all(base[r[first], c[first]] == kind[first]))


def _head_numbers(meta: dict, *tables: pd.DataFrame) -> tuple[int, ...]:
    found: set[int] = set()
    for tab in tables:
        if not tab.empty and "head" in tab:
            found.update(int(h) for h in tab["head"].unique())
    n = int(meta.get("heads", 0) or 0)
    if found:
        lo = min(found)
        return tuple(range(lo, lo + max(n, max(found) - lo + 1)))
    return tuple(range(n))


def _cells(rows: pd.Series, cols: pd.Series, width: int) -> np.ndarray:
    return rows.to_numpy(dtype=np.int64) * width + cols.to_numpy(dtype=np.int64)


def _head_positions(heads: tuple[int, ...], values: pd.Series) -> np.ndarray:
    lookup = np.full(max(heads) + 1, -1, dtype=np.int64)
    lookup[list(heads)] = np.arange(len(heads))
    return lookup[values.to_numpy(dtype=np.int64)]


def _sparse_argument_maps(
    attends: pd.DataFrame, n_steps: int, heads: tuple[int, ...], shape: tuple[int, int]
) -> tuple[np.ndarray, np.ndarray]:
    """(S, heads, N) a1 and a2 with the recorded strongest cells filled and NaN elsewhere."""
    n = shape[0] * shape[1]
    maps = np.full((2, n_steps, len(heads), n), np.nan)
    if not attends.empty:
        tab = attends.loc[attends["t"] < n_steps]
        arg = tab["arg"].to_numpy(dtype=np.int64) - 1  # arg 1 / 2 -> 0 / 1
        maps[
            arg,
            tab["t"].to_numpy(dtype=np.int64),
            _head_positions(heads, tab["head"]),
            _cells(tab["row"], tab["col"], shape[1]),
        ] = tab["weight"].to_numpy(dtype=float)
    return maps[0], maps[1]


def _r_vector_array(
    r_vectors: pd.DataFrame, n_steps: int, heads: tuple[int, ...], relations: int
) -> np.ndarray:
    """(S, heads, J + 4) R vectors; NaN where a component is missing."""
    out = np.full((n_steps, len(heads), relations + POSITION_COMPONENTS), np.nan)
    if r_vectors.empty:
        return out
    tab = r_vectors.loc[r_vectors["t"] < n_steps]
    j = tab["j"].to_numpy(dtype=np.int64)
    j = j - j.min() if len(j) else j  # components are numbered from 0 or 1: keep their order
    keep = j < out.shape[2]
    out[
        tab["t"].to_numpy(dtype=np.int64)[keep], _head_positions(heads, tab["head"])[keep], j[keep]
    ] = tab["value"].to_numpy(dtype=float)[keep]
    return out


class _RecordedAttention(Mapping[int, np.ndarray]):
    """State t -> (heads, N, N) MHDPA weights from the recording, built when first asked for.

    Dense maps of every state of a Box-World episode would take hundreds of MB,
    and a plot needs one or two states.
    """

    def __init__(
        self, table: pd.DataFrame, n_steps: int, heads: tuple[int, ...], shape: tuple[int, int]
    ) -> None:
        self._by_t = {int(t): rows for t, rows in table.groupby("t")} if not table.empty else {}
        self._n_steps = n_steps
        self._heads = heads
        self._shape = shape

    def __getitem__(self, t: int) -> np.ndarray:
        if not 0 <= t < self._n_steps:
            raise KeyError(t)
        n = self._shape[0] * self._shape[1]
        out = np.full((len(self._heads), n, n), np.nan)
        rows = self._by_t.get(int(t))
        if rows is not None:
            w = self._shape[1]
            out[
                _head_positions(self._heads, rows["head"]),
                _cells(rows["query_row"], rows["query_col"], w),
                _cells(rows["key_row"], rows["key_col"], w),
            ] = rows["weight"].to_numpy(dtype=float)
        return out

    def __iter__(self) -> Iterator[int]:
        return iter(range(self._n_steps))

    def __len__(self) -> int:
        return self._n_steps


def _recorded_focus(
    attention: pd.DataFrame,
    grids: np.ndarray,
    heads: tuple[int, ...],
    shape: tuple[int, int],
    n_steps: int,
) -> np.ndarray:
    """(S, heads) key cell with the largest recorded weight for the agent's cell as query; -1 if none."""
    focus = np.full((n_steps, len(heads)), -1, dtype=np.int64)
    if attention.empty:
        return focus
    w = shape[1]
    flat = (grids[:n_steps] == "agent").reshape(n_steps, -1)
    agent_cell = np.where(flat.any(axis=1), flat.argmax(axis=1), -1)  # (S,)
    tab = attention.loc[attention["t"] < n_steps]
    t = tab["t"].to_numpy(dtype=np.int64)
    mine = _cells(tab["query_row"], tab["query_col"], w) == agent_cell[t]
    tab = tab.loc[mine].sort_values(["t", "head", "weight"], kind="stable")
    last = tab.groupby(["t", "head"]).tail(1)  # strongest key per (t, head)
    focus[last["t"].to_numpy(dtype=np.int64), _head_positions(heads, last["head"])] = _cells(
        last["key_row"], last["key_col"], w
    )
    return focus
