"""Box-World's rules, written once over a batch axis.

``BoxWorldState`` holds n environments as arrays and ``step`` moves all of them
with one array operation per rule; the single environment is the batch of one,
so both versions play by the same code. The RGB observation is kept up to date
cell by cell (at most four cells change per step) instead of being redrawn.

One step, for each environment (Zambaldi et al. 2019 as the thesis plays it):

* the agent tries to enter the neighbouring cell in the action's direction;
* empty: it moves;
* a loose key (a key with no lock to its right): it moves there and holds the
  key, replacing (and losing) any key it held;
* a lock whose colour is the held key's: the key is consumed, the box opens and
  hands over its content (the cell left of the lock empties): a key becomes
  the held key, the gem is got. The agent moves onto the lock's cell.
  +1 for a box on the solution path, -1 for a distractor box, which ends the
  episode; the gem adds +10 and ends the episode (so the gem box pays +11);
* a loose gem (hand-built levels only): it moves there, +10, the episode ends;
* anything else (wall, a lock without its key, a box's content) blocks: it stays.

After ``max_steps`` steps an episode that did not end is truncated (outcome
timeout); a step that ends it by the rules is a termination, never both.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from neurosym.envs.boxworld_entities import (
    AGENT,
    EMPTY,
    ENTITY_NAMES,
    GEM,
    GOT_GEM,
    GOT_GEM_TEXT,
    GOT_KEY_TEXT,
    HELD,
    HIT_DISTRACTOR_TEXT,
    KEY,
    KEY_TEXT,
    LOCK,
    NUM_PLANES,
    ONEHOT,
    OPENED_TEXT,
    OUTCOME_DISTRACTOR,
    OUTCOME_GEM,
    OUTCOME_NONE,
    OUTCOME_TIMEOUT,
    OUTCOMES,
    PALETTE,
    WALL,
    object_id,
)
from neurosym.envs.boxworld_gen import CELLS, GRID, HELD_CELL, LevelArrays, base_grid

# Action -> change of the flat cell index: 0 up, 1 right, 2 down, 3 left.
DELTA = np.array([-GRID, 1, GRID, -1], dtype=np.int64)
_BASE_GRID = base_grid()
_RED, _GREEN, _BLUE = (np.ascontiguousarray(PALETTE[:, ch]) for ch in range(3))


OBS_MODES = ("rgb", "onehot")


def _table(obs_mode: str) -> np.ndarray:
    """(NUM_CODES, P) uint8 observation values of each entity code."""
    return PALETTE if obs_mode == "rgb" else ONEHOT


class BoxWorldState:
    """n Box-World environments as arrays (flat cells index the 14 x 14 grid row-major)."""

    def __init__(self, n: int, slots: int, max_steps: int, obs_mode: str = "rgb") -> None:
        self.n, self.slots, self.max_steps = n, slots, max_steps
        self.obs_mode = obs_mode
        self.planes = 3 if obs_mode == "rgb" else NUM_PLANES
        self._lut = _table(obs_mode)
        rows = np.arange(n)
        self.grid = np.tile(_BASE_GRID, (n, 1))  # (n, CELLS) uint8 entity codes
        # (n, P, CELLS) uint8 RGB or one-hot planes, kept up to date cell by cell
        self.obs = np.ascontiguousarray(self._lut[self.grid].transpose(0, 2, 1))
        self.distractor = np.zeros((n, CELLS), bool)  # lock cells of distractor boxes
        # object slot of each cell; `slots` where there is none
        self.slot_of_cell = np.full((n, CELLS), slots, np.int64)
        self.object_cell = np.full((n, slots), -1, np.int16)  # -1 pads
        self.object_code = np.zeros((n, slots), np.uint8)
        self.object_alive = np.zeros((n, slots), bool)  # still on the map
        # Flat views and row offsets for step(): env i, cell c is grid_flat[i * CELLS + c],
        # obs_flat[i * 3 * CELLS + channel * CELLS + c], alive_flat[i * slots + slot].
        self._grid_flat = self.grid.reshape(-1)
        self._obs_flat = self.obs.reshape(-1)
        self._distractor_flat = self.distractor.reshape(-1)
        self._slot_flat = self.slot_of_cell.reshape(-1)
        self._alive_flat = self.object_alive.reshape(-1)
        self._base = rows * CELLS
        self._base3 = np.tile(self._base, 3)
        self._rows3 = np.tile(rows, 3)
        self._obs_base3 = np.tile(rows * 3 * CELLS, 3)
        self._alive_base = rows * slots
        self.agent = np.zeros(n, np.int64)  # flat cell of the agent
        self.held = np.full(n, -1, np.int8)  # colour index of the held key, -1 none
        self.steps = np.zeros(n, np.int32)
        self.event_key = np.full(n, -1, np.int8)  # colour of the loose key picked up
        self.event_lock = np.full(n, -1, np.int8)  # colour of the lock opened
        self.event_got = np.full(n, -1, np.int8)  # content handed over: colour, GOT_GEM, -1
        self.outcome = np.zeros(n, np.int8)  # OUTCOME_*

    # ------------------------------------------------------------------ reset

    def load(self, rows: np.ndarray, levels: LevelArrays) -> None:
        """Start new episodes in environments ``rows`` on ``levels`` (one per row)."""
        rows = np.asarray(rows, np.int64)
        if levels.cells.shape[1] < self.slots:
            levels = levels.padded(self.slots)
        m, s = levels.cells.shape
        assert m == len(rows) and s == self.slots, (m, len(rows), s, self.slots)
        real = levels.cells >= 0
        # Padding writes go to the held key's border cell with values that leave it as it is.
        cells = np.where(real, levels.cells, HELD_CELL).astype(np.int64)  # (m, S)
        grid = np.tile(_BASE_GRID, (m, 1))  # (m, CELLS)
        grid.reshape(-1)[(np.arange(m) * CELLS)[:, None] + cells] = np.where(
            real, levels.codes, WALL
        )
        grid.reshape(-1)[np.arange(m) * CELLS + levels.agent] = AGENT
        self.grid[rows] = grid
        self.obs[rows] = self._lut[grid].transpose(0, 2, 1)
        at = (rows * CELLS)[:, None] + cells
        self.distractor[rows] = False
        self._distractor_flat[at] = levels.distractor & real
        self.slot_of_cell[rows] = self.slots
        self._slot_flat[at] = np.where(real, np.arange(s), self.slots)
        self.object_cell[rows] = levels.cells
        self.object_code[rows] = levels.codes
        self.object_alive[rows] = real
        self.agent[rows] = levels.agent
        self.held[rows] = -1
        self.steps[rows] = 0
        self.event_key[rows] = -1
        self.event_lock[rows] = -1
        self.event_got[rows] = -1
        self.outcome[rows] = OUTCOME_NONE

    # ------------------------------------------------------------------ step

    def step(self, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Apply one action per environment; returns (reward, terminated, truncated).

        Every read and write goes through flat views with precomputed row offsets:
        1-D fancy indexing is several times faster than (rows, cells) pairs."""
        grid, base = self._grid_flat, self._base
        old = self.agent
        target = old + DELTA[actions]  # (n,) cell the agent walks into
        at = base + target
        entity = grid[at].astype(np.int16)
        right = grid[at + 1]
        content = grid[at - 1].astype(np.int16)
        held = self.held.astype(np.int16)

        # a key or gem with a lock to its right is locked in its box
        in_box = (right >= LOCK) & (right < HELD)
        loose_key = (entity >= KEY) & (entity < LOCK) & ~in_box
        loose_gem = (entity == GEM) & ~in_box
        opens = (entity >= LOCK) & (entity < HELD) & (entity - LOCK == held)
        content_key = opens & (content >= KEY) & (content < LOCK)
        got_gem = (opens & (content == GEM)) | loose_gem
        distractor = opens & self._distractor_flat[at]
        moves = (entity == EMPTY) | loose_key | loose_gem | opens

        # Events of the step, as codes decode_info turns into Prolog text.
        self.event_key = np.where(loose_key, entity - KEY, -1).astype(np.int8)
        self.event_lock = np.where(opens, entity - LOCK, -1).astype(np.int8)
        handed = np.where(content_key, content - KEY, -1)  # the key a box hands over
        self.event_got = np.where(got_gem, GOT_GEM, handed).astype(np.int8)
        self.held = np.where(loose_key, entity - KEY, np.where(opens, handed, held)).astype(np.int8)

        reward = np.where(opens, np.where(distractor, -1.0, 1.0), 0.0) + 10.0 * got_gem
        terminated = got_gem | distractor
        self.steps += 1
        truncated = (self.steps >= self.max_steps) & ~terminated
        outcome = np.where(truncated, OUTCOME_TIMEOUT, OUTCOME_NONE)
        outcome = np.where(distractor, OUTCOME_DISTRACTOR, outcome)
        self.outcome = np.where(got_gem, OUTCOME_GEM, outcome).astype(np.int8)

        # Objects consumed (rare): the picked key / gem, or the opened lock and its content.
        taken = np.flatnonzero(loose_key | loose_gem | opens)
        if taken.size:
            alive, slot_of_cell = self._alive_flat, self._slot_flat
            alive[self._alive_base[taken] + slot_of_cell[at[taken]]] = False
            box = taken[opens[taken]]
            alive[self._alive_base[box] + slot_of_cell[at[box] - 1]] = False

        # Redraw the cells that changed. The held key's cell is written last, so it also
        # absorbs the writes of environments that emptied no box content.
        new = np.where(moves, target, old)
        emptied = np.where(opens, target - 1, HELD_CELL)
        grid[base + emptied] = EMPTY
        grid[base + old] = EMPTY
        grid[base + new] = AGENT
        held_code = np.where(self.held >= 0, HELD + self.held.astype(np.int16), WALL)
        self.grid[:, HELD_CELL] = held_code  # strided write
        changed = np.concatenate([old, emptied, new])  # (3n,) cells to repaint
        codes = grid[self._base3 + changed]
        if self.obs_mode == "rgb":
            paint = self._obs_base3 + changed
            obs = self._obs_flat
            obs[paint] = _RED[codes]
            obs[paint + CELLS] = _GREEN[codes]
            obs[paint + 2 * CELLS] = _BLUE[codes]
        else:  # (3n, P) rows of planes; the later writes of a cell win, as above
            self.obs[self._rows3, :, changed] = ONEHOT[codes]
        self.obs[:, :, HELD_CELL] = self._lut[held_code]  # a strided write
        self.agent = new
        return reward, terminated, truncated

    # ------------------------------------------------------------------ views

    def entity_grid(self) -> np.ndarray:
        """(n, 14, 14) entity codes (a copy)."""
        return self.grid.reshape(self.n, GRID, GRID).copy()

    def observation(self) -> np.ndarray:
        """(n, P, 14, 14) uint8 RGB or one-hot planes (a copy)."""
        return self.obs.reshape(self.n, self.planes, GRID, GRID).copy()

    def info(self) -> dict[str, np.ndarray]:
        """The batched info: arrays (copies) that ``decode_info`` turns into the single env's dict."""
        agent = self.agent
        return {
            "agent": np.stack([agent // GRID, agent % GRID], axis=1),
            "held": self.held.copy(),
            "object_code": self.object_code.copy(),
            "object_cell": self.object_cell.copy(),
            "object_alive": self.object_alive.copy(),
            "event_key": self.event_key.copy(),
            "event_lock": self.event_lock.copy(),
            "event_got": self.event_got.copy(),
            "outcome": self.outcome.copy(),
        }


def clear_events(info: dict[str, np.ndarray], rows: np.ndarray) -> None:
    """Mark ``rows`` of a batched info as just reset: no events, no outcome."""
    for key in ("event_key", "event_lock", "event_got"):
        info[key][rows] = -1
    info["outcome"][rows] = OUTCOME_NONE


def object_ids(codes: np.ndarray, cells: np.ndarray) -> tuple[str, ...]:
    """Unique ids for one level's object slots: ``lock_red``, then ``lock_red_2`` (row-major order)."""
    return _object_ids(codes.astype(np.uint8).tobytes(), cells.astype(np.int16).tobytes())


@lru_cache(maxsize=4096)
def _object_ids(codes_bytes: bytes, cells_bytes: bytes) -> tuple[str, ...]:
    # ids change only at reset: decoding every step hits this cache
    codes = np.frombuffer(codes_bytes, np.uint8)
    cells = np.frombuffer(cells_bytes, np.int16)
    seen: dict[str, int] = {}
    ids = []
    for code, cell in zip(codes.tolist(), cells.tolist(), strict=True):
        if cell < 0:
            ids.append("")
            continue
        base = object_id(ENTITY_NAMES[code])
        seen[base] = seen.get(base, 0) + 1
        ids.append(base if seen[base] == 1 else f"{base}_{seen[base]}")
    return tuple(ids)


def decode_info(info: dict[str, np.ndarray], i: int) -> dict:
    """The single environment's info dict for sub-environment ``i`` (docs/interfaces.md)."""
    row, col = (int(v) for v in info["agent"][i])
    held = int(info["held"][i])
    codes, cells, alive = info["object_code"][i], info["object_cell"][i], info["object_alive"][i]
    ids = object_ids(codes, cells)
    objects = (("agent", "agent", row, col),) + tuple(
        (ids[s], ENTITY_NAMES[int(codes[s])], int(cells[s]) // GRID, int(cells[s]) % GRID)
        for s in np.flatnonzero(alive)
    )
    events: list[str] = []
    key, lock, got = (
        int(info["event_key"][i]),
        int(info["event_lock"][i]),
        int(info["event_got"][i]),
    )
    outcome = int(info["outcome"][i])
    if key >= 0:
        events.append(GOT_KEY_TEXT[key])
    if lock >= 0:
        events.append(OPENED_TEXT[lock])
    if got >= 0:
        events.append(GOT_GEM_TEXT if got == GOT_GEM else GOT_KEY_TEXT[got])
    if outcome == OUTCOME_DISTRACTOR:
        events.append(HIT_DISTRACTOR_TEXT)
    return {
        "agent": (row, col),
        "holding": (KEY_TEXT[held],) if held >= 0 else (),
        "objects": objects,
        "events": tuple(events),
        "outcome": OUTCOMES[outcome],
    }
