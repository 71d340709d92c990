"""Record an agent's episodes with introspection into a :class:`Recording`.

The environments run batched (``make_batched``) and the model acts on the whole
batch at once with ``introspect=True``. Per step the recorder keeps a few numpy
arrays (which sub-environments are live, the argmax cells of each head, the
relation values); the tables are built from them with array operations once,
at the end.

Seeding: episode k is played from ``reset(seed=seed + k)``, whichever
sub-environment plays it (episodes run in waves of one reset of the whole
batch), so ``make(env).reset(seed=episodes.seed[k])`` followed by the recorded
actions replays episode k exactly, and greedy recordings do not depend on the
batch size. With ``greedy=False`` actions are
sampled from a torch generator seeded with ``seed``; the result then depends
on the batch size too (the draws are shared out over the batch).
"""

from __future__ import annotations

import datetime as _dt
from collections.abc import Callable
from itertools import chain
from typing import Any

import numpy as np
import pandas as pd

from neurosym.agent.networks.adapters import adapter_class
from neurosym.agent.waves import Wave, run_waves
from neurosym.errors import ConfigError
from neurosym.play import live
from neurosym.record.recording import Recording
from neurosym.seeds import check_seed

DEFAULT_BATCH = 64
"""Sub-environments stepped together (fewer when fewer episodes are asked for)."""

ACTION_SOURCES = ("agent", "random")
"""who chooses the recorded actions: the agent, or a uniform random draw (the network still runs)"""


def random_actions(episode_seeds: np.ndarray, t: int, count: int = 4) -> np.ndarray:
    """Uniform actions 0..count-1 for step ``t`` of the episodes reset with ``episode_seeds``.

    A SplitMix64 hash of (episode seed, t): the draw depends on nothing but the
    episode and the step, so a recording is the same at any batch size and
    any episode can be replayed alone.
    """
    with np.errstate(over="ignore"):
        x = episode_seeds.astype(np.uint64) * np.uint64(0x9E3779B97F4A7C15) + np.uint64(t)
        x ^= np.uint64(0xD1B54A32D192ED03)
        for shift, mult in ((30, 0xBF58476D1CE4E5B9), (27, 0x94D049BB133111EB)):
            x = (x ^ (x >> np.uint64(shift))) * np.uint64(mult)
        x ^= x >> np.uint64(31)
    return (x % np.uint64(count)).astype(np.int64)


def _action_count(venv: Any) -> int:
    """The batched env's number of actions (4 in RGW and Box-World, 7 in Minigrid)."""
    return int(getattr(getattr(venv, "single_action_space", None), "n", 4))


def _meta(
    agent: Any, env_name: str, seed: int, greedy: bool, env_kwargs: dict[str, Any]
) -> dict[str, Any]:
    from neurosym import __version__

    config = agent.config
    adapter = adapter_class(config.module)
    return {
        "checkpoint": str(getattr(agent, "path", "") or ""),
        "env": env_name,
        # Options the env was built with (a custom map, obs mode): plots redraw the grid from them.
        "env_kwargs": dict(env_kwargs),
        "module": config.module,
        "heads": int(config.heads),
        "relations": adapter.relation_count(config),
        "seed": int(seed),
        "greedy": bool(greedy),
        "created": _dt.datetime.now(_dt.UTC).replace(microsecond=0).isoformat(),
        "version": __version__,
    }


class _Columns:
    """Column chunks appended per step and concatenated once."""

    def __init__(self) -> None:
        self.chunks: dict[str, list[np.ndarray]] = {}

    def add(self, **cols: np.ndarray) -> None:
        for name, arr in cols.items():
            self.chunks.setdefault(name, []).append(np.asarray(arr))

    def get(self, name: str) -> np.ndarray:
        parts = self.chunks.get(name, [])
        return np.concatenate(parts) if parts else np.zeros(0)

    def sorted_by(self, key: str) -> dict[str, np.ndarray]:
        """Every column, rows ordered by ``key`` (stable: rows were appended in time order)."""
        cols = {name: self.get(name) for name in self.chunks}
        if key not in cols:
            return cols
        order = np.argsort(cols[key], kind="stable")
        return {name: col[order] for name, col in cols.items()}


