"""An :class:`EpisodeTrace` by playing a checkpoint: one episode, introspection on, full maps.

The agent acts greedily (or sampled from a generator seeded with the episode
seed) from ``reset(seed)``, one observation at a time on one torch thread;
per step only what the plots need is kept (MHDPA's (heads, N, N) maps only at
the states asked for).
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from neurosym.agent.networks.adapters import adapter_class
from neurosym.agent.waves import SingleAsBatch, run_waves
from neurosym.errors import ConfigError
from neurosym.viz.trace import DOOR_COLUMNS, OBJECT_COLUMNS, POSITION_COMPONENTS, EpisodeTrace

if TYPE_CHECKING:
    import gymnasium

    from neurosym.agent.agent import Agent


def trace_from_agent(
    agent: Agent,
    env: str | gymnasium.Env | None = None,
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
        self,
        agent: Agent,
        env: gymnasium.Env,
        env_name: str,
        seed: int,
        greedy: bool,
        keep: set[int] | None,
    ) -> None:
        import torch

        self.agent, self.env, self.env_name, self.seed = agent, env, env_name, seed
        self.greedy, self.keep = greedy, keep
        self.module = str(agent.config.module)
        self.pairs = adapter_class(self.module).has("attends")  # PrediNet: two attended cells
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
        self.facing: list[str] = []  # Minigrid: the agent's direction per state
        self.door_rows: list[tuple[int, int, int, str]] = []  # Minigrid: t, row, col, state
        self._intro: Any = None  # the model's introspection of the state being acted in

    def _grid(self) -> np.ndarray:
        return self.names[np.asarray(self.env.unwrapped.entity_grid())]

    def run(self, limit: int) -> None:
        """Play the episode (at most ``limit`` steps) with the shared play loop, as a batch of one."""
        waves = run_waves(
            self._act, lambda _count: SingleAsBatch(self.env), 1, self.seed, 1,
            act_on="live", max_steps=limit, stop_at_limit=True,
        )  # fmt: skip
        for wave in waves:
            self._check_shape(wave.obs[0])
            action_names = _action_names()
            self.grids.append(self._grid())
            self._objects(0, wave.info)
            for step in wave.steps():
                self._keep(step.t, self._intro)
                action = int(step.actions[0])
                self.actions.append(
                    action_names[action] if action < len(action_names) else str(action)
                )
                self.rewards.append(float(step.reward[0]))
                self.events.extend((step.t, str(e)) for e in step.info.get("events", ()))
                self.grids.append(self._grid())
                self._objects(step.t + 1, step.info)
                if step.ended.size:
                    truncated = bool(step.truncated[0])
                    self.outcome = step.info.get("outcome") or ("timeout" if truncated else None)

    def _act(self, obs: np.ndarray, _venv: Any) -> np.ndarray:
        """The agent's action for the one observation; keeps its introspection."""
        acts, self._intro = self.agent.act(
            obs, greedy=self.greedy, introspect=True, generator=self.generator
        )
        return np.asarray(acts).reshape(-1)

    def _check_shape(self, obs: np.ndarray) -> None:
        expected = tuple(self.agent.config.obs_shape)
        if tuple(obs.shape) != expected:
            raise ConfigError(
                f"{Path(str(self.agent.path)).name} expects observations of shape {expected}, "
                f"but {self.env_name} gives {tuple(obs.shape)}: pick the environment it was trained on"
            )

    def _objects(self, t: int, info: dict[str, Any]) -> None:
        objects = info.get("objects", ())
        self.object_rows.extend((t, str(i), str(k), int(r), int(c)) for i, k, r, c in objects)
        if "direction" in info:
            self.facing.append(str(info["direction"]))
        cell = {str(i): (int(r), int(c)) for i, _, r, c in objects}
        self.door_rows.extend(
            (t, *cell[str(i)], str(state)) for i, state in info.get("doors", ()) if str(i) in cell
        )

    def _keep(self, t: int, intro: Any) -> None:
        if self.pairs:
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
            facing=tuple(self.facing) if len(self.facing) == n_steps + 1 else (),
            doors=pd.DataFrame(self.door_rows, columns=DOOR_COLUMNS),
        )
        if self.pairs:
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


def _open_env(
    agent: Agent, env: str | gymnasium.Env | None, make: Any
) -> tuple[gymnasium.Env, str, bool]:
    """(env, short name, whether we made it): a fresh env unless the caller passed one.

    A named env may be any of the checkpoint's family with its observation
    shape (``checkpoint.env_for`` checks and picks its options); an env object
    passed in is checked for its shape when the episode starts.
    """
    from neurosym.agent.agent import env_for
    from neurosym.envs import canonical_name

    if env is None or isinstance(env, str):
        short, kwargs = env_for(agent, env)
        return make(short, **kwargs), short, True
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
