"""Relational-Grid-World as a gymnasium environment (one episode at a time).

The rules live in :mod:`neurosym.envs.rgw_rules` and are shared with the batched
:class:`~neurosym.envs.rgw_vector.RGWVectorEnv`; this class adds the gymnasium
API, the ``info`` dict and rendering.
"""

from __future__ import annotations

import os
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from neurosym.envs import render as draw
from neurosym.envs import rgw_rules as rules
from neurosym.envs.actions import Action
from neurosym.envs.rgw_levels import FixedLevel, LevelObjects, LevelSource, batch_for
from neurosym.envs.rgw_maps import load_map
from neurosym.envs.rgw_solver import Rules
from neurosym.errors import ConfigError

OBS_MODES = ("onehot", "grey")


def check_options(
    obs_mode: str,
    max_steps: int | None,
    render_mode: str | None,
    enemy: str = "pass",
    classic: bool = False,
) -> None:
    """Refuse bad constructor options with one line naming what would be right."""
    rules.check_enemy(enemy, bool(classic))
    if obs_mode not in OBS_MODES:
        raise ConfigError(f"obs_mode {obs_mode!r} is not one of {', '.join(OBS_MODES)}")
    if max_steps is not None and (not isinstance(max_steps, int | np.integer) or max_steps < 1):
        raise ConfigError(f"max_steps must be a positive integer or None, got {max_steps!r}")
    if render_mode not in (None, "rgb_array", "ansi"):
        raise ConfigError(f"render_mode {render_mode!r} is not one of None, 'rgb_array', 'ansi'")


def observation_space(obs_mode: str, height: int, width: int) -> spaces.Box:
    """Onehot: (9, H, W) of 0/1; grey: (1, H, W) of 0..255; uint8 either way."""
    if obs_mode == "onehot":
        return spaces.Box(0, 1, (rules.NUM_PLANES, height, width), dtype=np.uint8)
    return spaces.Box(0, 255, (1, height, width), dtype=np.uint8)


def parse_action(action: Any) -> int:
    """An action as a plain int 0..3, or ValueError naming the bad value."""
    try:
        value = int(action)
    except (TypeError, ValueError):
        raise ValueError(
            f"action must be an integer 0..3 (up, right, down, left), got {action!r}"
        ) from None
    if value != action or not 0 <= value <= 3:
        raise ValueError(f"action must be an integer 0..3 (up, right, down, left), got {action!r}")
    return value


