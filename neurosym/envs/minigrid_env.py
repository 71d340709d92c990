"""Farama Minigrid and BabyAI as neurosym environments: a thin wrapper, single and batched.

The wrapped env is Minigrid's own (``gymnasium.make(env_id).unwrapped``): its
rules, levels, rewards and seeding are untouched. What the wrapper adds is what
neurosym's agents, recorder and fact writer read from every env
(:mod:`neurosym.envs.minigrid_state`): a fully observed one-hot observation,
the entity grid, and an ``info`` with the symbolic state and the step's events.
"""

from __future__ import annotations

import contextlib
import io
from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from neurosym.envs import minigrid_state as ms
from neurosym.errors import ConfigError

_METADATA = {"render_modes": ["rgb_array", "ansi"], "render_fps": 8}
DEFAULT_TILE = 16


def _inner(env_id: str, max_steps: int | None, render_mode: str | None) -> Any:
    """Minigrid's own env, unwrapped (its TimeLimit-free step does its own truncation)."""
    import minigrid  # noqa: F401  (registers the MiniGrid-* and BabyAI-* ids)

    if env_id not in gym.registry:
        raise ConfigError(f"unknown Minigrid environment {env_id!r}")
    kwargs: dict[str, Any] = {} if max_steps is None else {"max_steps": int(max_steps)}
    if render_mode is not None:
        kwargs["render_mode"] = "rgb_array"
    try:
        env = gym.make(env_id, **kwargs).unwrapped
    except TypeError as exc:
        raise ConfigError(f"{env_id} does not take these options ({exc})") from None
    if getattr(env.action_space, "n", None) != len(ms.ACTION_NAMES):
        raise ConfigError(f"{env_id} has {env.action_space} actions, not Minigrid's 7")
    # Minigrid's own observation (the agent's 7 x 7 view, cropped and rotated cell by cell) is
    # never read here and took two thirds of a step; its step and reset return None for it.
    env.gen_obs = _no_observation
    return env


def _no_observation() -> None:
    return None


