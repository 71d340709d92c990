"""Procedural Relational-Grid-World levels (``rgw-random``), the thesis's stated future work.

On one fixed map an agent can solve the level by where things are; levels that
change every episode make it relate the sword, the enemy and the terminal. Every
level has random wall segments, an agent start, a terminal, a sword, one or more
enemies, a teleport pair, mountains and pits, and the terminal sits in a pocket:
walls on all its sides but one, the *door*. Each level draws its kind from
independent shares (:class:`RandomLevelConfig`):

* ``guarded_share`` (0.5): the first enemy stands in the door, so every route to
  the terminal meets an enemy. With a blocking or ending enemy (rgw-random's
  default is ``enemy="block"``) the terminal can only be reached with the sword.
  The other levels keep the door empty and the enemy elsewhere, off at least
  one route: a decoy. The sword is not needed there; taking it is a detour
  (steps, and return wherever the way to it crosses mountains).
* ``teleport_share`` (0.25): a full wall line splits the grid; the start and
  the sword lie on one side, the terminal on the other, and the teleport's two
  ends one on each side: every route goes through the teleport.
* ``hazard_share`` (0.3): mountains and pits are put on the shortest routes
  first, so every shortest route crosses one (pay -0.1 per mountain or detour;
  a pit ends the episode); the other levels keep them off the shortest routes.

A candidate is accepted only when its measured kinds
(:func:`neurosym.envs.rgw_solver.level_kinds`) are the ones it was drawn for and
the exact search over the env's own rules (:func:`~neurosym.envs.rgw_solver.solve_levels`:
cell x sword held x enemies left, teleports, mountains' costs, pits, the enemy
mode, the step limit) finds a route to the terminal; that search also gives the
level's optimal return, which the env reports in ``info["optimal_return"]`` and
the kinds in ``info["guarded"]``, ``info["needs_teleport"]`` and
``info["hazard_on_route"]``.

Levels are keyed by ``(seed, episode)`` through a counter-based hash (splitmix64)
instead of a stateful generator, so any batch of keys is generated at once with
array operations, and the same key always gives the same level whatever else
is generated beside it (and the same rules: the optimal return and the
solvability check depend on them). Candidates that fail the checks are redrawn
with the next attempt number until every key has its level. Evaluation seeds
are fresh levels as long as they differ from the training seeds: the level is a
function of the reset seed and the number of resets since.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields
from typing import Any

import numpy as np

from neurosym.envs import rgw_rules as rules
from neurosym.envs.rgw import RGWEnv, check_options
from neurosym.envs.rgw_levels import LevelInfo, LevelObjects, ObjectsCache
from neurosym.envs.rgw_solver import (
    UNREACHED,
    Rules,
    bfs,
    kinds_and_route,
    solve_levels,
)
from neurosym.errors import ConfigError

SHARES = ("guarded_share", "teleport_share", "hazard_share")

RANDOM_RULES = Rules(enemy="block")
"""rgw-random's default rules: a blocking enemy, 100 steps"""

EDITS = ("remove_sword", "remove_enemy", "swap_sword_enemy")
"""the controlled changes RandomLevelConfig.edit makes to generated levels"""

MAX_ENEMIES = 3
"""enemies per level at most: the optimal-return search tracks which are left (2**(1 + E) masks)"""


