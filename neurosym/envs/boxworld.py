"""Box-World (Zambaldi et al. 2019) as a gymnasium environment, single and batched.

Both classes drive :class:`~neurosym.envs.boxworld_rules.BoxWorldState`: the
single environment is a batch of one, so the two agree step for step. Levels
come from :mod:`neurosym.envs.boxworld_gen`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from neurosym.envs.actions import ACTION_NAMES, Action
from neurosym.envs.boxworld_entities import ENTITY_NAMES, NUM_PLANES
from neurosym.envs.boxworld_gen import (
    GRID,
    Box,
    BoxWorldConfig,
    Level,
    NextLevels,
    generate_levels,
    random_keys,
    seed_keys,
)
from neurosym.envs.boxworld_render import DEFAULT_TILE, ansi_text, rgb_frame
from neurosym.envs.boxworld_rules import OBS_MODES, OUTCOMES, BoxWorldState, decode_info
from neurosym.errors import ConfigError

__all__ = [
    "ACTION_NAMES",
    "BOXWORLD_CONFIGS",
    "Action",
    "BoxWorldEnv",
    "BoxWorldVectorEnv",
    "Box",
    "Level",
    "decode_info",
]


BOXWORLD_CONFIGS: dict[str, dict[str, int]] = {
    # thesis section 4.2, Figures 10-12; episodes end after 300 steps
    "bw1": {"solution_length": 1, "num_distractors": 0, "distractor_length": 1, "max_steps": 300},
    "bw2": {"solution_length": 1, "num_distractors": 1, "distractor_length": 1, "max_steps": 300},
    "bw3": {"solution_length": 2, "num_distractors": 0, "distractor_length": 1, "max_steps": 300},
}
"""The thesis's named configurations: keyword arguments of both environment classes."""

_METADATA = {"render_modes": ["rgb_array", "ansi"], "render_fps": 8}


def _observation_space(obs_mode: str) -> spaces.Box:
    if obs_mode not in OBS_MODES:
        raise ConfigError(f"obs_mode {obs_mode!r} is not one of {', '.join(OBS_MODES)}")
    if obs_mode == "onehot":  # 0/1 planes: 6 object types, then 20 colours
        return spaces.Box(0, 1, (NUM_PLANES, GRID, GRID), np.uint8)
    # RGB, channels first, 0..255 (obs_scale 1/255): the 12 x 12 interior and its border
    return spaces.Box(0, 255, (3, GRID, GRID), np.uint8)


def _obs_scale(obs_mode: str) -> float:
    return 1.0 if obs_mode == "onehot" else 1.0 / 255.0


def _check_render_mode(render_mode: str | None, tile_size: int) -> None:
    if render_mode is not None and render_mode not in _METADATA["render_modes"]:
        raise ConfigError(
            f"unknown render_mode {render_mode!r}; Box-World renders {', '.join(_METADATA['render_modes'])}"
        )
    if not isinstance(tile_size, int | np.integer) or isinstance(tile_size, bool) or tile_size < 4:
        raise ConfigError(f"tile_size must be an integer of at least 4 pixels, got {tile_size!r}")


