"""Building an :class:`EpisodeTrace` from a saved recording or by playing a checkpoint.

A recording (``neurosym extract`` / :func:`neurosym.record`) is read table by
table; its attention tables keep only the strongest cells, so the trace marks
every other weight as NaN. A checkpoint is played greedily from a seeded
reset with introspection on, which gives the full maps.

The grid of a recorded state is rebuilt from the ``positions`` table over the
environment's layout after ``reset(seed=episode seed)``; when that layout does
not agree with the recorded objects (or the environment cannot be built), the
cells nobody recorded are drawn as ``empty``.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from neurosym.errors import ConfigError
from neurosym.export.recording import Recording
from neurosym.viz.trace import OBJECT_COLUMNS, EpisodeTrace, require_module

POSITION_COMPONENTS = 4
"""R^h ends with the (row, col) of E1 and of E2"""


# ---------------------------------------------------------------------------
# from a recording


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
    if module not in ("predinet", "mhdpa"):
        raise ConfigError(
            f"the recording names an unknown module {module!r}: expected predinet or mhdpa"
        )
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
    base = _reset_layout(env_name, seed)
    shape = base.shape if base is not None else _shape_from_tables(positions, attends, attention)
    grids = _grids_from_positions(positions, n_steps, shape, base)
    heads = _head_numbers(meta, attends, attention, r_vectors)
    relations = int(meta.get("relations", 0) or 0) if module == "predinet" else 0
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
    )
    if module == "predinet":
        a1, a2 = _sparse_argument_maps(attends, n_steps, heads, shape)
        r = _r_vector_array(r_vectors, n_steps, heads, relations)
        return EpisodeTrace(**common, attention1=a1, attention2=a2, r_vectors=r)
    lazy = _RecordedAttention(attention, n_steps, heads, shape)
    focus = _recorded_focus(attention, grids, heads, shape, n_steps)
    return EpisodeTrace(**common, mhdpa=lazy, mhdpa_focus=focus)


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


def _reset_layout(env_name: str, seed: int | None) -> np.ndarray | None:
    """(H, W) entity names right after ``reset(seed)``, or None when the env cannot be built."""
    try:
        from neurosym.envs import make
    except ImportError:
        return None
    try:
        env = make(env_name)
        env.reset(seed=seed)
        base = env.unwrapped
        names = np.asarray(base.entity_names, dtype=object)
        grid = names[np.asarray(base.entity_grid())]
        env.close()
        return grid
    except Exception:  # an env name from another version, a missing map: draw without a layout
        return None


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
    if base is not None and _layout_agrees(base, t, r, c, kind):
        layout = base.copy()
        layout[r, c] = "empty"  # cells of recorded objects are painted per state below
        layout[layout == "agent"] = "empty"
        grids[:] = layout
    agent = kind == "agent"
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


# ---------------------------------------------------------------------------
# from a checkpoint


def trace_from_agent(
    agent: Any,
    env: Any = None,
    *,
    seed: int = 0,
    max_steps: int | None = None,
    keep_attention: set[int] | None = None,
    greedy: bool = True,
) -> EpisodeTrace:
    """Play one episode from ``reset(seed)`` with introspection and return its trace.

    ``env`` is a short name, a registered id or a gymnasium env (default: the
    checkpoint's own environment). ``max_steps`` stops early (a picture of step
    t needs only t + 1 steps). MHDPA maps are (heads, N, N) per state, so only
    the states in ``keep_attention`` keep them (default: all). The model acts
    on one torch thread: at batch size 1 more threads only cost time.
    """
    from neurosym.envs import make

    env_obj, env_name, owned = _open_env(agent, env, make)
    try:
        with _one_torch_thread():
            play = _Play(agent, env_obj, env_name, seed, greedy, keep_attention)
            play.run(max_steps if max_steps is not None else _step_limit(env_obj))
    finally:
        if owned:
            env_obj.close()
    return play.trace()


class _Play:
    """One greedy (or seeded sampled) episode, keeping per step only what the plots need."""

    def __init__(
        self, agent: Any, env: Any, env_name: str, seed: int, greedy: bool, keep: set[int] | None
    ) -> None:
        import torch

        self.agent, self.env, self.env_name, self.seed = agent, env, env_name, seed
        self.greedy, self.keep = greedy, keep
        self.module = str(agent.config.module)
        self.generator = None if greedy else torch.Generator().manual_seed(seed)
        self.names = np.asarray(env.unwrapped.entity_names, dtype=object)
        self.grids: list[np.ndarray] = []
        self.actions: list[str] = []
        self.rewards: list[float] = []
        self.events: list[tuple[int, str]] = []
        self.outcome: str | None = None
        self.predinet: list[Any] = []  # per step: the numpy introspection record (small)
        self.attention: dict[int, np.ndarray] = {}  # MHDPA, kept steps only
        self.focus: list[np.ndarray] = []  # MHDPA, per step (heads,)
        self.object_rows: list[tuple[int, str, str, int, int]] = []

    def _grid(self) -> np.ndarray:
        return self.names[np.asarray(self.env.unwrapped.entity_grid())]

    def run(self, limit: int) -> None:
        obs, info = self.env.reset(seed=self.seed)
        expected = tuple(self.agent.config.obs_shape)
        if tuple(obs.shape) != expected:
            raise ConfigError(
                f"{Path(str(self.agent.path)).name} expects observations of shape {expected}, "
                f"but {self.env_name} gives {tuple(obs.shape)}: pick the environment it was trained on"
            )
        action_names = _action_names()
        self.grids.append(self._grid())
        self._objects(0, info)
        for t in range(limit):
            acts, intro = self.agent.act(
                obs[None], greedy=self.greedy, introspect=True, generator=self.generator
            )
            self._keep(t, intro)
            action = int(np.asarray(acts).reshape(-1)[0])
            obs, reward, terminated, truncated, info = self.env.step(action)
            self.actions.append(action_names[action] if action < len(action_names) else str(action))
            self.rewards.append(float(reward))
            self.events.extend((t, str(e)) for e in info.get("events", ()))
            self.grids.append(self._grid())
            self._objects(t + 1, info)
            if terminated or truncated:
                self.outcome = info.get("outcome") or ("timeout" if truncated else None)
                break

    def _objects(self, t: int, info: dict[str, Any]) -> None:
        self.object_rows.extend(
            (t, str(i), str(k), int(r), int(c)) for i, k, r, c in info.get("objects", ())
        )

    def _keep(self, t: int, intro: Any) -> None:
        if self.module == "predinet":
            self.predinet.append(intro)
            return
        att = _numpy(intro.attention)[0]  # (heads, N, N) query x key
        agent = (self.grids[t] == "agent").ravel()
        heads = att.shape[0]
        self.focus.append(
            att[:, agent.argmax(), :].argmax(axis=1) if agent.any() else np.full(heads, -1)
        )
        if self.keep is None or t in self.keep:
            self.attention[t] = att

    def trace(self) -> EpisodeTrace:
        config = self.agent.config
        n_steps = len(self.actions)
        heads = tuple(range(int(config.heads)))
        common = dict(
            checkpoint=str(self.agent.path or ""),
            env=self.env_name,
            module=self.module,
            episode=0,
            seed=self.seed,
            grids=np.stack(self.grids),
            actions=tuple(self.actions),
            rewards=np.asarray(self.rewards, dtype=float),
            events=pd.DataFrame(self.events, columns=["t", "event"]).astype(
                {"t": int, "event": str}
            ),
            outcome=None if self.outcome is None else str(self.outcome),
            heads=heads,
            complete=True,
            objects=pd.DataFrame(self.object_rows, columns=OBJECT_COLUMNS),
        )
        if self.module == "predinet":
            n, h, j = config.n_entities, len(heads), int(config.relations)
            field_of = {name: _stack(self.predinet, name) for name in _PREDINET_FIELDS}
            a1 = field_of["attention1"] if n_steps else np.zeros((0, h, n))  # (S, heads, N)
            a2 = field_of["attention2"] if n_steps else np.zeros((0, h, n))
            r = (
                np.concatenate(
                    [field_of[k] for k in ("relations", "positions1", "positions2")], axis=2
                )
                if n_steps
                else np.zeros((0, h, j + POSITION_COMPONENTS))
            )  # (S, heads, J + 4)
            return EpisodeTrace(**common, relations=j, attention1=a1, attention2=a2, r_vectors=r)
        focus = np.stack(self.focus) if self.focus else np.zeros((0, len(heads)), dtype=np.int64)
        return EpisodeTrace(
            **common, relations=0, mhdpa=self.attention, mhdpa_focus=focus.astype(np.int64)
        )


_PREDINET_FIELDS = ("attention1", "attention2", "relations", "positions1", "positions2")


@contextmanager
def _one_torch_thread() -> Iterator[None]:
    import torch

    before = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        yield
    finally:
        torch.set_num_threads(before)


def _open_env(agent: Any, env: Any, make: Any) -> tuple[Any, str, bool]:
    """(env, short name, whether we made it): a fresh env unless the caller passed one.

    A named env other than the checkpoint's is made without the checkpoint's
    env options (they belong to the other env); the observation shape is checked.
    """
    from neurosym.envs import canonical_name

    if env is None or isinstance(env, str):
        name = env or agent.env_name
        short = canonical_name(name)
        same = short == canonical_name(agent.env_name)
        return make(short, **(dict(agent.env_kwargs or {}) if same else {})), short, True
    spec = getattr(env, "spec", None)
    name = canonical_name(spec.id) if spec is not None else type(env.unwrapped).__name__
    return env, name, False


def _step_limit(env: Any) -> int:
    spec = getattr(env, "spec", None)
    limit = getattr(spec, "max_episode_steps", None) or getattr(env.unwrapped, "max_steps", None)
    return int(limit) if limit else 1000


def _action_names() -> tuple[str, ...]:
    try:
        from neurosym.envs import ACTION_NAMES
    except ImportError:
        return ("up", "right", "down", "left")
    return tuple(ACTION_NAMES)


def _numpy(x: Any) -> np.ndarray:
    if hasattr(x, "detach"):
        x = x.detach().cpu().numpy()
    return np.asarray(x, dtype=np.float64)


def _stack(intros: list[Any], name: str) -> np.ndarray:
    """(S, ...) one field of per-step introspection records (each with batch axis 1)."""
    if not intros:
        return np.zeros(0)
    return np.concatenate([_numpy(getattr(i, name)) for i in intros], axis=0)


# ---------------------------------------------------------------------------
# either


def require_source_module(source: Any, module: str, what: str) -> None:
    """Refuse early (before playing an episode) a plot that needs the other module."""
    if isinstance(source, EpisodeTrace):
        found, name = source.module, source.checkpoint
    elif isinstance(source, Recording):
        found, name = str(source.meta.get("module", "")), str(source.meta.get("checkpoint", ""))
    elif hasattr(source, "config"):
        found, name = str(source.config.module), str(getattr(source, "path", ""))
    else:
        return  # load_trace words the error for anything else
    require_module(found, module, what, name)


def load_trace(
    source: Any,
    env: Any = None,
    *,
    episode: int | None = None,
    seed: int = 0,
    max_steps: int | None = None,
    keep_attention: set[int] | None = None,
) -> EpisodeTrace:
    """A trace from an EpisodeTrace (returned as is), a Recording, or an Agent (+ env)."""
    if isinstance(source, EpisodeTrace):
        return source
    if isinstance(source, Recording):
        return trace_from_recording(source, episode)
    if hasattr(source, "act") and hasattr(source, "config"):
        return trace_from_agent(
            source, env, seed=seed, max_steps=max_steps, keep_attention=keep_attention
        )
    raise ConfigError(
        f"cannot plot a {type(source).__name__}: pass a Recording, an Agent (load_agent) or an EpisodeTrace"
    )