@dataclass(frozen=True)
class RandomLevelConfig:
    """Parameters of the level generator."""

    height: int = 10
    """rows of the grid"""
    width: int = 10
    """columns of the grid"""
    num_enemies: int = 1
    """enemies per level, 1 to 3 (the first one guards the door or is the decoy)"""
    guarded_share: float = 0.5
    """share of levels whose terminal is guarded: an enemy in the only door"""
    teleport_share: float = 0.25
    """share of levels split by a wall line that only the teleport crosses"""
    hazard_share: float = 0.3
    """share of levels whose every shortest route crosses a mountain or a pit"""
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
    edit: str | None = None
    """a controlled change made to every generated level after it was drawn, so that level
    (seed, k) is the unedited level (seed, k) but for that one change (``neurosym
    intervene``): "remove_sword", "remove_enemy" (every enemy) or "swap_sword_enemy" (one
    enemy only); the level's info is then the edited level's own (it may be unsolvable)"""

    def __post_init__(self) -> None:
        if self.edit is not None and self.edit not in EDITS:
            raise ConfigError(f"unknown edit {self.edit!r}; expected one of {', '.join(EDITS)}")
        if self.edit == "swap_sword_enemy" and self.num_enemies != 1:
            raise ConfigError("edit swap_sword_enemy needs num_enemies=1 (which enemy to swap?)")
        for f in fields(self):
            if f.name == "edit":
                continue
            value = getattr(self, f.name)
            if f.name in SHARES:
                if not isinstance(value, int | float) or not 0.0 <= float(value) <= 1.0:
                    raise ConfigError(f"{f.name} must be a number in [0, 1], got {value!r}")
                continue
            low = (
                5
                if f.name in ("height", "width")
                else 1
                if f.name in ("num_enemies", "max_wall_length", "max_attempts", "min_route_length")
                else 0
            )
            if not isinstance(value, int | np.integer) or value < low:
                raise ConfigError(f"{f.name} must be an integer >= {low}, got {value!r}")
        if self.num_enemies > MAX_ENEMIES:
            raise ConfigError(
                f"num_enemies must be at most {MAX_ENEMIES} (the optimal-return search tracks "
                f"which enemies are left), got {self.num_enemies}"
            )
        needed = 8 + self.num_enemies + self.num_mountains + self.num_pits
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