class BoxWorldEnv(gym.Env[np.ndarray, np.int64]):
    """Box-World: open the right boxes, in the right order, to reach the gem.

    ## Description
    A 12 x 12 room with a one-cell wall border. Keys lie loose; a box is a lock
    cell with its content (a key or the gem) in the cell to its left. The agent
    holds at most one key, drawn in the top-left border cell. Walking into a
    loose key picks it up (a key already held is lost). Walking into a lock
    while holding its colour's key consumes the key and opens the box, which
    hands over its content at once (the thesis's variant: the agent need not
    step onto it); the agent moves onto the lock's cell. A lock without its key
    and a box's content block like walls. One loose key starts a chain of
    ``solution_length`` boxes ending in the gem; ``num_distractors`` branches
    of ``distractor_length`` boxes hang off the chain's locks and lead nowhere.
    Levels are drawn anew every episode (:mod:`neurosym.envs.boxworld_gen`).

    ## Action Space
    ``Discrete(4)``: 0 up, 1 right, 2 down, 3 left
    (:class:`neurosym.envs.actions.Action`).

    ## Observation
    ``obs_mode="rgb"`` (default): ``uint8`` RGB ``(3, 14, 14)``, channels first
    (``obs_scale`` 1/255): wall black, empty light grey, agent dark grey, gem
    white, keys and locks in one of 20 named colours
    (:data:`~neurosym.envs.boxworld_entities.COLOURS`).
    ``obs_mode="onehot"`` (what ``neurosym train`` uses by default): ``uint8``
    0/1 planes ``(26, 14, 14)``: six object types (wall, agent, gem, key,
    lock, held key) then one plane per colour, so a key and its lock share a
    plane (:data:`~neurosym.envs.boxworld_entities.ONEHOT`); empty cells
    set none. The held key is the top-left border cell in both modes.
    ``entity_grid()`` names each cell: ``agent, gem, key(C), lock(C),
    held(C), wall, empty`` (a box's content shows as ``key(C)`` or ``gem``).

    ## Rewards
    +1 for opening a box on the solution path, -1 for opening a distractor
    box, +10 for the gem (opening the gem's box pays +1 + 10 = 11), 0 otherwise.

    ## Termination
    Terminated on the gem (outcome ``gem``) or on opening a distractor box
    (outcome ``distractor``); truncated after ``max_steps`` steps (outcome
    ``timeout``), never both on one step.

    ## Info
    ``agent`` (row, col); ``holding`` ``("key(red)",)`` or ``()``; ``objects``
    ``(id, type, row, col)`` of the agent (id ``agent``, first) and every key,
    lock and gem still on the map (ids ``key_red``, ``lock_red``, ``lock_red_2``
    when a colour repeats, numbered row-major, fixed for the episode; the held
    key is in ``holding``, not here); ``events``: ``got(key(C))`` on picking up a loose key;
    ``opened(lock(C))`` then ``got(key(C2))`` or ``got(gem)`` on opening a box;
    ``got(gem)`` on a loose gem; ``hit(distractor)`` after the events of a
    distractor box; ``outcome``: ``gem``, ``distractor``, ``timeout`` or None.

    ## Seeding
    ``reset(seed=s)`` starts level stream ``s``; later resets without a seed
    play its next levels. A :class:`BoxWorldVectorEnv` seeded ``s`` plays in
    sub-environment ``i`` exactly the levels of this class seeded ``s + i``.
    ``reset(options={"level": Level(...)})`` plays a hand-built level.

    ## Registered Configurations
    ``bw1`` (solution length 1, no distractor), ``bw2`` (length 1, one
    distractor of length 1), ``bw3`` (length 2, no distractor), all with 300
    steps (:data:`BOXWORLD_CONFIGS`); ``boxworld`` uses this class's defaults
    (length 3, two distractors of length 1).
    """

    metadata = _METADATA
    entity_names: tuple[str, ...] = ENTITY_NAMES

    def __init__(
        self,
        solution_length: int = 3,
        num_distractors: int = 2,
        distractor_length: int = 1,
        max_steps: int = 300,
        render_mode: str | None = None,
        tile_size: int = DEFAULT_TILE,
        obs_mode: str = "rgb",
    ) -> None:
        self.config = BoxWorldConfig(solution_length, num_distractors, distractor_length, max_steps)
        _check_render_mode(render_mode, tile_size)
        self.render_mode = render_mode
        self.tile_size = tile_size
        self.observation_space = _observation_space(obs_mode)
        self.obs_mode = obs_mode
        self.obs_scale = _obs_scale(obs_mode)
        self.action_space = spaces.Discrete(4)  # 0 up, 1 right, 2 down, 3 left
        self._state = BoxWorldState(1, self.config.num_slots, max_steps, obs_mode)
        self._key: np.ndarray | None = None  # (1,) uint64 level stream
        self._episode = 0
        self._action = np.zeros(1, np.int64)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        if seed is not None:
            self._key, self._episode = seed_keys(seed, 1), 0
        elif self._key is None:
            self._key, self._episode = random_keys(self.np_random, 1), 0
        else:
            self._episode += 1
        level = (options or {}).get("level")
        if level is None:
            levels = generate_levels(self.config, self._key, np.array([self._episode], np.uint64))
        elif isinstance(level, Level):
            levels = level.to_arrays()
            if levels.cells.shape[1] > self._state.slots:
                self._state = BoxWorldState(
                    1, levels.cells.shape[1], self.config.max_steps, self.obs_mode
                )
        else:
            raise ConfigError(
                f"options['level'] must be a neurosym.envs.boxworld.Level, got {type(level).__name__}"
            )
        self._state.load(np.zeros(1, np.int64), levels)
        return self._state.observation()[0], decode_info(self._state.info(), 0)

    def step(self, action: int) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        if self._key is None:
            raise RuntimeError("call reset() before step()")
        if not (isinstance(action, int | np.integer) and 0 <= action < 4):
            raise ValueError(
                f"unknown action {action!r}; actions are 0 up, 1 right, 2 down, 3 left"
            )
        self._action[0] = action
        reward, terminated, truncated = self._state.step(self._action)
        info = decode_info(self._state.info(), 0)
        return (
            self._state.observation()[0],
            float(reward[0]),
            bool(terminated[0]),
            bool(truncated[0]),
            info,
        )

    def entity_grid(self) -> np.ndarray:
        """(14, 14) entity codes of the current state; names in ``entity_names``."""
        return self._state.entity_grid()[0]

    def render(self) -> np.ndarray | str | None:
        if self.render_mode == "rgb_array":
            return rgb_frame(self.entity_grid(), self.tile_size)
        if self.render_mode == "ansi":
            return ansi_text(self.entity_grid())
        return None