class RGWEnv(gym.Env[np.ndarray, np.int64]):
    """Relational-Grid-World (Yildirim 2021), the thesis's relational testbed.

    ## Description
    A grid of cells, one object per cell. The agent picks up the sword, uses it
    on the enemy, may take the teleport, and reaches the terminal. Maps are
    text (see :mod:`neurosym.envs.rgw_maps`); ``rgw2`` is the original
    release's Configuration-2, ``rgw1`` the same map without mountains and pits.

    ## Action Space
    ``Discrete(4)``: 0 up, 1 right, 2 down, 3 left (:class:`~neurosym.envs.Action`).

    ## Observation
    ``obs_mode="onehot"`` (default): ``(9, H, W)`` uint8, one 0/1 plane per
    entity (agent, sword, enemy, terminal, teleport, wall, mountain, pit; the
    agent's cell shows only the agent) and plane 8 all ones while the sword is
    held. ``obs_mode="grey"``: ``(1, H, W)`` uint8, the original intensities
    (agent 128, terminal 255, teleport 200, sword 75, enemy 175, mountain 150,
    pit 30, wall 0, empty 220). ``env.obs_scale`` turns values into [0, 1].

    ## Rewards
    Default rules (the thesis text), paid on *entering* a cell: mountain -0.1;
    pit -1; terminal +10; enemy +1 when holding the sword (the enemy is
    defeated and removed) and -1 otherwise; sword and teleport 0.
    Bumping into a wall or the border leaves the agent in place, pays nothing
    and triggers nothing (not even a teleport under the agent). Entering a
    teleport end puts the agent on the other end.

    What an unarmed meeting with the enemy does besides the -1 is the
    ``enemy`` option: ``"pass"`` (default for rgw1, rgw2 and maps: the thesis's
    rule; the enemy stays and the agent stands on its cell), ``"block"`` (the
    enemy blocks the way like a wall: the agent stays where it was; -1 every
    time it tries; event ``bumped(enemy)``) or ``"end"`` (the episode ends as
    in a pit; event ``killed_by(enemy)``, outcome ``enemy``). Every mode also
    lists ``hurt_by(enemy)``, so "met the enemy unarmed" reads the same in all.
    A meeting with the sword is the same in every mode: +1, defeated, removed.

    ``classic=True`` reproduces the original release exactly (and allows only
    ``enemy="pass"``): the cell reward
    is paid whenever a step ends on a cell, staying in place included; the
    enemy is never removed, so it pays +1 (with the sword) or -1 on every such
    step; the original's ``state > nS_pos`` test makes an agent at cell (0, 0)
    count as not holding the sword; the ``Q`` teleport end at (3, 9) of rgw2
    also counts as a mountain (-0.1 on landing there); any step that ends on a
    teleport end, bumps included, teleports. The original has no step limit:
    ``classic=True, max_steps=None`` is the original release exactly.

    ## Termination
    Terminated on reaching the terminal (outcome ``terminal``), falling into
    a pit (``pit``) or, with ``enemy="end"``, meeting the enemy unarmed
    (``enemy``); truncated after ``max_steps`` steps (default 100; None for
    no limit) with outcome ``timeout``. A step that terminates is never also
    reported as truncated.

    ## Info
    After reset and every step: ``agent`` (row, col); ``holding`` (``("sword",)``
    or ``()``); ``objects`` ((id, type, row, col) of the agent and every object
    still on the map); ``events`` (Prolog text of this step's events, in this
    order: ``bumped(border)``, ``bumped(wall)``, ``teleported``,
    ``crossed(mountain)``, ``picked(sword)``, ``defeated(enemy)``,
    ``hurt_by(enemy)``, ``fell(pit)``, ``reached(terminal)``,
    ``bumped(enemy)``, ``killed_by(enemy)``); ``outcome``. And the level:
    ``optimal_return`` (the best return any route earns within ``max_steps``
    under these rules, found by exhaustive search,
    :mod:`neurosym.envs.rgw_solver`; NaN for a map with more than 8 swords and
    enemies, or classic rules without a step limit), ``guarded`` (every route
    to a terminal meets an enemy), ``needs_teleport`` (every route goes
    through the teleport), ``hazard_on_route`` (every shortest route crosses a
    mountain or a pit).

    ## Registered Configurations
    * ``neurosym/RGW1-v0`` (``rgw1``): Configuration-1, optimal return 11.
    * ``neurosym/RGW2-v0`` (``rgw2``): Configuration-2, optimal return 10.7.
    * ``neurosym/RGWRandom-v0`` (``rgw-random``): procedural levels with a
      blocking enemy (:class:`~neurosym.envs.rgw_random.RGWRandomEnv`).

    Every configuration takes ``enemy=`` and ``classic=``; ``map=`` (a shipped
    name, a file or map text) plays any map with the same rules.
    """

    metadata: ClassVar[dict[str, Any]] = {"render_modes": ["rgb_array", "ansi"], "render_fps": 4}
    entity_names: tuple[str, ...] = rules.ENTITY_NAMES

    def __init__(
        self,
        map: str | os.PathLike[str] = "rgw2",
        *,
        classic: bool = False,
        obs_mode: str = "onehot",
        max_steps: int | None = 100,
        render_mode: str | None = None,
        enemy: str = "pass",
    ) -> None:
        check_options(obs_mode, max_steps, render_mode, enemy, classic)
        source = FixedLevel(load_map(map), Rules(bool(classic), enemy, max_steps))
        self._setup(source, classic, obs_mode, max_steps, render_mode, enemy)

    def _setup(
        self,
        source: LevelSource,
        classic: bool,
        obs_mode: str,
        max_steps: int | None,
        render_mode: str | None,
        enemy: str,
    ) -> None:
        check_options(obs_mode, max_steps, render_mode, enemy, classic)
        self.source = source
        self.enemy = enemy
        self.classic = bool(classic)
        self.obs_mode = obs_mode
        self.max_steps = max_steps
        self.render_mode = render_mode
        self.height, self.width = source.height, source.width
        # Observation: onehot planes or grey intensities, channels first.
        self.observation_space = observation_space(obs_mode, self.height, self.width)
        # Action: 0 up, 1 right, 2 down, 3 left.
        self.action_space = spaces.Discrete(len(Action))
        self.obs_scale = 1.0 if obs_mode == "onehot" else 1 / 255
        self._batch = batch_for(
            source, 1, classic=self.classic, obs_mode=obs_mode, max_steps=max_steps, enemy=enemy
        )
        self.level_seed: int | None = None
        """seed of the current level key (see rgw_levels)"""
        self.episode_index = -1
        """episodes begun since the last seeded reset"""
        self._objects = None if source.per_episode else source.objects(0, 0)
        self._ring = source.ring(1) if source.per_episode else None
        self._level: dict[str, Any] = {}
        """the current level's LevelInfo entries (optimal_return, guarded, ...)"""
        if not source.per_episode:
            self._level = source.levels(np.zeros(1, np.uint64), np.zeros(1, np.int64))[2].row(0)

    # -- gymnasium API --------------------------------------------------------

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        if seed is not None:
            self.level_seed, self.episode_index = int(seed), 0
        elif self.level_seed is None:
            self.level_seed, self.episode_index = int(self.np_random.integers(2**63)), 0
        else:
            self.episode_index += 1
        if self.source.per_episode:
            key_s = np.array([self.level_seed], dtype=np.uint64)
            key_e = np.array([self.episode_index], dtype=np.int64)
            cells, starts, level = self._ring.take(np.zeros(1, np.intp), key_s, key_e)
            self._batch.set_levels(np.zeros(1, np.intp), cells, starts)
            self._objects = LevelObjects(cells[0], self.width)
            self._level = level.row(0)
        self._batch.reset_rows()
        return self._batch.obs[0].copy(), self._info(0, False)

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        if self.episode_index < 0:
            raise gym.error.ResetNeeded("call reset() before step()")
        a = parse_action(action)
        res = self._batch.step(np.array([a], dtype=np.intp))
        info = self._info(int(res.events[0]), bool(res.truncated[0]))
        return (
            self._batch.obs[0].copy(),
            float(res.reward[0]),
            bool(res.terminated[0]),
            bool(res.truncated[0]),
            info,
        )

    def _info(self, events: int, truncated: bool) -> dict[str, Any]:
        b = self._batch
        pos = int(b.pos[0])
        return {
            "agent": divmod(pos, self.width),
            "holding": ("sword",) if b.holding[0] else (),
            "objects": self._objects.with_agent(pos, int(b.removed[0])),
            "events": rules.EVENT_TUPLES[events],
            "outcome": rules.outcome_name(events, truncated),
            **self._level,
        }

    def set_state(self, agent: tuple[int, int], holding: bool = False) -> dict[str, Any]:
        """Put the agent on a cell of the current level's initial map; returns the new info.

        For analysis and tests (transition tables, value maps): ``holding``
        also takes the sword off the map, as if picked up. The step count
        starts again from 0.
        """
        if self.episode_index < 0:
            raise gym.error.ResetNeeded("call reset() before set_state()")
        r, c = (int(v) for v in agent)
        if not (0 <= r < self.height and 0 <= c < self.width):
            raise ValueError(f"agent {agent} is outside the {self.height}x{self.width} grid")
        pos = r * self.width + c
        if self._batch.level_cells[self._batch.slot[0], pos] == rules.WALL:
            raise ValueError(f"agent {agent} would stand in a wall")
        self._batch.place(0, pos, bool(holding))
        return self._info(0, False)

    # -- symbolic views and rendering ----------------------------------------

    def entity_grid(self) -> np.ndarray:
        """(H, W) entity codes of the current state; names in ``entity_names``."""
        return self._batch.entity_grid()[0]

    def render(self) -> np.ndarray | str | None:
        if self.render_mode == "rgb_array":
            return draw.rgw_frame(self.entity_grid(), bool(self._batch.holding[0]))
        if self.render_mode == "ansi":
            return draw.rgw_text(self.entity_grid(), bool(self._batch.holding[0]))
        return None