class MinigridEnv(gym.Env[np.ndarray, np.int64]):
    """A Minigrid or BabyAI env, fully observed, with neurosym's symbolic ``info``.

    ## Action Space
    ``Discrete(7)``, Minigrid's own: 0 left, 1 right (turn), 2 forward, 3 pickup,
    4 drop, 5 toggle, 6 done (``step/4`` atoms: :data:`~neurosym.envs.minigrid_state.ACTION_NAMES`).

    ## Observation
    ``uint8`` 0/1 planes ``(31, H, W)`` of the whole grid
    (:data:`~neurosym.envs.minigrid_state.NUM_PLANES`): object types, colours,
    door states, the agent's direction at its cell, what it carries. The
    mission text is not in it (``info["mission"]`` and ``mission/2`` have it).

    ## Info
    ``agent`` (row, col); ``direction`` (``east``, ``south``, ``west``,
    ``north``); ``holding`` ``("key(yellow)",)`` or ``()``; ``objects`` (id,
    type, row, col) of the agent (first) and every key, ball, box, door and goal
    on the map; ``doors`` (id, state); ``mission``; ``events`` (see
    :func:`~neurosym.envs.minigrid_state.events`); ``outcome`` (``goal``,
    ``mission``, ``lava``, ``failure``, ``timeout`` or None).

    ## Seeding
    ``reset(seed=s)`` is Minigrid's ``reset(seed=s)``: the same level as
    ``gymnasium.make(env_id).reset(seed=s)``.
    """

    metadata = _METADATA
    entity_names: tuple[str, ...] = ms.ENTITY_NAMES
    action_names: tuple[str, ...] = ms.ACTION_NAMES
    obs_scale = 1.0

    def __init__(
        self,
        env_id: str = "MiniGrid-DoorKey-5x5-v0",
        max_steps: int | None = None,
        render_mode: str | None = None,
        tile_size: int = DEFAULT_TILE,
    ) -> None:
        if render_mode is not None and render_mode not in _METADATA["render_modes"]:
            raise ConfigError(
                f"unknown render_mode {render_mode!r}; Minigrid renders rgb_array, ansi"
            )
        if max_steps is not None and max_steps < 1:
            raise ConfigError(f"max_steps must be a positive integer or none, got {max_steps!r}")
        self.env_id = env_id
        self.render_mode = render_mode
        self.tile_size = int(tile_size)
        self.inner = _inner(env_id, max_steps, render_mode)
        with contextlib.redirect_stdout(io.StringIO()):
            self.inner.reset(seed=0)  # the grid's size (fixed per env id)
        height, width = self.inner.grid.height, self.inner.grid.width
        self.observation_space = spaces.Box(0, 1, (ms.NUM_PLANES, height, width), np.uint8)
        self.action_space = spaces.Discrete(len(ms.ACTION_NAMES))
        self._namer = ms.Namer()
        self._snap: ms.GridState | None = None

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        with contextlib.redirect_stdout(io.StringIO()):  # BabyAI prints its rejected samples
            self.inner.reset(seed=seed, options=options)
        self._namer = ms.Namer()
        self._snap = ms.snapshot(self.inner, self._namer)
        if self._snap.cells.shape[:2] != self.observation_space.shape[1:]:
            raise ConfigError(
                f"{self.env_id} drew a {self._snap.cells.shape[:2]} grid after "
                f"{self.observation_space.shape[1:]}: neurosym needs one grid size per env"
            )
        return ms.observation(self._snap), _info(self._snap, (), None)

    def step(self, action: int) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        if self._snap is None:
            raise RuntimeError("call reset() before step()")
        if not (isinstance(action, int | np.integer) and 0 <= action < len(ms.ACTION_NAMES)):
            raise ValueError(
                f"unknown action {action!r}; actions are "
                + ", ".join(f"{i} {a}" for i, a in enumerate(ms.ACTION_NAMES))
            )
        before = self._snap
        _, reward, terminated, truncated, _ = self.inner.step(int(action))
        after = ms.snapshot(self.inner, self._namer)
        self._snap = after
        events = ms.events(before, after, int(action), float(reward), bool(terminated))
        outcome = ms.outcome(after, float(reward), bool(terminated), bool(truncated))
        info = _info(after, events, outcome)
        return ms.observation(after), float(reward), bool(terminated), bool(truncated), info

    def entity_grid(self) -> np.ndarray:
        """(H, W) entity codes of the current state; names in ``entity_names``."""
        if self._snap is None:
            raise RuntimeError("call reset() before entity_grid()")
        return ms.entity_codes(self._snap)

    def render(self) -> np.ndarray | str | None:
        """Minigrid's own full-grid picture (``rgb_array``) or its text grid (``ansi``)."""
        if self.render_mode == "rgb_array":
            return self.inner.get_frame(highlight=False, tile_size=self.tile_size)
        if self.render_mode == "ansi":
            return self.inner.pprint_grid() + "\n" + self.inner.mission
        return None

    def close(self) -> None:
        self.inner.close()


def _info(snap: ms.GridState, events: tuple[str, ...], outcome: str | None) -> dict[str, Any]:
    return {
        "agent": snap.agent,
        "direction": ms.DIRECTIONS[snap.direction],
        "holding": snap.carrying,
        "objects": snap.objects,
        "doors": snap.doors,
        "mission": snap.mission,
        "events": events,
        "outcome": outcome,
    }