class _SymbolicColumns:
    """The symbolic side of the episodes (positions, holding, events), from decoded infos.

    Per state it keeps one reference to the decoded tuples; the columns are
    built at the end by chaining them (no Python object per table row until then).
    """

    def __init__(self) -> None:
        self.keys: list[tuple[int, int]] = []  # (episode, t) of each state
        self.objects: list[tuple] = []  # (id, type, row, col) rows of each state
        self.held: list[tuple] = []  # held items of each state
        self.event_keys: list[tuple[int, int]] = []  # (episode, t) of each transition
        self.events: list[tuple] = []  # event texts of each transition
        self.terrain: list[tuple[int, str, int, int]] = []  # (episode, type, row, col)
        self.grids: list[tuple[int, int, int]] = []  # (episode, rows, cols)
        self.facing: list[tuple[int, int, str]] = []  # (episode, t, direction): Minigrid
        self.doors: list[tuple[int, int, str, str]] = []  # (episode, t, id, state): Minigrid
        self.missions: list[tuple[int, str]] = []  # (episode, text): Minigrid

    def map(self, episode: int, grid: np.ndarray, names: np.ndarray, info: dict[str, Any]) -> None:
        """Episode's map size and terrain: its (H, W) entity codes after the reset
        (:func:`neurosym.play.live.episode_facts`, what the Prolog agent asserts).

        Terrain is every cell that is neither empty, nor the agent, nor one of
        the named objects of ``info["objects"]`` (RGW's walls and mountains,
        Box-World's walls). It does not change within an episode.
        """
        facts = live.episode_facts(info, grid, names)
        self.grids.append((episode, facts.rows, facts.cols))
        self.terrain.extend((episode, *row) for row in facts.terrain)
        if "mission" in info:
            self.missions.append((episode, str(info["mission"])))

    def state(self, episode: int, t: int, info: dict[str, Any]) -> None:
        """Positions and held items of state t (the agent first, then the map's objects)."""
        self.keys.append((episode, t))
        self.objects.append(live.state_objects(info))
        self.held.append(tuple(info["holding"]))
        minigrid = live.minigrid_rows(info)  # Minigrid's agent direction and door states
        if minigrid is not None:
            self.facing.append((episode, t, minigrid[0]))
            self.doors.extend((episode, t, i, s) for i, s in minigrid[1])

    def transition(self, episode: int, t: int, info: dict[str, Any]) -> None:
        """Events of the step taken in state t."""
        self.event_keys.append((episode, t))
        self.events.append(tuple(info["events"]))

    @staticmethod
    def _expand(
        keys: list[tuple[int, int]], groups: list[tuple]
    ) -> tuple[np.ndarray, np.ndarray, list]:
        """(episode, t) repeated per row of each group, and the rows chained."""
        lens = np.fromiter(map(len, groups), dtype=np.int64, count=len(groups))
        key = np.array(keys, dtype=np.int64).reshape(-1, 2)
        return (
            np.repeat(key[:, 0], lens),
            np.repeat(key[:, 1], lens),
            list(chain.from_iterable(groups)),
        )

    def minigrid_tables(self) -> dict[str, pd.DataFrame]:
        """facing, doors (ordered by episode, then t) and missions (by episode): Minigrid's state."""
        return {
            "facing": _by_episode(pd.DataFrame(self.facing, columns=["episode", "t", "direction"])),
            "doors": _by_episode(
                pd.DataFrame(self.doors, columns=["episode", "t", "id", "state"])
            ),
            "missions": _by_episode(pd.DataFrame(self.missions, columns=["episode", "text"])),
        }

    def map_tables(self) -> tuple[pd.DataFrame, pd.DataFrame]:
        """terrain (row-major per episode) and grids, ordered by episode."""
        terrain = pd.DataFrame(self.terrain, columns=["episode", "type", "row", "col"])
        grids = pd.DataFrame(self.grids, columns=["episode", "rows", "cols"])
        return _by_episode(terrain), _by_episode(grids)

    def tables(self) -> tuple[pd.DataFrame, pd.DataFrame, pd.DataFrame]:
        """positions, holding and events, ordered by episode then t."""
        ep, t, rows = self._expand(self.keys, self.objects)
        ids, types, r, c = (
            (list(col) for col in zip(*rows, strict=True)) if rows else ([], [], [], [])
        )
        positions = pd.DataFrame(
            {
                "episode": ep,
                "t": t,
                "object": ids,
                "type": types,
                "row": np.asarray(r, np.int64),
                "col": np.asarray(c, np.int64),
            }
        )
        ep, t, items = self._expand(self.keys, self.held)
        holding = pd.DataFrame({"episode": ep, "t": t, "item": items})
        ep, t, events = self._expand(self.event_keys, self.events)
        events_df = pd.DataFrame({"episode": ep, "t": t, "event": events})
        return _by_episode(positions), _by_episode(holding), _by_episode(events_df)


