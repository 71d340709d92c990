"""Box-World levels: the configuration, the vectorised generator and hand-built levels.

A level is a set of object cells (loose keys, boxes = lock + content, the gem)
and the agent's cell. The generator follows DeepMind's pycolab reference
(``box_world.py``, Zambaldi et al. 2019):

* the solution is one loose key and ``solution_length`` boxes: the loose key
  opens box 1, box i holds the key of box i + 1, the last box holds the gem;
* each of ``num_distractors`` branches starts at a box whose lock takes one of
  the solution's keys and goes on for ``distractor_length`` boxes whose keys
  have colours the solution never uses, so a distractor's key opens nothing on
  the way to the gem (opening a distractor box also ends the episode);
* colours are a random permutation of the 20; distractor keys are drawn with
  replacement from the colours the solution leaves free (two branches may
  share a colour, as in the reference);
* every object takes a 1 x 2 footprint (content, lock to its right; a loose key
  leaves its right cell empty) placed uniformly among the positions whose
  surrounding ring of cells is free of other objects and of the border. So no
  two objects touch, not even diagonally, the free cells stay connected, and
  every lock and key can be reached from the start;
* the agent starts on a uniformly drawn empty interior cell.

Levels are a pure function of (key, episode): a counter-based generator hashes
them into the random numbers, so a batch of environments that reset at the same
step draws its levels in one set of array operations, and the single
environment with seed ``s + i`` plays exactly the levels of sub-environment
``i`` of a batched environment seeded with ``s``. A layout that cannot be
completed (rare with the default sizes) is drawn again with the next attempt
number, still deterministically.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from neurosym.envs.boxworld_entities import (
    COLOUR_INDEX,
    COLOUR_NAMES,
    EMPTY,
    GEM,
    KEY,
    LOCK,
    NUM_COLOURS,
    WALL,
)
from neurosym.errors import ConfigError

SIZE = 12
"""Interior side length; the observation adds a one-cell border on each side."""
GRID = SIZE + 2
CELLS = GRID * GRID
HELD_CELL = 0
"""the top-left border cell (row-major), where the held key is drawn"""

MAX_OBJECTS = 15
"""Most objects (loose key + boxes) a generated level may hold: beyond this the
random packing of 1 x 2 footprints with free rings jams (15 objects: ~9 attempts per level)."""
MAX_ATTEMPTS = 1000


@dataclass(frozen=True)
class BoxWorldConfig:
    """The parameters of a Box-World level family (thesis section 4.2)."""

    solution_length: int = 3
    """boxes to open on the way to the gem (the last one holds the gem)"""
    num_distractors: int = 1
    """dead-end branches, each rooted at a lock that a solution key opens"""
    distractor_length: int = 1
    """boxes per distractor branch"""
    max_steps: int = 300
    """steps before the episode is truncated (outcome timeout)"""

    def __post_init__(self) -> None:
        for name in ("solution_length", "num_distractors", "distractor_length", "max_steps"):
            value = getattr(self, name)
            if not isinstance(value, int | np.integer) or isinstance(value, bool):
                raise ConfigError(f"Box-World {name} must be an integer, got {value!r}")
        if self.solution_length < 1:
            raise ConfigError(
                f"Box-World solution_length must be at least 1, got {self.solution_length}"
            )
        if self.num_distractors < 0:
            raise ConfigError(
                f"Box-World num_distractors must be 0 or more, got {self.num_distractors}"
            )
        if self.distractor_length < 1:
            raise ConfigError(
                f"Box-World distractor_length must be at least 1, got {self.distractor_length}"
            )
        if self.max_steps < 1:
            raise ConfigError(f"Box-World max_steps must be at least 1, got {self.max_steps}")
        free = NUM_COLOURS - self.solution_length
        need = 0 if self.num_distractors == 0 else (1 if self.distractor_length == 1 else 2)
        if free < need:
            raise ConfigError(
                f"Box-World solution_length {self.solution_length} leaves {max(free, 0)} of the "
                f"{NUM_COLOURS} colours for distractor keys, {need} needed; use a shorter solution"
            )
        if self.num_objects > MAX_OBJECTS:
            raise ConfigError(
                f"Box-World level would hold {self.num_objects} objects (1 key + {self.num_boxes} boxes), "
                f"at most {MAX_OBJECTS} fit the 12 x 12 grid; reduce solution_length, "
                "num_distractors or distractor_length"
            )

    @property
    def num_boxes(self) -> int:
        return self.solution_length + self.num_distractors * self.distractor_length

    @property
    def num_objects(self) -> int:
        """Loose key plus boxes: the footprints the generator places."""
        return 1 + self.num_boxes

    @property
    def num_slots(self) -> int:
        """Object cells of a level: the loose key plus two per box."""
        return 1 + 2 * self.num_boxes


@dataclass(frozen=True)
class LevelArrays:
    """m levels as arrays; cells are flat indices into the 14 x 14 grid, -1 pads."""

    agent: np.ndarray  # (m,) int16
    cells: np.ndarray  # (m, S) int16, sorted row-major, padding -1 at the end
    codes: np.ndarray  # (m, S) uint8 entity codes
    distractor: np.ndarray  # (m, S) bool, True on the lock cells of distractor boxes

    def __len__(self) -> int:
        return len(self.agent)

    def padded(self, slots: int) -> LevelArrays:
        """The same levels with ``slots`` object columns (more padding)."""
        extra = slots - self.cells.shape[1]
        if extra < 0:
            raise ValueError(f"levels have {self.cells.shape[1]} object cells, more than {slots}")
        m = len(self)
        return LevelArrays(
            self.agent,
            np.concatenate([self.cells, np.full((m, extra), -1, np.int16)], axis=1),
            np.concatenate([self.codes, np.zeros((m, extra), np.uint8)], axis=1),
            np.concatenate([self.distractor, np.zeros((m, extra), bool)], axis=1),
        )

    def take(self, rows: np.ndarray) -> LevelArrays:
        """Levels ``rows`` (copies)."""
        return LevelArrays(
            self.agent[rows], self.cells[rows], self.codes[rows], self.distractor[rows]
        )

    def put(self, rows: np.ndarray, levels: LevelArrays) -> None:
        """Overwrite levels ``rows`` with ``levels``."""
        self.agent[rows] = levels.agent
        self.cells[rows] = levels.cells
        self.codes[rows] = levels.codes
        self.distractor[rows] = levels.distractor


# ---------------------------------------------------------------- random numbers

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_ODD = np.uint64(0xD1B54A32D192ED03)


def _mix(x: np.ndarray) -> np.ndarray:
    """splitmix64's finaliser: a bijective avalanche of uint64 values."""
    x = (x ^ (x >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    x = (x ^ (x >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return x ^ (x >> np.uint64(31))


def uniforms(
    keys: np.ndarray, episodes: np.ndarray, attempts: np.ndarray, count: int
) -> np.ndarray:
    """(m, count) floats in [0, 1): draw j of level (key, episode, attempt), for any m at once."""
    with np.errstate(over="ignore"):
        base = _mix(_mix(keys.astype(np.uint64)) ^ (episodes.astype(np.uint64) * _GOLDEN))
        base = _mix(base ^ (attempts.astype(np.uint64) * _ODD))
        j = np.arange(1, count + 1, dtype=np.uint64)
        x = _mix(base[:, None] + j[None, :] * _GOLDEN)
    return (x >> np.uint64(11)).astype(np.float64) * (1.0 / (1 << 53))


def seed_keys(seed: int, count: int) -> np.ndarray:
    """Level keys of ``count`` environments seeded ``seed, seed + 1, ...`` (gymnasium's convention)."""
    if not isinstance(seed, int | np.integer) or isinstance(seed, bool) or seed < 0:
        raise ConfigError(f"seed must be a non-negative integer, got {seed!r}")
    return np.array(
        [
            np.random.SeedSequence(int(seed) + i).generate_state(1, np.uint64)[0]
            for i in range(count)
        ],
        dtype=np.uint64,
    )


def random_keys(rng: np.random.Generator, count: int) -> np.ndarray:
    """Level keys for unseeded environments, drawn from ``rng``."""
    return rng.integers(0, _USED, size=count, dtype=np.uint64, endpoint=True)


def _pick(valid: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Index of a uniformly chosen True per row of ``valid`` (m, P), and whether there was one."""
    count = valid.sum(axis=1)
    k = np.floor(u * count).astype(np.int64)
    chosen = np.argmax(np.cumsum(valid, axis=1, dtype=np.int16) > k[:, None], axis=1)
    return chosen, count > 0


def _choose(
    valid: np.ndarray, candidates: np.ndarray, u_exact: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """A uniformly chosen valid index per row of ``valid`` (m, P), and whether there was one.

    The first valid one of a few uniform ``candidates`` (m, C) is uniform among the valid
    indices; rows where no candidate is valid fall back to an exact draw with ``u_exact``,
    which keeps the choice exactly uniform while the common case never scans all P."""
    m, p = valid.shape
    rows = np.arange(m)
    hit = valid.reshape(-1)[(rows * p)[:, None] + candidates]  # (m, C)
    first = np.argmax(hit, axis=1)
    chosen = candidates[rows, first]
    found = hit[rows, first]
    miss = np.flatnonzero(~found)
    if miss.size:
        chosen[miss], found[miss] = _pick(valid[miss], u_exact[miss])
    return chosen, found


# ---------------------------------------------------------------- placement tables

_PLACE_ROWS = np.arange(2, SIZE)  # content rows 2..11: the ring stays inside the border
_PLACE_COLS = np.arange(2, SIZE - 1)  # content cols 2..10: ring cols c-1..c+2 inside
_PR, _PC = np.meshgrid(_PLACE_ROWS, _PLACE_COLS, indexing="ij")
_PLACE_CELL = (_PR * GRID + _PC).ravel().astype(np.int16)  # (P,) content cell per position
# Placing at p rules out q when the footprints' rings would hold each other's cells.
_BLOCK = (np.abs(_PR.ravel()[:, None] - _PR.ravel()[None, :]) <= 1) & (
    np.abs(_PC.ravel()[:, None] - _PC.ravel()[None, :]) <= 2
)
_INTERIOR = np.zeros((GRID, GRID), bool)
_INTERIOR[1:-1, 1:-1] = True
_INTERIOR_CELLS = np.flatnonzero(_INTERIOR).astype(np.int16)  # (144,)


def _structure(config: BoxWorldConfig, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Colours of every object: lock (-1 for the loose key) and content (NUM_COLOURS = gem)."""
    m = len(u)
    n, nd, ln = config.solution_length, config.num_distractors, config.distractor_length
    perm = np.argsort(u[:, :NUM_COLOURS], axis=1)  # (m, 20) a random colour order
    locks = np.empty((m, config.num_objects), np.int64)
    contents = np.empty((m, config.num_objects), np.int64)
    locks[:, 0] = -1
    contents[:, 0] = perm[:, 0]
    locks[:, 1 : n + 1] = perm[:, :n]
    contents[:, 1:n] = perm[:, 1:n]
    contents[:, n] = NUM_COLOURS
    spare = NUM_COLOURS - n  # colours the solution does not use: perm[:, n:]
    root_u = u[:, NUM_COLOURS : NUM_COLOURS + nd]
    step_u = u[:, NUM_COLOURS + nd : NUM_COLOURS + nd + nd * ln].reshape(m, nd, ln) if nd else None
    j = n + 1
    for b in range(nd):
        lock = perm[np.arange(m), np.floor(root_u[:, b] * n).astype(np.int64)]
        prev = np.full(m, -1)
        for s in range(ln):
            if s == 0:
                idx = np.floor(step_u[:, b, s] * spare).astype(np.int64)
            else:  # not the colour of its own lock, else the branch would loop
                idx = np.floor(step_u[:, b, s] * (spare - 1)).astype(np.int64)
                idx += idx >= prev
            content = perm[np.arange(m), n + idx]
            locks[:, j], contents[:, j] = lock, content
            lock, prev = content, idx
            j += 1
    distractor = np.zeros(config.num_objects, bool)
    distractor[n + 1 :] = True
    return locks, contents, distractor


_CANDIDATES = 8  # uniform candidate positions drawn per object before the exact fallback


def _try_generate(
    config: BoxWorldConfig, keys: np.ndarray, episodes: np.ndarray, attempts: np.ndarray
) -> tuple[LevelArrays, np.ndarray]:
    """One attempt at m levels; returns them and which ones could be placed."""
    m = len(keys)
    rows = np.arange(m)
    nobj, places = config.num_objects, len(_PLACE_CELL)
    nd, ln = config.num_distractors, config.distractor_length
    # draws: colours | branch roots | branch keys | per object (exact, candidates) | agent (same)
    first_pos = NUM_COLOURS + nd + nd * ln
    per = 1 + _CANDIDATES
    u = uniforms(keys, episodes, attempts, first_pos + per * (nobj + 1))
    locks, contents, distractor = _structure(config, u)
    draws = u[:, first_pos:].reshape(m, nobj + 1, per)
    exact = draws[:, :, 0]  # (m, nobj + 1)
    candidates = (draws[:, :, 1:] * places).astype(np.int64)  # (m, nobj + 1, C) placement indices

    blocked = np.zeros((m, places), bool)
    ok = np.ones(m, bool)
    content_cell = np.empty((m, nobj), np.int64)
    for j in range(nobj):
        pos, found = _choose(~blocked, candidates[:, j], exact[:, j])
        ok &= found
        content_cell[:, j] = _PLACE_CELL[pos]
        blocked |= _BLOCK[pos]

    # Object cells: every content, then every lock (the loose key, object 0, has none).
    slot_cells = np.concatenate([content_cell, content_cell[:, 1:] + 1], axis=1)  # (m, S)
    slot_codes = np.concatenate(
        [np.where(contents == NUM_COLOURS, GEM, KEY + contents), LOCK + locks[:, 1:]], axis=1
    )
    slot_distractor = np.zeros((m, config.num_slots), bool)
    slot_distractor[:, nobj:] = distractor[1:]

    occupied = np.zeros((m, CELLS), bool)
    occupied.reshape(-1)[(rows * CELLS)[:, None] + slot_cells] = True
    free = ~occupied[:, _INTERIOR_CELLS]
    agent_candidates = (draws[:, nobj, 1:] * len(_INTERIOR_CELLS)).astype(np.int64)
    agent_pos, found = _choose(free, agent_candidates, exact[:, nobj])
    ok &= found

    order = np.argsort(slot_cells, axis=1, kind="stable")
    flat = (rows * config.num_slots)[:, None] + order  # row-major object order
    levels = LevelArrays(
        agent=_INTERIOR_CELLS[agent_pos].astype(np.int16),
        cells=slot_cells.reshape(-1)[flat].astype(np.int16),
        codes=slot_codes.reshape(-1)[flat].astype(np.uint8),
        distractor=slot_distractor.reshape(-1)[flat],
    )
    return levels, ok


def generate_levels(config: BoxWorldConfig, keys: np.ndarray, episodes: np.ndarray) -> LevelArrays:
    """The levels of (key, episode) pairs, all at once; each is independent of the others in the batch."""
    m = len(keys)
    keys = np.asarray(keys, np.uint64)
    episodes = np.asarray(episodes, np.uint64)
    levels, ok = _try_generate(config, keys, episodes, np.zeros(m, np.uint64))
    attempt = 0
    while not ok.all():
        attempt += 1
        if attempt >= MAX_ATTEMPTS:
            raise ConfigError(
                f"Box-World could not place {config.num_objects} objects in {MAX_ATTEMPTS} attempts; "
                "use fewer boxes"
            )
        redo = np.flatnonzero(~ok)
        again, ok_again = _try_generate(
            config, keys[redo], episodes[redo], np.full(len(redo), attempt, np.uint64)
        )
        for field in ("agent", "cells", "codes", "distractor"):
            getattr(levels, field)[redo] = getattr(again, field)
        ok[redo] = ok_again
    return levels


_USED = np.uint64(np.iinfo(np.uint64).max)  # episode tag of a buffered level already handed out


class NextLevels:
    """The next level of each of n level streams, drawn ahead and refilled in batches.

    A call to :func:`generate_levels` costs a fixed ~0.2 ms plus a few microseconds per
    level, and autoresets come a few environments at a time: drawing each level when it
    is needed would pay the fixed cost on most steps. Here every stream's next level
    waits ready; the ones used are drawn again together once ``batch`` of them are used.
    Levels stay a pure function of (key, episode), so nothing about them changes."""

    def __init__(self, config: BoxWorldConfig, n: int, batch: int) -> None:
        self.config, self.batch = config, max(1, batch)
        self._levels = LevelArrays(
            np.zeros(n, np.int16),
            np.full((n, config.num_slots), -1, np.int16),
            np.zeros((n, config.num_slots), np.uint8),
            np.zeros((n, config.num_slots), bool),
        )
        self._key = np.zeros(n, np.uint64)  # the (key, episode) each buffered level belongs to
        self._episode = np.full(n, _USED, np.uint64)

    def take(self, rows: np.ndarray, keys: np.ndarray, episodes: np.ndarray) -> LevelArrays:
        """Levels of streams ``rows`` for their episodes ``episodes[rows]``; then keep the
        following ones ready. ``keys`` and ``episodes`` are the (n,) arrays of all streams."""
        want_key, want_episode = keys[rows], episodes[rows]
        levels = self._levels.take(rows)
        miss = np.flatnonzero((self._key[rows] != want_key) | (self._episode[rows] != want_episode))
        if miss.size:
            levels.put(miss, generate_levels(self.config, want_key[miss], want_episode[miss]))
        self._episode[rows] = _USED  # used up
        stale = np.flatnonzero(self._episode == _USED)
        if stale.size >= self.batch:
            following = episodes[stale] + np.uint64(1)
            self._levels.put(stale, generate_levels(self.config, keys[stale], following))
            self._key[stale], self._episode[stale] = keys[stale], following
        return levels


# ---------------------------------------------------------------- hand-built levels


@dataclass(frozen=True)
class Box:
    """A box: its lock at (row, col) and its content at (row, col - 1), in observation coordinates."""

    row: int
    col: int
    lock: str
    """the lock's colour name"""
    content: str
    """a colour name (the key handed over), or ``"gem"``"""
    distractor: bool = False
    """opening it costs -1 and ends the episode"""


@dataclass(frozen=True)
class Level:
    """A hand-built level (tests, demonstrations); coordinates include the border, interior 1..12."""

    agent: tuple[int, int]
    keys: tuple[tuple[int, int, str], ...] = ()
    """loose keys as (row, col, colour)"""
    boxes: tuple[Box, ...] = ()
    gem: tuple[int, int] | None = None
    """a loose gem (walking onto it wins)"""

    def to_arrays(self) -> LevelArrays:
        """This level as a batch of one, checked cell by cell."""
        cells: list[int] = []
        codes: list[int] = []
        distractor: list[bool] = []

        def place(row: int, col: int, code: int, what: str, is_distractor: bool = False) -> None:
            if not (1 <= row <= SIZE and 1 <= col <= SIZE):
                raise ConfigError(
                    f"Box-World level: {what} at ({row}, {col}) is outside the interior rows/cols 1..{SIZE}"
                )
            cell = row * GRID + col
            if cell in cells:
                raise ConfigError(
                    f"Box-World level: {what} at ({row}, {col}) shares its cell with another object"
                )
            cells.append(cell)
            codes.append(code)
            distractor.append(is_distractor)

        for row, col, colour in self.keys:
            place(row, col, KEY + _colour(colour), f"key({colour})")
        for box in self.boxes:
            content = GEM if box.content == "gem" else KEY + _colour(box.content)
            place(box.row, box.col - 1, content, f"content of the {box.lock} box")
            place(box.row, box.col, LOCK + _colour(box.lock), f"lock({box.lock})", box.distractor)
        if self.gem is not None:
            place(*self.gem, GEM, "gem")
        row, col = self.agent
        if not (1 <= row <= SIZE and 1 <= col <= SIZE):
            raise ConfigError(
                f"Box-World level: agent at ({row}, {col}) is outside the interior rows/cols 1..{SIZE}"
            )
        if row * GRID + col in cells:
            raise ConfigError(f"Box-World level: agent at ({row}, {col}) stands on an object")
        order = np.argsort(cells, kind="stable")
        return LevelArrays(
            agent=np.array([row * GRID + col], np.int16),
            cells=np.array(cells, np.int16)[order][None, :],
            codes=np.array(codes, np.uint8)[order][None, :],
            distractor=np.array(distractor, bool)[order][None, :],
        )


def _colour(name: str) -> int:
    try:
        return COLOUR_INDEX[name]
    except KeyError:
        raise ConfigError(
            f"Box-World level: unknown colour {name!r}; colours are {', '.join(COLOUR_NAMES)}"
        ) from None


def base_grid() -> np.ndarray:
    """(CELLS,) uint8 codes of an empty level: wall border, empty interior."""
    grid = np.full((GRID, GRID), WALL, np.uint8)
    grid[1:-1, 1:-1] = EMPTY
    return grid.ravel()