class MinigridVectorEnv(VectorEnv):
    """``num_envs`` :class:`MinigridEnv` stepped in turn, with gymnasium's next-step autoreset.

    Minigrid steps one env in Python, so the batch is a loop; what it shares
    with the other families' batched classes is the interface: the step after
    one that ends sub-env ``i``'s episode ignores its action and returns the
    first observation of the next one (reward 0, not terminated, not truncated);
    ``info["decoded"]`` holds each sub-env's single-env info (:meth:`decode_info`).

    Seeding: sub-environment ``i`` of an environment seeded ``s`` (here or in
    ``reset(seed=s)``) plays what :class:`MinigridEnv` seeded ``s + i`` plays.
    """

    metadata = {**_METADATA, "autoreset_mode": AutoresetMode.NEXT_STEP}
    entity_names: tuple[str, ...] = ms.ENTITY_NAMES
    action_names: tuple[str, ...] = ms.ACTION_NAMES
    obs_scale = 1.0

    def __init__(
        self,
        num_envs: int,
        seed: int | None = None,
        env_id: str = "MiniGrid-DoorKey-5x5-v0",
        max_steps: int | None = None,
        render_mode: str | None = None,
        tile_size: int = DEFAULT_TILE,
        copy: bool = True,
    ) -> None:
        if not isinstance(num_envs, int | np.integer) or isinstance(num_envs, bool) or num_envs < 1:
            raise ConfigError(f"num_envs must be a positive integer, got {num_envs!r}")
        self.num_envs = int(num_envs)
        self.envs = [
            MinigridEnv(env_id, max_steps, render_mode, tile_size) for _ in range(self.num_envs)
        ]
        self.render_mode = render_mode
        self.copy = bool(copy)
        self.single_observation_space = self.envs[0].observation_space
        self.single_action_space = self.envs[0].action_space
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self._seed = seed
        self._obs = np.zeros(self.observation_space.shape, np.uint8)
        self._infos: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
        self._autoreset = np.zeros(self.num_envs, bool)
        self._started = False

    def reset(
        self, *, seed: int | Sequence[int] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Reset all sub-environments, or those in ``options["reset_mask"]`` (bool, (n,))."""
        n = self.num_envs
        mask = (options or {}).get("reset_mask")
        rows = range(n) if mask is None or not self._started else np.flatnonzero(mask).tolist()
        if seed is None and not self._started and self._seed is not None:
            seed = self._seed
        if seed is None:
            seeds: list[int | None] = [None] * n
        elif isinstance(seed, int | np.integer):
            super().reset(seed=int(seed))
            seeds = [int(seed) + i for i in range(n)]
        else:
            if len(seed) != n:
                raise ConfigError(f"reset got {len(seed)} seeds for {n} environments")
            seeds = [int(s) for s in seed]
        for i in rows:
            self._obs[i], self._infos[i] = self.envs[i].reset(seed=seeds[i])
            self._autoreset[i] = False
        self._started = True
        return self._observation(), {"decoded": tuple(self._infos)}

    def step(
        self, actions: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        if not self._started:
            raise RuntimeError("call reset() before step()")
        actions = np.asarray(actions)
        if actions.shape != (self.num_envs,) or actions.dtype.kind not in "iu":
            raise ValueError(
                f"actions must be {self.num_envs} integers in 0..6, got shape {actions.shape} "
                f"dtype {actions.dtype}"
            )
        n = self.num_envs
        reward = np.zeros(n, np.float64)
        terminated = np.zeros(n, bool)
        truncated = np.zeros(n, bool)
        restarted = self._autoreset.copy()
        final = list(self._infos)
        for i, env in enumerate(self.envs):
            if restarted[i]:
                self._obs[i], self._infos[i] = env.reset()
                continue
            self._obs[i], reward[i], terminated[i], truncated[i], self._infos[i] = env.step(
                int(actions[i])
            )
        info: dict[str, Any] = {"decoded": tuple(self._infos)}
        if restarted.any():
            info = {**info, "final_info": {"decoded": tuple(final)}, "_final_info": restarted}
        self._autoreset = terminated | truncated
        return self._observation(), reward, terminated, truncated, info

    def _observation(self) -> np.ndarray:
        return self._obs.copy() if self.copy else self._obs

    def decode_info(self, info: dict[str, Any], i: int) -> dict[str, Any]:
        """The dict :class:`MinigridEnv` gave for sub-environment ``i``."""
        return info["decoded"][i]

    def episode_outcome(self, info: dict[str, Any], i: int) -> str | None:
        return info["decoded"][i]["outcome"]

    def entity_grid(self) -> np.ndarray:
        """(n, H, W) entity codes of the current states; names in ``entity_names``."""
        return np.stack([env.entity_grid() for env in self.envs])

    def render(self) -> tuple[Any, ...] | None:
        if self.render_mode is None:
            return None
        return tuple(env.render() for env in self.envs)

    def close_extras(self, **kwargs: Any) -> None:
        for env in self.envs:
            env.close()