def _resolve_env(
    agent: Any, env: Any, env_kwargs: dict[str, Any] | None = None
) -> tuple[str, dict[str, Any]]:
    """(short name, options) of the env to record on; any env of the agent's family and shape."""
    from neurosym.agent.agent import env_for

    if env is not None and not isinstance(env, str):
        raise ConfigError(
            f"env must be an environment name such as {agent.env_name!r}, got {type(env).__name__}"
        )
    return env_for(agent, env, env_kwargs)


def record(
    agent: Any,
    env: str | None = None,
    episodes: int = 20,
    seed: int = 0,
    greedy: bool = True,
    batch: int | None = None,
    *,
    progress: bool = False,
    top_keys: int = 1,
    max_steps: int = 100_000,
    threads: int | None = 1,
    env_kwargs: dict[str, Any] | None = None,
    actions: str = "agent",
) -> Recording:
    """Play ``episodes`` episodes of ``agent`` on ``env`` (default: the env it was trained on).

    ``actions="random"`` plays uniformly random actions instead of the agent's
    (drawn by :func:`random_actions` from each episode's seed and step, so
    reproducible); the network still runs on every state, so its introspection
    is recorded as usual. ``meta["actions"]`` says which.

    ``env`` may be any env of the agent's family with its observation shape
    (an rgw-random agent on rgw2, say); ``env_kwargs`` adds env options such
    as ``{"map": "my_map.txt"}``.

    Returns a :class:`Recording` with the trace (episodes, steps, positions,
    holding, events) and what the relational module showed at every state the
    agent acted in: PrediNet's attended cells, relation values and R vectors,
    or MHDPA's ``top_keys`` strongest keys for every query cell that is not
    empty or wall. ``progress`` shows a rich progress bar on stderr.
    ``max_steps`` guards against an env without a time limit.

    ``threads``: torch intra-op threads while recording (None: leave torch's
    setting). The default 1 is deliberate: the model runs one modest batch
    between numpy env steps, and torch's idle worker threads keep spinning
    against the main thread; on 2 shared cores one thread recorded about 10x
    faster (11k vs 1k steps/s, bench/extract.py) at nearly the same model speed.
    """
    from neurosym.envs import make_batched

    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
        raise ConfigError(f"episodes must be a positive integer, got {episodes!r}")
    check_seed(seed, episodes, name="seed")
    if batch is not None and (isinstance(batch, bool) or not isinstance(batch, int) or batch < 1):
        raise ConfigError(f"batch must be a positive integer, got {batch!r}")
    if top_keys < 1:
        raise ConfigError(f"top_keys must be at least 1, got {top_keys}")
    if actions not in ACTION_SOURCES:
        raise ConfigError(f"actions must be one of {', '.join(ACTION_SOURCES)}, got {actions!r}")
    name, kwargs = _resolve_env(agent, env, env_kwargs)
    waves = -(-episodes // (batch or DEFAULT_BATCH))
    n = -(-episodes // waves)  # equal waves: 100 episodes at batch 64 run as 2 x 50
    if threads is not None and (
        isinstance(threads, bool) or not isinstance(threads, int) or threads < 1
    ):
        raise ConfigError(f"threads must be a positive integer or None, got {threads!r}")
    import torch

    saved_threads = torch.get_num_threads()
    venv = make_batched(name, n, seed=seed, **kwargs)
    try:
        if threads is not None:
            torch.set_num_threads(threads)
        from neurosym.progress import Stages

        with Stages(progress) as stages:
            advance = stages.stage("recording", episodes)
            recorder = _Recorder(agent, venv, episodes, seed, greedy, top_keys, max_steps, advance)
            recorder.random = actions == "random"
            rec = recorder.run()
            rec.optimal = optimal_table(name, venv, seed, episodes)
    finally:
        torch.set_num_threads(saved_threads)
        venv.close()
    rec.meta.update(_meta(agent, name, seed, greedy, kwargs))
    rec.meta["actions"] = actions
    return rec


def optimal_table(name: str, venv: Any, seed: int, episodes: int) -> pd.DataFrame:
    """The recording's ``optimal`` table: episode k's level (``reset(seed=seed + k)``) and the
    key objects its optimal route visits, in order, as Prolog list text
    (:func:`neurosym.envs.rgw_solver.optimal_visit_orders`, which replays the levels on
    ``venv``). RGW only; a level without an optimal return has no row.
    """
    from neurosym.envs import env_family
    from neurosym.envs.rgw_solver import optimal_visit_orders
    from neurosym.record.recording import conform

    if env_family(name) != "rgw":
        return conform("optimal", None)
    orders = optimal_visit_orders(venv, [seed + k for k in range(episodes)])
    rows = [(k, "[" + ",".join(o) + "]") for k, o in enumerate(orders) if o is not None]
    return conform("optimal", pd.DataFrame(rows, columns=["episode", "order"]))


def _by_episode(df: pd.DataFrame) -> pd.DataFrame:
    """Rows ordered by episode, then time: rows were appended in time order, so a stable sort suffices."""
    order = np.argsort(df["episode"].to_numpy(), kind="stable")
    return df.take(order).reset_index(drop=True)


class _Recorder:
    """One recording run: the stepping loop and the table building."""

    def __init__(
        self,
        agent: Any,
        venv: Any,
        episodes: int,
        seed: int,
        greedy: bool,
        top_keys: int,
        max_steps: int,
        advance: Callable[[int], None],
    ) -> None:
        self.agent, self.venv = agent, venv
        self.episodes, self.seed, self.greedy = episodes, seed, greedy
        self.top_keys, self.max_steps, self.advance = top_keys, max_steps, advance
        self.n = venv.num_envs
        self.names = np.asarray(venv.entity_names, dtype=object)
        self.adapter = adapter_class(agent.config.module)
        self.trace = _SymbolicColumns()
        self.model = _Columns()  # model outputs per (episode, t)
        self.step_cols = _Columns()  # steps table
        self.ep_rows: list[tuple[int, int, float, str, int]] = []
        self._grid = np.zeros((0, 0), dtype=np.int64)  # entity codes before the step being played
        self._intro: Any = None  # the model's introspection of that step's live states
        self.random = False  # play random_actions instead of the agent's
        self._live_seeds = np.zeros(0, dtype=np.int64)  # reset seeds of the live episodes
        self._t = 0  # the step about to be played
        self.generator = None
        if not greedy:
            import torch

            self.generator = torch.Generator().manual_seed(seed)

    # -------------------------------------------------------------- stepping

    def run(self) -> Recording:
        """Play the episodes in waves of ``n``: reset every sub-env with its episode's seed, step to the end.

        A sub-env whose episode ended keeps stepping (the env autoresets it)
        until the wave's longest episode ends; its later steps are not recorded.
        Waves need nothing beyond ``reset(seed=[...])``; the price is idle steps
        when episode lengths differ within a wave. The model sees only the live
        sub-envs (``act_on="live"``): idle ones at a wave's end cost nothing.
        """
        waves = run_waves(
            self._act, lambda _count: self.venv, self.episodes, self.seed, self.n,
            act_on="live", max_steps=self.max_steps,
        )  # fmt: skip
        for wave in waves:
            self._wave(wave)
        return self._tables()

    def _act(self, obs: np.ndarray, venv: Any) -> np.ndarray:
        """The agent's actions for the live sub-envs' observations; keeps the grid and introspection."""
        self._grid = venv.entity_grid().reshape(self.n, -1)  # (n, N) entity codes before the step
        acted, self._intro = self.agent.act(
            obs, greedy=self.greedy, introspect=True, generator=self.generator
        )
        if self.random:
            return random_actions(self._live_seeds, self._t, _action_count(venv))
        return np.asarray(acted)

    def _wave(self, wave: Wave) -> None:
        """Record one wave: the reset states, then each live sub-env's steps and states."""
        from neurosym.envs import ACTION_NAMES

        venv = self.venv
        action_names = np.asarray(getattr(venv, "action_names", ACTION_NAMES), dtype=object)
        grid = venv.entity_grid()  # (n, H, W) entity codes after the reset
        for i in range(wave.count):
            decoded = venv.decode_info(wave.info, i)
            self.trace.state(wave.first + i, 0, decoded)
            self.trace.map(wave.first + i, grid[i], self.names, decoded)
        live_mask = np.arange(self.n) < wave.count
        self._live_seeds, self._t = self.seed + wave.first + np.flatnonzero(live_mask), 0
        for step in wave.steps():
            live, episode = step.live, step.episodes
            t = np.full(live.size, step.t, dtype=np.int64)
            self._model_outputs(episode, t, self._grid[live], self._intro)
            self.step_cols.add(
                episode=episode,
                t=t,
                action=action_names[step.actions[live]],
                reward=step.reward[live],
            )
            for i in live.tolist():
                d = venv.decode_info(step.info, i)
                e, s = wave.first + i, step.t + 1
                self.trace.transition(e, s - 1, d)
                self.trace.state(e, s, d)
                if step.terminated[i] or step.truncated[i]:
                    outcome = d["outcome"] or ("timeout" if step.truncated[i] else "terminal")
                    self.ep_rows.append((e, s, float(wave.returns[i]), str(outcome), self.seed + e))
            if step.ended.size:
                self.advance(int(step.ended.size))
                live_mask[step.ended] = False
            self._live_seeds = self.seed + wave.first + np.flatnonzero(live_mask)
            self._t = step.t + 1

    def _model_outputs(self, ep: np.ndarray, t: np.ndarray, grid: np.ndarray, intro: Any) -> None:
        """Keep what the module's adapter keeps of the live states' introspection (argmax cells,
        top keys: small arrays); the tables are built from them once, at the end."""
        self.model.add(ep=ep, t=t, **self.adapter.keep(intro, grid, self.top_keys))

    # -------------------------------------------------------------- tables

    def _tables(self) -> Recording:
        W = self.venv.entity_grid().shape[-1]
        eps = pd.DataFrame(self.ep_rows, columns=["episode", "steps", "return", "outcome", "seed"])
        eps = eps.sort_values("episode", kind="stable")
        sc = self.step_cols.sorted_by("episode")
        steps = pd.DataFrame(
            {c: sc.get(c, np.zeros(0)) for c in ("episode", "t", "action", "reward")}
        )
        positions, holding, events = self.trace.tables()
        terrain, grids = self.trace.map_tables()
        tables: dict[str, pd.DataFrame] = {"terrain": terrain, "grids": grids}
        tables.update(self.trace.minigrid_tables())
        m = self.model.sorted_by("ep")  # states in episode order
        rows = self.adapter.rows(m, m["ep"], m["t"], self.names, W)
        tables.update({name: pd.DataFrame(cols) for name, cols in rows.items()})
        return Recording(
            episodes=eps,
            steps=steps,
            positions=positions,
            holding=holding,
            events=events,
            **tables,  # built from state arrays already in episode order
        )
