"""The rules of Relational-Grid-World, written once as array operations over a batch.

Both :class:`~neurosym.envs.rgw.RGWEnv` (n = 1) and
:class:`~neurosym.envs.rgw_vector.RGWVectorEnv` run :class:`RGWBatch`, so the
single and the batched environment cannot disagree.

How a step is computed (no Python loop over environments or cells):

* Walls, borders and teleports never change, so where an action leads from each
  cell is precomputed per level (:func:`compile_moves`): one gather per step.
* What happens on the cell the agent lands on depends only on the cell's code,
  whether the agent holds the sword, and whether it stayed in place. These are
  combined into one small index into lookup tables (reward, events,
  termination, the cell's new code, the new holding flag): one gather each.
* The observation buffer is updated in place: only the cell the agent left and
  the cell it entered change (and the holding plane when the sword is picked).

Cell codes are the entity codes of ``ENTITY_NAMES`` (agent 0 ... empty 8) plus
``TELEPORT_MOUNTAIN`` (9), the teleport end that the original release also
counts as a mountain.

What an unarmed meeting with the enemy does is a rule option (``ENEMY_MODES``):
``pass`` (the thesis: -1, the agent stands on the enemy's cell), ``block``
(-1, the agent stays where it was, as if the enemy were a wall) or ``end``
(-1, the episode ends, outcome ``enemy``). A blocked step is the one rule whose
destination depends on the state (holding the sword, the enemy still there),
so it is handled with the rare steps, apart from the precomputed moves.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from neurosym.terms import Term

# Entity codes: what `entity_grid()` returns; also the internal cell codes.
AGENT, SWORD, ENEMY, TERMINAL, TELEPORT, WALL, MOUNTAIN, PIT, EMPTY = range(9)
TELEPORT_MOUNTAIN = 9
NUM_CELL_CODES = 10

ENTITY_NAMES: tuple[str, ...] = (
    "agent",
    "sword",
    "enemy",
    "terminal",
    "teleport",
    "wall",
    "mountain",
    "pit",
    "empty",
)
ENTITY_OF_CELL = np.array([0, 1, 2, 3, 4, 5, 6, 7, 8, 4], dtype=np.uint8)

# Onehot observation: plane e holds entity e (agent .. pit); plane 8 is 1 while holding the sword.
HOLD_PLANE = 8
NUM_PLANES = 9

# Grey observation: the original release's intensities (reference/rgw-original.md).
GREY_AGENT = 128
GREY_OF_CELL = np.array([128, 75, 175, 255, 200, 0, 150, 30, 220, 200], dtype=np.uint8)

# Event bits, in the order events are listed within a step.
EVENT_TERMS: tuple[Term, ...] = (
    Term("bumped", ("border",)),
    Term("bumped", ("wall",)),
    Term("teleported"),
    Term("crossed", ("mountain",)),
    Term("picked", ("sword",)),
    Term("defeated", ("enemy",)),
    Term("hurt_by", ("enemy",)),
    Term("fell", ("pit",)),
    Term("reached", ("terminal",)),
    Term("bumped", ("enemy",)),
    Term("killed_by", ("enemy",)),
)
EVENT_NAMES: tuple[str, ...] = tuple(str(t) for t in EVENT_TERMS)
(
    EV_BUMP_BORDER,
    EV_BUMP_WALL,
    EV_TELEPORTED,
    EV_MOUNTAIN,
    EV_PICKED,
    EV_DEFEATED,
    EV_HURT,
    EV_PIT,
    EV_TERMINAL,
    EV_BUMP_ENEMY,
    EV_KILLED,
) = (1 << i for i in range(len(EVENT_TERMS)))

EVENT_TUPLES: tuple[tuple[str, ...], ...] = tuple(
    tuple(name for i, name in enumerate(EVENT_NAMES) if mask >> i & 1)
    for mask in range(1 << len(EVENT_NAMES))
)
"""event bitmask -> tuple of event texts (what info["events"] holds)"""

# Outcome codes of a finished episode.
OUTCOME_NAMES: tuple[str | None, ...] = (None, "terminal", "pit", "timeout", "enemy")

ENEMY_MODES = ("pass", "block", "end")
"""what meeting the enemy without the sword does: pass for -1, be blocked for -1, die for -1"""

ENEMY_REWARD = -1.0
"""reward of meeting the enemy without the sword, in every mode (Table 1's 'Enemy -1')"""

# Move codes: bits of where an action led, precomputed per level and cell.
MV_STAY, MV_WALL, MV_BORDER, MV_TELEPORT = 1, 2, 4, 8
MOVE_EVENTS = np.zeros(16, dtype=np.uint16)
for _mc in range(16):
    MOVE_EVENTS[_mc] = (
        (EV_BUMP_WALL if _mc & MV_WALL else 0)
        | (EV_BUMP_BORDER if _mc & MV_BORDER else 0)
        | (EV_TELEPORTED if _mc & MV_TELEPORT else 0)
    )

# (row, col) offsets of the actions 0 up, 1 right, 2 down, 3 left.
ACTION_DELTAS = np.array([(-1, 0), (0, 1), (1, 0), (0, -1)])

MOUNTAIN_REWARD = -0.1


@dataclass(frozen=True)
class RuleTables:
    """What happens on the landing cell, indexed by ``cell * 4 + a * 2 + b``.

    Default rules: ``a`` = holds the sword, ``b`` = stayed in place (nothing
    happens then). Classic rules: ``a`` = holds the sword by the original's
    ``state > nS_pos`` test (false at cell 0), ``b`` = holds the sword.
    """

    reward: np.ndarray  # float64
    events: np.ndarray  # uint16 event bits
    terminated: np.ndarray  # bool
    new_cell: np.ndarray  # uint8 code of the cell after the step
    new_holding: np.ndarray  # uint8
    removes: np.ndarray  # bool: the landing cell's object leaves the map
    blocked: np.ndarray  # bool: the agent goes back to the cell it came from (enemy="block")
    special: np.ndarray  # bool: removes, picks up the sword or is blocked (rare; handled apart)


def check_enemy(enemy: str, classic: bool) -> None:
    """Refuse an unknown enemy mode, and any but ``pass`` with the original release's rules."""
    from neurosym.errors import ConfigError

    if enemy not in ENEMY_MODES:
        raise ConfigError(f"enemy {enemy!r} is not one of {', '.join(ENEMY_MODES)}")
    if classic and enemy != "pass":
        raise ConfigError(
            f"enemy={enemy!r} with classic=True: the original release always lets the agent "
            "pass the enemy; use enemy='pass' or classic=False"
        )


def rule_tables(classic: bool, enemy: str = "pass") -> RuleTables:
    """Build the lookup tables of one rule set (default or classic; enemy mode, see ENEMY_MODES)."""
    check_enemy(enemy, classic)
    size = NUM_CELL_CODES * 4
    reward = np.zeros(size, dtype=np.float64)
    events = np.zeros(size, dtype=np.uint16)
    terminated = np.zeros(size, dtype=bool)
    new_cell = np.zeros(size, dtype=np.uint8)
    new_holding = np.zeros(size, dtype=np.uint8)
    blocked = np.zeros(size, dtype=bool)
    for cell in range(NUM_CELL_CODES):
        for a in (0, 1):
            for b in (0, 1):
                i = cell * 4 + a * 2 + b
                r, ev, term, nc = 0.0, 0, False, cell
                if classic:
                    held_for_enemy, holding = bool(a), bool(b)
                    hold = holding
                    if cell == SWORD and not holding:
                        hold, nc, ev = True, EMPTY, EV_PICKED
                    if cell == PIT:
                        r, ev, term = -1.0, EV_PIT, True
                    elif cell in (MOUNTAIN, TELEPORT_MOUNTAIN):
                        r, ev = MOUNTAIN_REWARD, EV_MOUNTAIN
                    elif cell == ENEMY:
                        r, ev = (1.0, EV_DEFEATED) if held_for_enemy else (-1.0, EV_HURT)
                    if cell == TERMINAL:
                        r, ev, term = r + 10.0, ev | EV_TERMINAL, True
                else:
                    hold, stayed = bool(a), bool(b)
                    if not stayed:
                        if cell == SWORD:
                            hold, nc, ev = True, EMPTY, EV_PICKED
                        elif cell == ENEMY and hold:
                            r, ev, nc = 1.0, EV_DEFEATED, EMPTY
                        elif cell == ENEMY and enemy == "block":
                            r, ev, blocked[i] = ENEMY_REWARD, EV_HURT | EV_BUMP_ENEMY, True
                        elif cell == ENEMY and enemy == "end":
                            r, ev, term = ENEMY_REWARD, EV_HURT | EV_KILLED, True
                        elif cell == ENEMY:
                            r, ev = ENEMY_REWARD, EV_HURT
                        elif cell == MOUNTAIN:
                            r, ev = MOUNTAIN_REWARD, EV_MOUNTAIN
                        elif cell == PIT:
                            r, ev, term = -1.0, EV_PIT, True
                        elif cell == TERMINAL:
                            r, ev, term = 10.0, EV_TERMINAL, True
                reward[i], events[i], terminated[i] = r, ev, term
                new_cell[i], new_holding[i] = nc, hold
    removes = (new_cell != np.repeat(np.arange(NUM_CELL_CODES), 4)) & (new_cell == EMPTY)
    special = removes | ((events & EV_PICKED) != 0) | blocked
    return RuleTables(reward, events, terminated, new_cell, new_holding, removes, blocked, special)


def outcome_codes(events: np.ndarray, truncated: np.ndarray) -> np.ndarray:
    """(n,) index into OUTCOME_NAMES from a step's event bits and truncation flags."""
    codes = np.where(
        events & EV_TERMINAL,
        1,
        np.where(events & EV_PIT, 2, np.where(events & EV_KILLED, 4, 0)),
    )
    return np.where(truncated, 3, codes).astype(np.uint8)


def outcome_name(events: int, truncated: bool) -> str | None:
    """The outcome of one step: terminal, pit, enemy, timeout, or None while the episode goes on."""
    if events & EV_TERMINAL:
        return "terminal"
    if events & EV_PIT:
        return "pit"
    if events & EV_KILLED:
        return "enemy"
    return "timeout" if truncated else None


def teleport_partners(cells: np.ndarray) -> np.ndarray:
    """(S, N) index of the other teleport end for teleport cells, the cell itself elsewhere."""
    S, N = cells.shape
    partner = np.broadcast_to(np.arange(N), (S, N)).copy()
    is_tele = (cells == TELEPORT) | (cells == TELEPORT_MOUNTAIN)
    rows, cols = np.nonzero(is_tele)  # row-major: each level's two ends are consecutive
    lvl, end_a, end_b = rows[0::2], cols[0::2], cols[1::2]
    partner[lvl, end_a] = end_b
    partner[lvl, end_b] = end_a
    return partner


def compile_moves(
    cells: np.ndarray, height: int, width: int, classic: bool
) -> tuple[np.ndarray, np.ndarray]:
    """Where each action leads from each cell: (S, N, 4) destination cell and move code.

    Default rules: a wall or the border leaves the agent in place; entering a
    teleport end puts it on the other end. Classic rules apply the original's
    order literally: clip, wall -> stay, then teleport whenever the resulting
    cell is a teleport end (so bumping while standing on one teleports too).
    """
    S, N = cells.shape
    target, border = cell_geometry(height, width)  # (4, N) each
    base = (np.arange(S, dtype=np.intp) * N)[:, None]  # flat offset of each level
    flat_cells = cells.reshape(-1)
    is_tele = (flat_cells == TELEPORT) | (flat_cells == TELEPORT_MOUNTAIN)
    partner = teleport_partners(cells).reshape(-1) if is_tele.any() else None
    dest = np.empty((S, N, 4), dtype=np.intp)
    code = np.empty((S, N, 4), dtype=np.uint8)
    here = np.arange(N)
    u8 = np.uint8
    # One action at a time keeps the temporaries small (S * N), which is faster.
    for a in range(4):
        # (S, N); a border target is the cell itself, never a wall
        wall = flat_cells.take(base + target[a]) == WALL
        stay = wall | border[a]
        new = np.where(stay, here, target[a])  # (S, N)
        flat = new + base
        tele = is_tele.take(flat)
        if not classic:
            tele &= ~stay
        if partner is not None:  # partner holds cells within each level
            new = np.where(tele, partner.take(flat), new)
        dest[:, :, a] = new
        code[:, :, a] = (
            stay.view(u8) | (wall.view(u8) << u8(1)) | (border[a].view(u8) << u8(2))
        ) | (tele.view(u8) << u8(3))
    return dest, code


_GEOMETRY: dict[tuple[int, int], tuple[np.ndarray, np.ndarray]] = {}


def cell_geometry(height: int, width: int) -> tuple[np.ndarray, np.ndarray]:
    """(4, N) clipped target cell of each action and (4, N) whether it hits the border."""
    key = (height, width)
    if key not in _GEOMETRY:
        r, c = np.divmod(np.arange(height * width), width)
        tr = r[None, :] + ACTION_DELTAS[:, 0, None]
        tc = c[None, :] + ACTION_DELTAS[:, 1, None]
        border = (tr < 0) | (tr >= height) | (tc < 0) | (tc >= width)
        target = np.clip(tr, 0, height - 1) * width + np.clip(tc, 0, width - 1)
        _GEOMETRY[key] = (target.astype(np.intp), border)
    return _GEOMETRY[key]


def onehot_planes(cells: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """(S, NUM_PLANES, N) uint8 initial onehot observation of levels (not holding)."""
    S, N = cells.shape
    ent = ENTITY_OF_CELL[cells].copy()
    ent[np.arange(S), starts] = AGENT
    planes = (ent[:, None, :] == np.arange(NUM_PLANES, dtype=np.uint8)[None, :, None]).astype(
        np.uint8
    )
    planes[:, HOLD_PLANE, :] = 0  # code 8 is empty, which has no plane
    return planes


def grey_planes(cells: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """(S, 1, N) uint8 initial grey observation: the original's intensities."""
    S, _ = cells.shape
    grey = GREY_OF_CELL[cells].copy()
    grey[np.arange(S), starts] = GREY_AGENT
    return grey[:, None, :]


def removable_bits(cells: np.ndarray) -> np.ndarray:
    """(S, N) uint64: bit k for the k-th sword or enemy in row-major order, 0 elsewhere."""
    mask = (cells == SWORD) | (cells == ENEMY)
    rank = np.cumsum(mask, axis=1) - 1
    bits = np.left_shift(np.uint64(1), np.clip(rank, 0, 63).astype(np.uint64))
    return np.where(mask, bits, np.uint64(0))


class StepResult(NamedTuple):
    """Arrays of one batched step (fresh arrays, safe to hand out)."""

    reward: np.ndarray  # (n,) float64
    terminated: np.ndarray  # (n,) bool
    truncated: np.ndarray  # (n,) bool
    events: np.ndarray  # (n,) uint16 event bits


class RGWBatch:
    """n Relational-Grid-World episodes as flat arrays, stepped together.

    Levels live in slots: one slot shared by every episode for a fixed map, one
    slot per environment for generated levels. The state arrays ``pos``,
    ``holding`` and ``removed`` are replaced, never modified in place, once
    handed out, so callers may keep references to them.
    """

    def __init__(
        self,
        n: int,
        height: int,
        width: int,
        *,
        classic: bool,
        obs_mode: str,
        max_steps: int | None,
        per_env_levels: bool,
        enemy: str = "pass",
    ) -> None:
        self.n, self.height, self.width = n, height, width
        N = self.cells_per_level = height * width
        self.classic = classic
        self.enemy = enemy
        self.obs_mode = obs_mode
        self.channels = NUM_PLANES if obs_mode == "onehot" else 1
        self.max_steps = np.iinfo(np.int64).max if max_steps is None else int(max_steps)
        S = self.num_slots = n if per_env_levels else 1
        self.slot = np.arange(n) if per_env_levels else np.zeros(n, dtype=np.intp)
        # Static per-slot tables, flat so that one index addresses them.
        self._dest_pos = np.zeros(S * N * 4, dtype=np.intp)  # destination cell
        self._dest_key = np.zeros(S * N * 4, dtype=np.intp)  # slot * N * 4 + destination * 4
        self._mcode = np.zeros(S * N * 4, dtype=np.uint8)
        self.level_cells = np.full((S, N), EMPTY, dtype=np.uint8)
        self.level_start = np.zeros(S, dtype=np.intp)
        self._level_obs = np.zeros((S, self.channels * N), dtype=np.uint8)
        self._level_bits = np.zeros((S, N), dtype=np.uint64)
        self._tables = rule_tables(classic, enemy)
        # Dynamic state.
        self.grid = np.full(n * N, EMPTY, dtype=np.uint8)  # (n * N,) cell codes
        self.obs = np.zeros((n, self.channels, height, width), dtype=np.uint8)
        self._obs_flat = self.obs.reshape(-1)
        self._grow = np.arange(n, dtype=np.intp) * N  # first grid index of each env
        self._orow = np.arange(n, dtype=np.intp) * (self.channels * N)  # first obs index
        self.pos = np.zeros(n, dtype=np.intp)
        self._key = np.zeros(n, dtype=np.intp)
        self._opos = self._orow.copy()  # obs index of the agent's cell (plane 0)
        self.under = np.full(n, EMPTY, dtype=np.uint8)  # cell code under the agent
        self.holding = np.zeros(n, dtype=np.uint8)
        self.removed = np.zeros(n, dtype=np.uint64)  # bits of removed swords/enemies
        self.t = np.zeros(n, dtype=np.int64)
        # Observation update tables indexed by cell code: the plane offset of each
        # code; an empty cell has no plane, so its writes go to the wall plane (always
        # 0 where the agent can be) with value 0, which keeps every write of a step
        # at a distinct index or a repeat of the same value.
        code = np.arange(NUM_CELL_CODES)
        plane = np.where(code == EMPTY, WALL, ENTITY_OF_CELL)
        self._plane_off = plane.astype(np.intp) * N
        self._plane_val = (code != EMPTY).astype(np.uint8)
        self._write_at = np.empty((n, 2), dtype=np.intp)  # scratch for the paired writes
        self._write_val = np.empty((n, 2), dtype=np.uint8)

    # -- levels ---------------------------------------------------------------

    def set_levels(self, slots: np.ndarray, cells: np.ndarray, starts: np.ndarray) -> None:
        """Install levels into slots: compile moves, initial observations, object bits."""
        N = self.cells_per_level
        slots = np.asarray(slots, dtype=np.intp)
        cells = np.asarray(cells, dtype=np.uint8).reshape(len(slots), N)
        starts = np.asarray(starts, dtype=np.intp)
        k, S = len(slots), self.num_slots
        dest, code = compile_moves(cells, self.height, self.width, self.classic)
        dest = dest.reshape(k, N * 4)
        self._dest_pos.reshape(S, N * 4)[slots] = dest
        dest *= 4
        dest += slots[:, None] * (N * 4)
        self._dest_key.reshape(S, N * 4)[slots] = dest
        self._mcode.reshape(S, N * 4)[slots] = code.reshape(k, N * 4)
        self.level_cells[slots] = cells
        self.level_start[slots] = starts
        planes = (
            onehot_planes(cells, starts)
            if self.obs_mode == "onehot"
            else grey_planes(cells, starts)
        )
        self._level_obs[slots] = planes.reshape(len(slots), -1)
        self._level_bits[slots] = removable_bits(cells)

    def reset_rows(self, rows: np.ndarray | None = None) -> None:
        """Start new episodes in the given environments (all when None) from their slots."""
        N = self.cells_per_level
        if rows is None:
            rows = np.arange(self.n)
        slots = self.slot[rows]
        start = self.level_start[slots]
        self.pos = self.pos.copy()
        self.pos[rows] = start
        self._key[rows] = slots * (N * 4) + start * 4
        self._opos[rows] = self._orow[rows] + start
        self.grid.reshape(self.n, N)[rows] = self.level_cells[slots]
        self.obs.reshape(self.n, -1)[rows] = self._level_obs[slots]
        self.under[rows] = EMPTY
        self.holding = self.holding.copy()
        self.holding[rows] = 0
        self.removed = self.removed.copy()
        self.removed[rows] = 0
        self.t[rows] = 0

    def place(self, row: int, pos: int, holding: bool) -> None:
        """Start env ``row`` over with its agent on cell ``pos`` (for analysis and tests).

        The map is the level's initial one; ``holding`` also takes the level's
        swords off the map, as if the agent had picked them up.
        """
        N = self.cells_per_level
        slot = int(self.slot[row])
        cells = self.level_cells[slot].copy()
        removed = np.uint64(0)
        swords = cells == SWORD
        if holding and swords.any():
            removed = np.bitwise_or.reduce(self._level_bits[slot][swords])
            cells[swords] = EMPTY
        self.reset_rows(np.array([row]))
        self.grid.reshape(self.n, N)[row] = cells
        self.pos[row] = pos
        self._key[row] = slot * (N * 4) + pos * 4
        self._opos[row] = self._orow[row] + pos
        self.under[row] = cells[pos]
        self.holding[row] = bool(holding)
        self.removed[row] = removed
        start = np.array([pos])
        if self.obs_mode == "onehot":
            planes = onehot_planes(cells[None], start)
            planes[:, HOLD_PLANE] = bool(holding)
        else:
            planes = grey_planes(cells[None], start)
        self.obs.reshape(self.n, -1)[row] = planes.reshape(-1)

    # -- the step -----------------------------------------------------------

    def step(self, actions: np.ndarray) -> StepResult:
        """Apply one action per environment; update state and observation in place."""
        a = np.asarray(actions)
        if a.shape != (self.n,):
            raise ValueError(f"expected {self.n} actions (shape ({self.n},)), got shape {a.shape}")
        if a.dtype != np.intp:
            if a.dtype.kind not in "iu":
                raise ValueError(f"actions must be integers 0..3, got dtype {a.dtype}")
            a = a.astype(np.intp)
        if a.view(np.uintp).max() > 3:
            raise ValueError(
                f"actions must be 0 up, 1 right, 2 down or 3 left; got {a[(a < 0) | (a > 3)][:5]}"
            )
        T = self._tables
        # Where each agent goes: one gather per static table.
        flat = self._key + a
        new = self._dest_pos.take(flat)
        self._key = self._dest_key.take(flat)
        mc = self._mcode.take(flat)
        gidx = self._grow + new
        cell = self.grid.take(gidx)
        # What happens there: one gather per rule table.
        if self.classic:
            held = self.holding * (self.pos != 0)  # the original's `state > nS_pos` test
            idx = cell * 4 + held * 2 + self.holding
        else:
            idx = cell * 4 + self.holding * 2 + (mc & MV_STAY)
        reward = T.reward.take(idx)
        terminated = T.terminated.take(idx)
        events = T.events.take(idx) | MOVE_EVENTS.take(mc)
        new_cell = T.new_cell.take(idx)
        self.grid[gidx] = new_cell
        holding = T.new_holding.take(idx)
        special = T.special.take(idx)
        if special.any():  # rare: a sword picked up, an object removed, a blocked step
            self._special(np.flatnonzero(special), idx, new, cell, new_cell, holding)
        # Observation: restore the cell left behind, then draw the agent on the new one.
        o_new = self._orow + new
        obs = self._obs_flat
        if self.channels == 1:
            obs[self._opos] = GREY_OF_CELL.take(self.under)
            obs[o_new] = GREY_AGENT
        else:
            # Two writes per env and pass, side by side so each env's cache lines are
            # loaded once per pass: (agent plane <- 0, left cell's plane <- 1), then
            # (entered cell's plane <- 0, agent plane <- 1).
            o_old, where, val = self._opos, self._write_at, self._write_val
            where[:, 0] = o_old
            np.add(o_old, self._plane_off.take(self.under), out=where[:, 1])
            val[:, 0] = 0
            val[:, 1] = self._plane_val.take(self.under)
            obs[where] = val
            np.add(o_new, self._plane_off.take(cell), out=where[:, 0])
            where[:, 1] = o_new
            val[:, 1] = 1
            obs[where] = val
        self._opos = o_new
        self.under = new_cell
        self.holding = holding
        self.pos = new
        self.t += 1
        truncated = (self.t >= self.max_steps) > terminated
        return StepResult(reward, terminated, truncated, events)

    def _special(
        self,
        rows: np.ndarray,
        idx: np.ndarray,
        new: np.ndarray,
        cell: np.ndarray,
        new_cell: np.ndarray,
        holding: np.ndarray,
    ) -> None:
        """The rare steps: removed objects' bits, the holding plane, blocked steps.

        A blocked step (enemy="block") takes the agent back to the cell it came
        from: ``new``, ``cell`` (what the agent stands on) and ``new_cell`` (what
        will be under it) are rewritten in place for those rows, as for a bump.
        """
        T = self._tables
        gone = rows[T.removes.take(idx[rows])]
        if len(gone):
            self.removed = self.removed.copy()
            self.removed[gone] |= self._level_bits[self.slot[gone], new[gone]]
        back = rows[T.blocked.take(idx[rows])]
        if len(back):
            here = self.pos[back]
            new[back] = here
            self._key[back] = self.slot[back] * (self.cells_per_level * 4) + here * 4
            cell[back] = self.under[back]
            new_cell[back] = self.under[back]
        if self.channels > 1:
            picked = rows[holding[rows] > self.holding[rows]]
            self.obs[picked, HOLD_PLANE] = 1

    # -- views ----------------------------------------------------------------

    def entity_grid(self) -> np.ndarray:
        """(n, H, W) entity codes of the current states, the agent's cell ``agent``."""
        ent = ENTITY_OF_CELL[self.grid].reshape(self.n, -1)
        ent[np.arange(self.n), self.pos] = AGENT
        return ent.reshape(self.n, self.height, self.width).astype(np.int64)
