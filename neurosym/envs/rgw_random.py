"""Procedural Relational-Grid-World levels (``rgw-random``), the thesis's stated future work.

Every level has random wall segments, an agent start, a terminal, a sword, one
or more enemies, a teleport pair, mountains and pits. A level is accepted only
when it is solvable: a search over (position, holding-sword) states must find
the sword without meeting an enemy while unarmed, then the terminal, never
through a pit. With probability ``enemy_on_route`` a level puts an enemy on
*every* shortest route from the start to the terminal (the agent has to plan
sword -> enemy -> terminal); the other levels keep the enemies off at least one
shortest route, as decoys (thesis section 4.1).

Levels are keyed by ``(seed, episode)`` through a counter-based hash (splitmix64)
instead of a stateful generator, so any batch of keys is generated at once with
array operations, and the same key always gives the same level whatever else
is generated beside it. Candidates that fail the checks are redrawn with the
next attempt number until every key has its level.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields
from typing import Any

import numpy as np

from neurosym.envs import rgw_rules as rules
from neurosym.envs.rgw import RGWEnv
from neurosym.envs.rgw_levels import LevelObjects, ObjectsCache
from neurosym.errors import ConfigError

UNREACHED = np.int32(1 << 30)


@dataclass(frozen=True)
class RandomLevelConfig:
    """Parameters of the level generator."""

    height: int = 10
    """rows of the grid"""
    width: int = 10
    """columns of the grid"""
    num_enemies: int = 1
    """enemies per level (the first one is the one placed on or off the route)"""
    enemy_on_route: float = 0.5
    """share of levels whose enemies lie on every shortest route to the terminal"""
    wall_segments: int = 6
    """straight wall segments per level"""
    max_wall_length: int = 5
    """longest wall segment"""
    num_mountains: int = 6
    """mountains per level (-0.1 on entering)"""
    num_pits: int = 2
    """pits per level (-1, end the episode)"""
    min_route_length: int = 4
    """shortest start-to-terminal route must be at least this many steps"""
    max_attempts: int = 500
    """candidates tried per level before giving up with an error"""

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name == "enemy_on_route":
                if not 0.0 <= float(value) <= 1.0:
                    raise ConfigError(f"enemy_on_route must be in [0, 1], got {value!r}")
                continue
            low = (
                3
                if f.name in ("height", "width")
                else 1
                if f.name in ("num_enemies", "max_wall_length", "max_attempts", "min_route_length")
                else 0
            )
            if not isinstance(value, int | np.integer) or value < low:
                raise ConfigError(f"{f.name} must be an integer >= {low}, got {value!r}")
        needed = 6 + self.num_enemies + self.num_mountains + self.num_pits
        if needed > self.height * self.width // 2:
            raise ConfigError(
                f"{needed} objects do not fit a {self.height}x{self.width} level with room to move; "
                "use fewer enemies, mountains or pits, or a larger grid"
            )


# -- counter-based random numbers ------------------------------------------------

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_M1 = np.uint64(0xBF58476D1CE4E5B9)
_M2 = np.uint64(0x94D049BB133111EB)


def mix64(x: np.ndarray) -> np.ndarray:
    """The splitmix64 output function on uint64 arrays (wrapping arithmetic)."""
    z = x + _GOLDEN
    z = (z ^ (z >> np.uint64(30))) * _M1
    z = (z ^ (z >> np.uint64(27))) * _M2
    return z ^ (z >> np.uint64(31))


def level_keys(seeds: np.ndarray, episodes: np.ndarray, attempt: int = -1) -> np.ndarray:
    """(B,) uint64 keys of (seed, episode, attempt); attempt -1 keys the level itself."""
    k = mix64(np.asarray(seeds, dtype=np.uint64))
    k = mix64(k ^ np.asarray(episodes).astype(np.uint64))
    return mix64(k ^ np.uint64(attempt & 0xFFFFFFFF))


def uniform(keys: np.ndarray, stream: int, count: int) -> np.ndarray:
    """(B, count) floats in [0, 1), independent per key, stream and index."""
    ctr = (np.uint64(stream) << np.uint64(32)) + np.arange(count, dtype=np.uint64)
    bits = mix64(keys[:, None] ^ mix64(ctr)[None, :])
    return (bits >> np.uint64(11)).astype(np.float64) * (1.0 / (1 << 53))


# -- search ----------------------------------------------------------------------


def _swap(flat: np.ndarray, i1: np.ndarray, i2: np.ndarray) -> None:
    """Exchange the entries at flat indices i1 and i2 (the two ends of each level's teleport)."""
    a = flat[i1]
    flat[i1] = flat[i2]
    flat[i2] = a


def _padded(x: np.ndarray, height: int, width: int) -> np.ndarray:
    """(B, N) bool -> flat (B * (H + 1) * (W + 1),) with a False guard row and column per level."""
    B = len(x)
    out = np.zeros((B, height + 1, width + 1), dtype=bool)
    out[:, :height, :width] = x.reshape(B, height, width)
    return out.reshape(-1)


def bfs(
    sources: np.ndarray,
    visit: np.ndarray,
    expand: np.ndarray,
    teleports: np.ndarray,
    height: int,
    width: int,
    backward: bool = False,
) -> np.ndarray:
    """Layered search over many levels at once: (B, N) steps from (or, backward, to) ``sources``.

    Forward: a step enters one of the four neighbours; entering a teleport end
    (``teleports`` (B, 2) cells) lands on the other end; a cell is entered when
    ``visit`` allows it and expanded further when ``expand`` allows it.
    Backward gives the steps needed to reach the source instead.

    All levels sit in one flat boolean array, each padded with a guard row and
    column that ``visit`` keeps False, so a layer is four shifted ORs over the
    whole batch plus a few masks: no per-level work, no gathers of neighbour lists.
    Unreached cells hold UNREACHED.
    """
    B, N = visit.shape
    W1 = width + 1
    P = (height + 1) * W1
    lvl = np.arange(B)

    def flat_index(cells: np.ndarray) -> np.ndarray:
        r, c = np.divmod(cells, width)
        return lvl * P + r * W1 + c

    i1, i2 = flat_index(teleports[:, 0]), flat_index(teleports[:, 1])
    visit_p = _padded(visit, height, width)
    expand_p = _padded(expand, height, width)
    visited = np.zeros(B * P, dtype=bool)
    visited[flat_index(sources)] = True
    dist = np.full(B * P, UNREACHED, dtype=np.int32)
    dist[visited] = 0
    front = visited.copy()
    d = 0
    while True:
        d += 1
        if backward:
            src = front  # a fresh array each layer, safe to modify
            _swap(src, i1, i2)  # reaching end 1 means entering end 2
        else:
            src = front & expand_p
        new = np.zeros_like(src)
        new[1:] = src[:-1]
        new[:-1] |= src[1:]
        new[W1:] |= src[:-W1]
        new[:-W1] |= src[W1:]
        if not backward:
            _swap(new, i1, i2)  # entering end 1 lands on end 2
        new &= visit_p
        new = new > visited
        if not new.any():
            return dist.reshape(B, height + 1, W1)[:, :height, :width].reshape(B, N)
        visited |= new
        np.copyto(dist, d, where=new)
        front = new


# -- generation ------------------------------------------------------------------


def _walls(cfg: RandomLevelConfig, keys: np.ndarray) -> np.ndarray:
    """(B, N) bool: random straight wall segments."""
    B, H, W, S, L = len(keys), cfg.height, cfg.width, cfg.wall_segments, cfg.max_wall_length
    wall = np.zeros((B, H * W), dtype=bool)
    if S == 0:
        return wall
    u = uniform(keys, 1, 4 * S).reshape(B, S, 4)
    r0 = (u[..., 0] * H).astype(np.intp)
    c0 = (u[..., 1] * W).astype(np.intp)
    horizontal = u[..., 2] < 0.5
    length = 1 + (u[..., 3] * L).astype(np.intp)
    k = np.arange(L)[None, None, :]
    rr = r0[..., None] + k * ~horizontal[..., None]  # (B, S, L)
    cc = c0[..., None] + k * horizontal[..., None]
    ok = (k < length[..., None]) & (rr < H) & (cc < W)
    b = np.broadcast_to(np.arange(B)[:, None, None], ok.shape)
    wall[b[ok], (rr * W + cc)[ok]] = True
    return wall


def _candidates(
    cfg: RandomLevelConfig, keys: np.ndarray, want_route: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One candidate level per key: (cells (B, N), starts (B,), accepted (B,))."""
    B, N = len(keys), cfg.height * cfg.width
    lvl = np.arange(B)
    wall = _walls(cfg, keys)
    # Distinct random free cells: terminal, start, sword, 2 teleports, mountains, pits, extra enemies.
    order = np.argsort(np.where(wall, 2.0, 0.0) + uniform(keys, 2, N), axis=1)
    n_fixed = 5 + cfg.num_mountains + cfg.num_pits + (cfg.num_enemies - 1)
    enough = (N - wall.sum(axis=1)) > n_fixed + 1
    terminal, start, sword = order[:, 0], order[:, 1], order[:, 2]
    cells = np.where(wall, rules.WALL, rules.EMPTY).astype(np.uint8)
    cells[lvl, terminal] = rules.TERMINAL
    cells[lvl, sword] = rules.SWORD
    cells[lvl[:, None], order[:, 3:5]] = rules.TELEPORT
    i = 5
    for code, count in (
        (rules.MOUNTAIN, cfg.num_mountains),
        (rules.PIT, cfg.num_pits),
        (rules.ENEMY, cfg.num_enemies - 1),
    ):
        cells[lvl[:, None], order[:, i : i + count]] = code
        i += count
    cells[~enough] = rules.EMPTY  # keep the arrays valid; these candidates are rejected
    cells[~enough, 0] = rules.TERMINAL

    # Shortest routes with enemies passable: forward from the start, backward from the terminal.
    H, W = cfg.height, cfg.width
    tele = np.where(enough[:, None], order[:, 3:5], 0)
    standable = (cells != rules.WALL) & (cells != rules.PIT)
    is_terminal = cells == rules.TERMINAL
    d_start = bfs(start, standable, ~is_terminal, tele, H, W)
    route = d_start[lvl, terminal]
    d_term = bfs(terminal, standable & ~is_terminal, standable, tele, H, W, backward=True)

    # Cells on every shortest route: on some shortest route and alone in their layer.
    on_route = (d_start + d_term == route[:, None]) & (route[:, None] < UNREACHED)
    layer = np.where(on_route, d_start, 0)
    counts = np.bincount((lvl[:, None] * (N + 1) + layer)[on_route], minlength=B * (N + 1)).reshape(
        B, N + 1
    )
    choke = on_route & (np.take_along_axis(counts, layer, axis=1) == 1)
    free = cells == rules.EMPTY
    free[lvl, start] = False
    # The first enemy: on a chokepoint when the level wants it on the route, elsewhere otherwise.
    allowed = np.where(want_route[:, None], choke, ~choke) & free
    pick = np.where(allowed, uniform(keys, 3, N), 2.0)
    enemy = np.argmin(pick, axis=1)
    placed = allowed[lvl, enemy]
    cells[lvl[placed], enemy[placed]] = rules.ENEMY

    # With enemies blocked: is the terminal further (enemy on every route)? Is the sword reachable?
    no_enemy = standable & (cells != rules.ENEMY)
    d_safe = bfs(start, no_enemy, ~is_terminal, tele, H, W)
    enemy_on_route = d_safe[lvl, terminal] > route
    solvable = (d_safe[lvl, sword] < UNREACHED) & (d_term[lvl, sword] < UNREACHED)
    accepted = (
        enough
        & placed
        & solvable
        & (route >= cfg.min_route_length)
        & (route < UNREACHED)
        & (enemy_on_route == want_route)
    )
    return cells, start, accepted


def generate_levels(
    cfg: RandomLevelConfig, seeds: np.ndarray, episodes: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(B, N) uint8 cells and (B,) starts of the levels keyed by (seed, episode)."""
    seeds = np.atleast_1d(np.asarray(seeds, dtype=np.uint64))
    episodes = np.atleast_1d(np.asarray(episodes, dtype=np.int64))
    B, N = len(seeds), cfg.height * cfg.width
    want_route = uniform(level_keys(seeds, episodes), 0, 1)[:, 0] < cfg.enemy_on_route
    cells = np.empty((B, N), dtype=np.uint8)
    starts = np.empty(B, dtype=np.intp)
    pending = np.arange(B)
    for attempt in range(cfg.max_attempts):
        keys = level_keys(seeds[pending], episodes[pending], attempt)
        c, s, ok = _candidates(cfg, keys, want_route[pending])
        cells[pending[ok]], starts[pending[ok]] = c[ok], s[ok]
        pending = pending[~ok]
        if not len(pending):
            return cells, starts
    raise ConfigError(
        f"no solvable level found in {cfg.max_attempts} attempts for {len(pending)} of {B} keys "
        f"with {asdict(cfg)}; use fewer walls, pits or enemies"
    )


class LevelRing:
    """Levels generated ahead, per environment, so that generation runs in large batches.

    Generating one level costs tens of microseconds inside a large batch but a
    few milliseconds alone (each search layer is a fixed number of array
    operations). When an environment asks for a level that is not buffered,
    every environment gets its next ``window`` levels generated in one batch
    (only those not already buffered). Levels depend only on their key, so
    buffering never changes which level an episode gets.
    """

    def __init__(
        self,
        cfg: RandomLevelConfig,
        n: int,
        first_batch: int = 2048,
        max_buffered: int = 16384,
        depth: int = 16,
    ) -> None:
        self.cfg, self.n, self.depth = cfg, n, depth
        # Levels kept ahead per env: few at first (a quick first reset), doubling per
        # refill up to `cap`, so that at most about max_buffered levels wait in all.
        self.cap = int(np.clip(max_buffered // n, 1, depth))
        self.first_window = self.window = int(np.clip(first_batch // n, 1, self.cap))
        N = cfg.height * cfg.width
        self.cells = np.zeros((n, depth, N), dtype=np.uint8)
        self.starts = np.zeros((n, depth), dtype=np.intp)
        self.key_ep = np.full((n, depth), -1, dtype=np.int64)
        self.key_seed = np.zeros((n, depth), dtype=np.uint64)
        self.seeds = np.zeros(n, dtype=np.uint64)
        self.next_ep = np.zeros(n, dtype=np.int64)  # the episode each env asks for next

    def take(
        self, rows: np.ndarray, seeds: np.ndarray, episodes: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Cells (k, N) and starts (k,) of the levels (seeds, episodes) for envs ``rows``."""
        rows = np.asarray(rows, dtype=np.intp)
        seeds = np.asarray(seeds, dtype=np.uint64)
        episodes = np.asarray(episodes, dtype=np.int64)
        slot = episodes % self.depth
        hit = (self.key_ep[rows, slot] == episodes) & (self.key_seed[rows, slot] == seeds)
        if (self.seeds[rows] != seeds).any():
            self.window = self.first_window  # new seeds: start small again
        self.seeds[rows] = seeds
        self.next_ep[rows] = episodes
        if not hit.all():
            self._refill()
        self.next_ep[rows] = episodes + 1
        return self.cells[rows, slot], self.starts[rows, slot]

    def _refill(self) -> None:
        eps = self.next_ep[:, None] + np.arange(self.window)  # (n, window)
        slot = eps % self.depth
        env = np.broadcast_to(np.arange(self.n)[:, None], eps.shape)
        have = (self.key_ep[env, slot] == eps) & (self.key_seed[env, slot] == self.seeds[:, None])
        need_env, need_k = np.nonzero(~have)
        need_ep, need_slot = eps[need_env, need_k], slot[need_env, need_k]
        cells, starts = generate_levels(self.cfg, self.seeds[need_env], need_ep)
        self.cells[need_env, need_slot] = cells
        self.starts[need_env, need_slot] = starts
        self.key_ep[need_env, need_slot] = need_ep
        self.key_seed[need_env, need_slot] = self.seeds[need_env]
        self.window = min(self.cap, self.window * 2)


class RandomLevels:
    """A level source (rgw_levels.LevelSource) that generates a new level per episode."""

    per_episode = True

    def __init__(self, cfg: RandomLevelConfig) -> None:
        self.cfg = cfg
        self.name = "random"
        self.height, self.width = cfg.height, cfg.width
        self._cache = ObjectsCache()

    def levels(self, seeds: np.ndarray, episodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return generate_levels(self.cfg, seeds, episodes)

    def ring(self, n: int) -> LevelRing:
        """A LevelRing for an env of n sub-envs."""
        return LevelRing(self.cfg, n)

    def objects(self, seed: int, episode: int) -> LevelObjects:
        key = (int(seed), int(episode))
        got = self._cache.get(key)
        if got is None:
            cells, _ = generate_levels(self.cfg, np.array([seed]), np.array([episode]))
            got = LevelObjects(cells[0], self.width)
            self._cache.put(key, got)
        return got


def config_from_kwargs(kwargs: dict[str, Any]) -> RandomLevelConfig:
    """A RandomLevelConfig from keyword arguments, refusing unknown names."""
    known = {f.name for f in fields(RandomLevelConfig)}
    unknown = sorted(set(kwargs) - known)
    if unknown:
        raise ConfigError(
            f"unknown rgw-random parameter {unknown[0]!r}; expected one of {', '.join(sorted(known))}"
        )
    return RandomLevelConfig(**kwargs)


class RGWRandomEnv(RGWEnv):
    """Relational-Grid-World on procedural levels: a new solvable level every episode.

    Rules, actions, observations, rewards, termination and info are those of
    :class:`~neurosym.envs.rgw.RGWEnv` (default or ``classic`` rules). The
    level of an episode is decided by the reset seed and the number of resets
    since it: ``reset(seed=s)`` plays level (s, 0), each later ``reset()`` the
    next one. The generator's parameters are those of :class:`RandomLevelConfig`.

    ## Registered Configurations
    * ``neurosym/RGWRandom-v0`` (``rgw-random``): 10 x 10, one enemy, on every
      shortest route in half of the levels.
    """

    def __init__(
        self,
        *,
        classic: bool = False,
        obs_mode: str = "onehot",
        max_steps: int | None = 100,
        render_mode: str | None = None,
        **level_kwargs: Any,
    ) -> None:
        self.level_config = config_from_kwargs(level_kwargs)
        self._setup(RandomLevels(self.level_config), classic, obs_mode, max_steps, render_mode)
