"""Batched Relational-Grid-World: n episodes stepped with array operations.

Runs the same :class:`~neurosym.envs.rgw_rules.RGWBatch` as the single env, so
the two agree step for step (tests/envs/test_rgw_vector.py runs them in lockstep).
Autoreset follows gymnasium's next-step mode: the step after an episode ends
ignores that sub-env's action and returns the first observation of its next
episode with reward 0.

``info`` is a dict of arrays, cheap to build every step:

* ``pos``: (n,) row-major cell of the agent; ``holding``: (n,) 1 with the sword;
* ``events``: (n,) bitmask over ``rgw_rules.EVENT_NAMES``; ``truncated``: (n,)
  (``rgw_rules.outcome_codes(events, truncated)`` gives the outcomes);
* ``removed``: (n,) bitmask of swords and enemies gone from the map;
* ``episode_id``: (n,) episodes begun by each sub-env since the seeded reset;
  ``seed``: (n,) level seeds (procedural levels only);
* ``optimal_return`` (n,) float, ``guarded``, ``needs_teleport``,
  ``hazard_on_route`` (n,) bool: each sub-env's current level (rgw_levels.LevelInfo);
* on an autoreset step, ``final_info`` (the previous step's info, which
  described the last state of the old episode) and ``_final_info`` (mask).

``decode_info(info, i)`` turns sub-env i's entries into the dict the single
env gives.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any, ClassVar

import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from neurosym.envs import render as draw
from neurosym.envs import rgw_rules as rules
from neurosym.envs.rgw import check_options, observation_space
from neurosym.envs.rgw_levels import (
    LEVEL_KEYS,
    FixedLevel,
    LevelInfo,
    LevelObjects,
    LevelSource,
    ObjectsCache,
    batch_for,
)
from neurosym.envs.rgw_maps import load_map
from neurosym.envs.rgw_random import RandomLevels, config_from_kwargs, random_enemy
from neurosym.envs.rgw_solver import Rules
from neurosym.errors import ConfigError


class RGWVectorEnv(VectorEnv):
    """n Relational-Grid-World environments (see RGWEnv) stepped together.

    ``RGWVectorEnv(num_envs, seed=None, map="rgw2", classic=False,
    obs_mode="onehot", max_steps=100, render_mode=None, enemy="pass", copy=True)``.
    ``seed`` is used by the first ``reset()`` when that gets none; sub-env i
    is seeded ``seed + i``. ``copy=False`` returns the internal observation
    buffer itself, which the next step overwrites (faster; copy it if you keep it).
    """

    metadata: ClassVar[dict[str, Any]] = {
        "render_modes": ["rgb_array", "ansi"],
        "render_fps": 4,
        "autoreset_mode": AutoresetMode.NEXT_STEP,
    }
    entity_names: tuple[str, ...] = rules.ENTITY_NAMES

    def __init__(
        self,
        num_envs: int,
        seed: int | None = None,
        map: str | os.PathLike[str] = "rgw2",
        *,
        classic: bool = False,
        obs_mode: str = "onehot",
        max_steps: int | None = 100,
        render_mode: str | None = None,
        enemy: str = "pass",
        copy: bool = True,
    ) -> None:
        check_options(obs_mode, max_steps, render_mode, enemy, classic)
        self._setup(
            FixedLevel(load_map(map), Rules(bool(classic), enemy, max_steps)),
            num_envs,
            seed,
            classic,
            obs_mode,
            max_steps,
            render_mode,
            copy,
            enemy,
        )

    def _setup(
        self,
        source: LevelSource,
        num_envs: int,
        seed: int | None,
        classic: bool,
        obs_mode: str,
        max_steps: int | None,
        render_mode: str | None,
        copy: bool,
        enemy: str,
    ) -> None:
        if not isinstance(num_envs, int | np.integer) or num_envs < 1:
            raise ConfigError(f"num_envs must be a positive integer, got {num_envs!r}")
        check_options(obs_mode, max_steps, render_mode, enemy, classic)
        self.source = source
        self.enemy = enemy
        self.num_envs = int(num_envs)
        self.classic, self.obs_mode, self.max_steps = bool(classic), obs_mode, max_steps
        self.render_mode = render_mode
        self.copy = copy
        self.height, self.width = source.height, source.width
        self.single_observation_space = observation_space(obs_mode, self.height, self.width)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.single_action_space = spaces.Discrete(4)
        self.action_space = spaces.MultiDiscrete(np.full(self.num_envs, 4))
        self.obs_scale = 1.0 if obs_mode == "onehot" else 1 / 255
        self._batch = batch_for(
            source,
            self.num_envs,
            classic=self.classic,
            obs_mode=obs_mode,
            max_steps=max_steps,
            enemy=enemy,
        )
        self._first_seed = seed
        self._seeds: np.ndarray | None = None
        self._episodes = np.zeros(self.num_envs, dtype=np.int64)
        self._pending: np.ndarray | None = None  # sub-envs to autoreset on the next step
        self._last_info: dict[str, Any] | None = None
        self._ring = source.ring(self.num_envs) if source.per_episode else None
        # Each sub-env's level description, (n,) arrays replaced (never written) on new levels.
        if source.per_episode:  # set by reset()
            n = self.num_envs
            self._level = LevelInfo(np.zeros(n), *(np.zeros(n, dtype=bool) for _ in range(3)))
        else:
            zeros = np.zeros(self.num_envs, dtype=np.int64)
            self._level = source.levels(zeros, zeros)[2]
        # Named objects of procedural levels by (seed, episode), built on first decode.
        self._objects = ObjectsCache(size=max(256, 4 * self.num_envs))

    # -- gymnasium vector API -------------------------------------------------

    def reset(
        self,
        *,
        seed: int | Sequence[int] | None = None,
        options: dict[str, Any] | None = None,
    ) -> tuple[np.ndarray, dict[str, Any]]:
        if options and options.get("reset_mask") is not None:
            raise ConfigError(
                "RGWVectorEnv resets all sub-envs at once; reset_mask is not supported "
                "(each sub-env autoresets itself on the step after its episode ends)"
            )
        if seed is None and self._seeds is None:
            seed = self._first_seed
        n = self.num_envs
        if seed is not None:
            if isinstance(seed, int | np.integer):
                super().reset(seed=int(seed))
                seeds = np.uint64(seed) + np.arange(n, dtype=np.uint64)
            else:
                seeds = np.asarray(seed, dtype=np.uint64)
                if seeds.shape != (n,):
                    raise ValueError(f"expected one seed or {n} seeds, got {len(seeds)}")
                super().reset(seed=int(seeds[0]))
            self._seeds, self._episodes = seeds, np.zeros(n, dtype=np.int64)
        elif self._seeds is None:
            base = np.uint64(self.np_random.integers(2**63))
            self._seeds, self._episodes = (
                base + np.arange(n, dtype=np.uint64),
                np.zeros(n, np.int64),
            )
        else:
            self._episodes = self._episodes + 1
        if self._ring is not None:
            cells, starts, level = self._ring.take(np.arange(n), self._seeds, self._episodes)
            self._batch.set_levels(np.arange(n), cells, starts)
            self._level = level
        self._batch.reset_rows(None)
        self._pending = None
        info = self._info(np.zeros(n, dtype=np.uint16), np.zeros(n, dtype=bool))
        self._last_info = info
        return self._observation(), info

    def step(
        self, actions: Any
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        if self._seeds is None:
            raise RuntimeError("call reset() before step()")
        b = self._batch
        res = b.step(actions)
        rows = self._pending
        if rows is not None:
            self._episodes = self._episodes.copy()
            self._episodes[rows] += 1
            if self._ring is not None:
                cells, starts, level = self._ring.take(
                    rows, self._seeds[rows], self._episodes[rows]
                )
                b.set_levels(rows, cells, starts)
                self._level = LevelInfo(*(a.copy() for a in self._level))
                for mine, new in zip(self._level, level, strict=True):
                    mine[rows] = new
            b.reset_rows(rows)
            res.reward[rows] = 0.0
            res.terminated[rows] = False
            res.truncated[rows] = False
            res.events[rows] = 0
        info = self._info(res.events, res.truncated)
        if rows is not None:
            mask = np.zeros(self.num_envs, dtype=bool)
            mask[rows] = True
            info["final_info"] = self._last_info
            info["_final_info"] = mask
        done = res.terminated | res.truncated
        self._pending = np.flatnonzero(done) if done.any() else None
        self._last_info = info
        return self._observation(), res.reward, res.terminated, res.truncated, info

    def _observation(self) -> np.ndarray:
        return self._batch.obs.copy() if self.copy else self._batch.obs

    def _info(self, events: np.ndarray, truncated: np.ndarray) -> dict[str, Any]:
        b = self._batch
        info = {
            "pos": b.pos,
            "holding": b.holding,
            "events": events,
            "truncated": truncated,
            "removed": b.removed,
            "episode_id": self._episodes,
            **self._level._asdict(),
        }
        if self.source.per_episode:
            info["seed"] = self._seeds
        return info

    def decode_info(self, info: dict[str, Any], i: int) -> dict[str, Any]:
        """The info dict the single env gives, for sub-env ``i`` of a batched info."""
        pos = int(info["pos"][i])
        if self.source.per_episode:
            objects = self._level_objects(i, int(info["seed"][i]), int(info["episode_id"][i]))
        else:
            objects = self.source.objects(0, 0)
        return {
            "agent": divmod(pos, self.width),
            "holding": ("sword",) if info["holding"][i] else (),
            "objects": objects.with_agent(pos, int(info["removed"][i])),
            "events": rules.EVENT_TUPLES[int(info["events"][i])],
            "outcome": self.episode_outcome(info, i),
            **LevelInfo(*(info[k] for k in LEVEL_KEYS)).row(i),
        }

    def episode_outcome(self, info: dict[str, Any], i: int) -> str | None:
        """``decode_info(info, i)["outcome"]`` without building the rest of that dict."""
        return rules.outcome_name(int(info["events"][i]), bool(info["truncated"][i]))

    def _level_objects(self, i: int, seed: int, episode: int) -> LevelObjects:
        """Objects of level (seed, episode): from sub-env i's cells while it plays it, else regenerated."""
        key = (seed, episode)
        objects = self._objects.get(key)
        if objects is None:
            current = (
                self._seeds is not None and (int(self._seeds[i]), int(self._episodes[i])) == key
            )
            if current:
                objects = LevelObjects(self._batch.level_cells[self._batch.slot[i]], self.width)
            else:
                objects = self.source.objects(seed, episode)
            self._objects.put(key, objects)
        return objects

    # -- symbolic views and rendering ----------------------------------------

    @property
    def rules(self) -> Rules:
        """The rule options the levels are played and searched by (rgw_solver.Rules)."""
        return self.source.rules

    def current_levels(self) -> tuple[np.ndarray, np.ndarray]:
        """(n, H * W) uint8 initial cells and (n,) start cells of each sub-env's level.

        For searches over the levels being played (rgw_solver), e.g. what a
        route without the sword earns in evaluation.
        """
        b = self._batch
        slots = b.slot
        return b.level_cells[slots].copy(), b.level_start[slots].copy()

    def agent_states(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(n,) agent cells, (n,) removed-objects bitmasks and (n,) steps taken this episode.

        With :meth:`current_levels`, the state a search needs (rgw_solver.Planner).
        """
        b = self._batch
        return b.pos.copy(), b.removed.copy(), b.t.copy()

    def entity_grid(self) -> np.ndarray:
        """(n, H, W) entity codes of the current states; names in ``entity_names``."""
        return self._batch.entity_grid()

    def render(self) -> tuple[Any, ...] | None:
        if self.render_mode is None:
            return None
        grids, holding = self.entity_grid(), self._batch.holding
        if self.render_mode == "rgb_array":
            return tuple(draw.rgw_frame(g, bool(h)) for g, h in zip(grids, holding, strict=True))
        return tuple(draw.rgw_text(g, bool(h)) for g, h in zip(grids, holding, strict=True))


class RGWRandomVectorEnv(RGWVectorEnv):
    """n Relational-Grid-World environments on procedural levels (see RGWRandomEnv).

    Sub-env i plays the levels (seed + i, 0), (seed + i, 1), ... exactly as a
    single RGWRandomEnv reset with seed + i and then reset without a seed.
    """

    def __init__(
        self,
        num_envs: int,
        seed: int | None = None,
        *,
        classic: bool = False,
        obs_mode: str = "onehot",
        max_steps: int | None = 100,
        render_mode: str | None = None,
        enemy: str | None = None,
        copy: bool = True,
        **level_kwargs: Any,
    ) -> None:
        self.level_config = config_from_kwargs(level_kwargs)
        enemy = random_enemy(enemy, classic)
        check_options(obs_mode, max_steps, render_mode, enemy, classic)
        self._setup(
            RandomLevels(self.level_config, Rules(bool(classic), enemy, max_steps)),
            num_envs,
            seed,
            classic,
            obs_mode,
            max_steps,
            render_mode,
            copy,
            enemy,
        )