class BoxWorldVectorEnv(VectorEnv):
    """``num_envs`` Box-World environments stepped together with array operations.

    Same rules, observation and configurations as :class:`BoxWorldEnv`, with
    gymnasium's next-step autoreset: the step after one that ends sub-env
    ``i``'s episode ignores its action and returns the first observation of a
    new level (reward 0, not terminated, not truncated). Every sub-env's next
    level is drawn ahead; used ones are drawn again together, vectorised, once
    an eighth of the sub-envs used theirs (:class:`~neurosym.envs.boxworld_gen.NextLevels`).

    ``info`` holds arrays (agent, held, object_code/cell/alive, event_key,
    event_lock, event_got, outcome); :meth:`decode_info` gives the single
    environment's dict for one sub-environment. On an autoreset step
    ``info["final_info"]`` is the previous step's info (the ended episode's
    last step) and ``info["_final_info"]`` marks the sub-environments it
    concerns.

    Seeding: sub-environment ``i`` of an environment seeded ``s`` (here or in
    ``reset(seed=s)``) plays the levels of ``BoxWorldEnv`` seeded ``s + i``.

    ``copy=False`` returns the internal observation buffer itself, which the next
    step overwrites (faster; copy it if you keep it).
    """

    metadata = {**_METADATA, "autoreset_mode": AutoresetMode.NEXT_STEP}
    entity_names: tuple[str, ...] = ENTITY_NAMES

    def __init__(
        self,
        num_envs: int,
        seed: int | None = None,
        solution_length: int = 3,
        num_distractors: int = 2,
        distractor_length: int = 1,
        max_steps: int = 300,
        render_mode: str | None = None,
        tile_size: int = DEFAULT_TILE,
        copy: bool = True,
        obs_mode: str = "rgb",
    ) -> None:
        if not isinstance(num_envs, int | np.integer) or isinstance(num_envs, bool) or num_envs < 1:
            raise ConfigError(f"num_envs must be a positive integer, got {num_envs!r}")
        self.num_envs = int(num_envs)
        self.config = BoxWorldConfig(solution_length, num_distractors, distractor_length, max_steps)
        _check_render_mode(render_mode, tile_size)
        self.render_mode = render_mode
        self.tile_size = tile_size
        self.copy = bool(copy)
        self.single_observation_space = _observation_space(obs_mode)
        self.obs_mode = obs_mode
        self.obs_scale = _obs_scale(obs_mode)
        self.single_action_space = spaces.Discrete(4)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self._state = BoxWorldState(self.num_envs, self.config.num_slots, max_steps, obs_mode)
        if seed is not None:
            seed_keys(seed, 1)  # refuse a bad seed now rather than at the first reset
        self._seed = seed
        self._keys: np.ndarray | None = None  # (n,) uint64 level streams
        self._episodes = np.zeros(self.num_envs, np.uint64)
        # next levels drawn ahead, refilled once an eighth of the envs used theirs
        self._next = NextLevels(self.config, self.num_envs, self.num_envs // 8)
        self._autoreset = np.zeros(self.num_envs, bool)
        self._last_info: dict[str, Any] | None = None

    def reset(
        self, *, seed: int | Sequence[int] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Reset all sub-environments, or those in ``options["reset_mask"]`` (bool, (n,))."""
        n = self.num_envs
        mask = (options or {}).get("reset_mask")
        if mask is None or self._keys is None:  # the first reset starts every sub-environment
            rows = np.arange(n)
        else:
            rows = np.flatnonzero(np.asarray(mask, bool).reshape(n))
        if seed is not None:
            if isinstance(seed, int | np.integer):
                super().reset(seed=int(seed))
                keys = seed_keys(int(seed), n)
            else:
                if len(seed) != n:
                    raise ConfigError(f"reset got {len(seed)} seeds for {n} environments")
                keys = np.concatenate([seed_keys(s, 1) for s in seed])
            if self._keys is None:
                self._keys = keys
            self._keys[rows] = keys[rows]
            self._episodes[rows] = 0
        elif self._keys is None:
            self._keys = (
                seed_keys(self._seed, n)
                if self._seed is not None
                else random_keys(self.np_random, n)
            )
            self._episodes[:] = 0
        else:
            self._episodes[rows] += np.uint64(1)
        self._state.load(rows, self._next.take(rows, self._keys, self._episodes))
        self._autoreset[rows] = False
        info = self._state.info()
        self._last_info = info
        return self._observation(), info

    def step(
        self, actions: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        if self._keys is None:
            raise RuntimeError("call reset() before step()")
        actions = np.asarray(actions)
        if actions.shape != (self.num_envs,) or actions.dtype.kind not in "iu":
            raise ValueError(
                f"actions must be {self.num_envs} integers in 0..3, got shape {actions.shape} dtype {actions.dtype}"
            )
        if ((actions < 0) | (actions > 3)).any():
            bad = actions[(actions < 0) | (actions > 3)][0]
            raise ValueError(f"unknown action {bad}; actions are 0 up, 1 right, 2 down, 3 left")
        reward, terminated, truncated = self._state.step(actions.astype(np.int64, copy=False))
        restart = np.flatnonzero(self._autoreset)
        if restart.size:
            self._episodes[restart] += np.uint64(1)
            self._state.load(restart, self._next.take(restart, self._keys, self._episodes))
            reward[restart] = 0.0
            terminated[restart] = False
            truncated[restart] = False
        info = self._state.info()
        last = self._last_info
        self._last_info = info
        if restart.size:
            info = {**info, "final_info": last, "_final_info": self._autoreset.copy()}
        self._autoreset = terminated | truncated
        return self._observation(), reward, terminated, truncated, info

    def _observation(self) -> np.ndarray:
        if self.copy:
            return self._state.observation()
        return self._state.obs.reshape(self.num_envs, self._state.planes, GRID, GRID)  # live buffer

    def decode_info(self, info: dict[str, Any], i: int) -> dict[str, Any]:
        """The dict :class:`BoxWorldEnv` would give for sub-environment ``i``."""
        return decode_info(info, i)

    def episode_outcome(self, info: dict[str, Any], i: int) -> str | None:
        """``decode_info(info, i)["outcome"]`` without building the rest of that dict."""
        return OUTCOMES[int(info["outcome"][i])]

    def entity_grid(self) -> np.ndarray:
        """(n, 14, 14) entity codes of the current states; names in ``entity_names``."""
        return self._state.entity_grid()

    def solver_states(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(n, 196) entity codes, (n, 196) distractor-lock flags, (n,) agent cells and (n,) held
        key colours (-1 none) of the current states (copies): what
        :func:`boxworld_solver.search` starts from."""
        s = self._state
        return s.grid.copy(), s.distractor.copy(), s.agent.copy(), s.held.astype(np.int64)

    def render(self) -> tuple[np.ndarray, ...] | tuple[str, ...] | None:
        grids = self.entity_grid()
        if self.render_mode == "rgb_array":
            return tuple(rgb_frame(g, self.tile_size) for g in grids)
        if self.render_mode == "ansi":
            return tuple(ansi_text(g) for g in grids)
        return None