def _pick(allowed: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One random allowed cell per level: (B,) cell and (B,) whether there was one."""
    cell = np.argmin(np.where(allowed, u, 2.0), axis=1)
    return cell, allowed[np.arange(len(allowed)), cell]


def _candidates(
    cfg: RandomLevelConfig, keys: np.ndarray, want: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One candidate level per key, built to be of the kinds ``want`` (B, 3) asks for.

    Returns (cells (B, N), starts (B,), ok (B,)): ``ok`` is False where the
    construction ran out of room; the kinds are measured afterwards.
    """
    B, H, W, N = len(keys), cfg.height, cfg.width, cfg.height * cfg.width
    lvl = np.arange(B)
    want_guard, want_tele, want_hazard = want[:, 0], want[:, 1], want[:, 2]
    wall = _walls(cfg, keys)
    row, col = np.divmod(np.arange(N), W)

    # Teleport levels: a full wall line (row or column 2 .. size-3) splits the grid;
    # side A (start, sword, one teleport end) and side B (terminal, the other end).
    u = uniform(keys, 4, 3)
    across = u[:, 0] < 0.5  # a horizontal line
    size = np.where(across, H, W)
    line = 2 + (u[:, 1] * (size - 4)).astype(np.intp)
    coord = np.where(across[:, None], row[None, :], col[None, :])  # (B, N)
    wall |= (coord == line[:, None]) & want_tele[:, None]
    flip = (u[:, 2] < 0.5)[:, None]
    side_a = np.where(want_tele[:, None], (coord < line[:, None]) ^ flip, True)
    side_b = np.where(want_tele[:, None], (coord > line[:, None]) ^ flip, True)

    # The terminal in a pocket: walls on every side but one, the door.
    free = ~wall
    terminal, ok = _pick(free & side_b, uniform(keys, 5, N))
    target, border = rules.cell_geometry(H, W)  # (4, N) each
    nb = target[:, terminal].T  # (B, 4) neighbour cells
    open_nb = ~border[:, terminal].T & free[lvl[:, None], nb]
    door_k = np.argmin(np.where(open_nb, uniform(keys, 6, 4), 2.0), axis=1)
    ok &= open_nb[lvl, door_k]
    door = nb[lvl, door_k]
    seal = open_nb.copy()
    seal[lvl, door_k] = False
    for k in range(4):
        wall[lvl[seal[:, k]], nb[seal[:, k], k]] = True
    free = ~wall
    free[lvl, terminal] = False
    free[lvl, door] = False

    # Start, sword and teleport ends (side A, side A, one end per side).
    picks = []
    for stream, region in ((7, side_a), (8, side_a), (9, side_a), (10, side_b)):
        cell, got = _pick(free & region, uniform(keys, stream, N))
        ok &= got
        free[lvl, cell] = False
        picks.append(cell)
    start, sword, tele_a, tele_b = picks

    cells = np.where(wall, rules.WALL, rules.EMPTY).astype(np.uint8)
    cells[lvl, terminal] = rules.TERMINAL
    cells[lvl, sword] = rules.SWORD
    cells[lvl, tele_a] = rules.TELEPORT
    cells[lvl, tele_b] = rules.TELEPORT

    # The first enemy: in the door (guarded) or on a random free cell (decoy).
    decoy, got = _pick(free, uniform(keys, 11, N))
    enemy = np.where(want_guard, door, decoy)
    ok &= want_guard | got
    cells[lvl, enemy] = rules.ENEMY
    free[lvl, enemy] = False

    # Mountains and pits: on the shortest routes first (hazard levels) or last.
    teleports = np.stack([tele_a, tele_b], axis=1)
    open_ = cells != rules.WALL
    is_terminal = cells == rules.TERMINAL
    d_start = bfs(start, open_, ~is_terminal, teleports, H, W)
    d_term = bfs(terminal, open_ & ~is_terminal, open_, teleports, H, W, backward=True)
    route = d_start[lvl, terminal]
    on_route = (d_start + d_term == route[:, None]) & (route[:, None] < UNREACHED)
    bias = np.where(want_hazard[:, None], -1.0, 1.0) * on_route
    score = np.where(free, uniform(keys, 12, N) + bias, 9.0)
    order = np.argsort(score, axis=1)
    n_haz = cfg.num_mountains + cfg.num_pits
    extra = cfg.num_enemies - 1
    ok &= free.sum(axis=1) > n_haz + extra
    cells[lvl[:, None], order[:, : cfg.num_mountains]] = rules.MOUNTAIN
    cells[lvl[:, None], order[:, cfg.num_mountains : n_haz]] = rules.PIT
    if extra:
        rest = np.where(free, uniform(keys, 13, N), 9.0)
        rest[lvl[:, None], order[:, :n_haz]] = 9.0
        cells[lvl[:, None], np.argsort(rest, axis=1)[:, :extra]] = rules.ENEMY
    cells[~ok] = rules.EMPTY  # keep the arrays valid; these candidates are rejected
    cells[~ok, 0] = rules.TERMINAL
    start = np.where(ok, start, 1)
    return cells, start, ok


def generate_levels(
    cfg: RandomLevelConfig,
    seeds: np.ndarray,
    episodes: np.ndarray,
    rules_: Rules = RANDOM_RULES,
) -> tuple[np.ndarray, np.ndarray, LevelInfo]:
    """(B, N) uint8 cells, (B,) starts and the LevelInfo of the levels keyed by (seed, episode).

    ``rules_`` are the rules the levels will be played by: a level is accepted
    only when a route reaches its terminal under them within the step limit,
    and its optimal return is computed under them.
    """
    seeds = np.atleast_1d(np.asarray(seeds, dtype=np.uint64))
    episodes = np.atleast_1d(np.asarray(episodes, dtype=np.int64))
    B, H, W = len(seeds), cfg.height, cfg.width
    shares = np.array([cfg.guarded_share, cfg.teleport_share, cfg.hazard_share])
    want = uniform(level_keys(seeds, episodes), 0, 3) < shares  # (B, 3)
    cells = np.empty((B, H * W), dtype=np.uint8)
    starts = np.empty(B, dtype=np.intp)
    best = np.empty(B)
    kinds = np.empty((B, 3), dtype=bool)
    pending = np.arange(B)
    for attempt in range(cfg.max_attempts):
        keys = level_keys(seeds[pending], episodes[pending], attempt)
        c, s, ok = _candidates(cfg, keys, want[pending])
        kinds_c, route = kinds_and_route(c, s, H, W)
        k = np.stack(kinds_c, axis=1)  # (b, 3)
        ok &= (k == want[pending]).all(axis=1) & (route >= cfg.min_route_length)
        idx = np.flatnonzero(ok)
        if len(idx):
            sol = solve_levels(c[idx], s[idx], H, W, rules_)
            ok[idx] = sol.solvable
            best_ok = sol.optimal_return[sol.solvable]
        else:
            best_ok = np.empty(0)
        done = pending[ok]
        cells[done], starts[done], kinds[done], best[done] = c[ok], s[ok], k[ok], best_ok
        pending = pending[~ok]
        if not len(pending):
            if cfg.edit is not None:
                return edited_levels(cfg, cells, starts, rules_)
            info = LevelInfo(best, kinds[:, 0], kinds[:, 1], kinds[:, 2])
            return cells, starts, info
    raise ConfigError(
        f"no solvable level found in {cfg.max_attempts} attempts for {len(pending)} of {B} keys "
        f"with {asdict(cfg)}; use fewer walls, pits or enemies"
    )


def edit_cells(cells: np.ndarray, edit: str) -> np.ndarray:
    """A copy of (B, N) level cells with ``edit`` (one of EDITS) made to every level."""
    out = cells.copy()
    sword, enemy = cells == rules.SWORD, cells == rules.ENEMY
    if edit in ("remove_sword", "remove_enemy"):
        out[sword if edit == "remove_sword" else enemy] = rules.EMPTY
    elif edit == "swap_sword_enemy":
        out[sword], out[enemy] = rules.ENEMY, rules.SWORD
    else:
        raise ConfigError(f"unknown edit {edit!r}; expected one of {', '.join(EDITS)}")
    return out


def edited_levels(
    cfg: RandomLevelConfig, cells: np.ndarray, starts: np.ndarray, rules_: Rules
) -> tuple[np.ndarray, np.ndarray, LevelInfo]:
    """The accepted levels with ``cfg.edit`` made, and the edited levels' own info."""
    cells = edit_cells(cells, str(cfg.edit))
    kinds, _ = kinds_and_route(cells, starts, cfg.height, cfg.width)
    sol = solve_levels(cells, starts, cfg.height, cfg.width, rules_)
    best = np.where(sol.solvable, sol.optimal_return, np.nan)
    return (
        cells,
        starts,
        LevelInfo(best, kinds.guarded, kinds.needs_teleport, kinds.hazard_on_route),
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
        rules_: Rules,
        first_batch: int = 2048,
        max_buffered: int = 16384,
        depth: int = 16,
    ) -> None:
        self.cfg, self.n, self.depth, self.rules = cfg, n, depth, rules_
        # Levels kept ahead per env: few at first (a quick first reset), doubling per
        # refill up to `cap`, so that at most about max_buffered levels wait in all.
        self.cap = int(np.clip(max_buffered // n, 1, depth))
        self.first_window = self.window = int(np.clip(first_batch // n, 1, self.cap))
        N = cfg.height * cfg.width
        self.cells = np.zeros((n, depth, N), dtype=np.uint8)
        self.starts = np.zeros((n, depth), dtype=np.intp)
        self.info = LevelInfo(
            np.zeros((n, depth)), *(np.zeros((n, depth), dtype=bool) for _ in range(3))
        )
        self.key_ep = np.full((n, depth), -1, dtype=np.int64)
        self.key_seed = np.zeros((n, depth), dtype=np.uint64)
        self.seeds = np.zeros(n, dtype=np.uint64)
        self.next_ep = np.zeros(n, dtype=np.int64)  # the episode each env asks for next

    def take(
        self, rows: np.ndarray, seeds: np.ndarray, episodes: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, LevelInfo]:
        """Cells (k, N), starts (k,) and info of the levels (seeds, episodes) for envs ``rows``."""
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
        info = LevelInfo(*(a[rows, slot] for a in self.info))
        return self.cells[rows, slot], self.starts[rows, slot], info

    def _refill(self) -> None:
        eps = self.next_ep[:, None] + np.arange(self.window)  # (n, window)
        slot = eps % self.depth
        env = np.broadcast_to(np.arange(self.n)[:, None], eps.shape)
        have = (self.key_ep[env, slot] == eps) & (self.key_seed[env, slot] == self.seeds[:, None])
        need_env, need_k = np.nonzero(~have)
        need_ep, need_slot = eps[need_env, need_k], slot[need_env, need_k]
        cells, starts, info = generate_levels(self.cfg, self.seeds[need_env], need_ep, self.rules)
        self.cells[need_env, need_slot] = cells
        self.starts[need_env, need_slot] = starts
        for mine, new in zip(self.info, info, strict=True):
            mine[need_env, need_slot] = new
        self.key_ep[need_env, need_slot] = need_ep
        self.key_seed[need_env, need_slot] = self.seeds[need_env]
        self.window = min(self.cap, self.window * 2)


class RandomLevels:
    """A level source (rgw_levels.LevelSource) that generates a new level per episode."""

    per_episode = True

    def __init__(self, cfg: RandomLevelConfig, rules_: Rules) -> None:
        self.cfg, self.rules = cfg, rules_
        self.name = "random"
        self.height, self.width = cfg.height, cfg.width
        self._cache = ObjectsCache()

    def levels(
        self, seeds: np.ndarray, episodes: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, LevelInfo]:
        return generate_levels(self.cfg, seeds, episodes, self.rules)

    def ring(self, n: int) -> LevelRing:
        """A LevelRing for an env of n sub-envs."""
        return LevelRing(self.cfg, n, self.rules)

    def objects(self, seed: int, episode: int) -> LevelObjects:
        key = (int(seed), int(episode))
        got = self._cache.get(key)
        if got is None:
            cells = self.levels(np.array([seed]), np.array([episode]))[0]
            got = LevelObjects(cells[0], self.width)
            self._cache.put(key, got)
        return got


ENV_OPTIONS = ("classic", "obs_mode", "max_steps", "render_mode", "enemy")
"""rgw-random's options besides the level parameters (RGWRandomEnv's and its batched env's own)"""


def config_from_kwargs(kwargs: dict[str, Any]) -> RandomLevelConfig:
    """A RandomLevelConfig from keyword arguments, refusing unknown names."""
    known = {f.name for f in fields(RandomLevelConfig)}
    unknown = sorted(set(kwargs) - known)
    if unknown:
        raise ConfigError(
            f"unknown rgw-random parameter {unknown[0]!r}; expected one of {', '.join(sorted(known))} "
            f"(or an option of the env: {', '.join(ENV_OPTIONS)})"
        )
    return RandomLevelConfig(**kwargs)


def random_enemy(enemy: str | None, classic: bool) -> str:
    """rgw-random's enemy mode: ``block`` unless asked otherwise (``pass`` with classic rules)."""
    if enemy is None:
        return "pass" if classic else "block"
    return enemy


class RGWRandomEnv(RGWEnv):
    """Relational-Grid-World on procedural levels: a new solvable level every episode.

    ## Description
    The sword, the enemy, the teleport and the terminal move every episode, so
    an agent cannot solve the level by where it is; it has to relate them. The
    mix of level kinds (guarded terminal, decoy enemy, teleport needed,
    mountains and pits on the way) is set by :class:`RandomLevelConfig`'s
    shares and described in this module's docstring. The level of an episode
    is decided by the reset seed and the number of resets since it:
    ``reset(seed=s)`` plays level (s, 0), each later ``reset()`` the next one.
    Train and evaluate on different seeds: evaluation seeds are then unseen levels.

    ## Action Space
    ``Discrete(4)``, as :class:`~neurosym.envs.rgw.RGWEnv`.

    ## Observation
    As :class:`~neurosym.envs.rgw.RGWEnv`: ``(9, H, W)`` onehot or ``(1, H, W)`` grey.

    ## Rewards
    As :class:`~neurosym.envs.rgw.RGWEnv`, with ``enemy="block"`` by default: an
    enemy met without the sword costs -1 and the agent stays where it was
    (``enemy="end"``: -1 and the episode ends; ``"pass"``: the thesis's -1 and
    pass, which makes the sword nearly worthless against the +10 terminal).
    ``classic=True`` (the original release's rules) implies ``enemy="pass"``.

    ## Termination
    As :class:`~neurosym.envs.rgw.RGWEnv`; ``enemy="end"`` adds outcome ``enemy``.

    ## Info
    As :class:`~neurosym.envs.rgw.RGWEnv`, whose ``optimal_return``,
    ``guarded``, ``needs_teleport`` and ``hazard_on_route`` describe the
    episode's level (computed by the generator under the env's rules).

    ## Registered Configurations
    * ``neurosym/RGWRandom-v0`` (``rgw-random``): 10 x 10, one enemy, blocking;
      half the levels guarded, a quarter needing the teleport, 30 % with
      mountains or pits across every shortest route.
    """

    def __init__(
        self,
        *,
        classic: bool = False,
        obs_mode: str = "onehot",
        max_steps: int | None = 100,
        render_mode: str | None = None,
        enemy: str | None = None,
        **level_kwargs: Any,
    ) -> None:
        self.level_config = config_from_kwargs(level_kwargs)
        enemy = random_enemy(enemy, classic)
        check_options(obs_mode, max_steps, render_mode, enemy, classic)
        source = RandomLevels(self.level_config, Rules(bool(classic), enemy, max_steps))
        self._setup(source, classic, obs_mode, max_steps, render_mode, enemy)
