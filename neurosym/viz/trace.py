"""One episode as the plots see it, whether it was recorded or played from a checkpoint.

Every picture needs the same few things: what occupies each cell at each state,
where the agent went, and what the relational module computed at each step.
A saved :class:`~neurosym.record.recording.Recording` keeps only the strongest
cells of each attention map, while a checkpoint played live gives the full
maps; :class:`EpisodeTrace` holds both kinds, with ``NaN`` marking the weights
that were not recorded (``complete`` says which kind it is), so one set of
drawing functions serves both sources.

Time follows the recording's convention: states 0..S, state 0 after reset, the
action of step t taken in state t; model outputs exist for states 0..S-1.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import numpy as np
import pandas as pd

from neurosym.errors import ConfigError

OBJECT_COLUMNS = ["t", "object", "type", "row", "col"]
"""columns of :attr:`EpisodeTrace.objects` (the recording's ``positions`` without ``episode``)"""

DOOR_COLUMNS = ["t", "row", "col", "state"]
"""columns of :attr:`EpisodeTrace.doors` (Minigrid)"""

POSITION_COMPONENTS = 4
"""R^h ends with the (row, col) of E1 and of E2"""


@dataclass(frozen=True)
class EpisodeTrace:
    """One episode: the grid at every state plus the relational module's outputs."""

    checkpoint: str
    """name of the checkpoint that acted (used in titles)"""
    env: str
    """short environment name"""
    module: str
    """the relational module's name (``"predinet"``, ``"mhdpa"``)"""
    episode: int
    """episode number in its recording (0 for a live run)"""
    seed: int | None
    """seed the episode's environment was reset with"""
    grids: np.ndarray
    """(S+1, H, W) object array of entity names, what occupies each cell at each state"""
    actions: tuple[str, ...]
    """(S,) action atoms"""
    rewards: np.ndarray
    """(S,) reward of each step"""
    events: pd.DataFrame
    """columns t, event: events of the transition out of state t"""
    outcome: str | None
    """how the episode ended (terminal, pit, timeout, gem, distractor), None if cut short"""
    heads: tuple[int, ...]
    """head numbers as the tables name them"""
    relations: int
    """J, number of PrediNet relations (0 for MHDPA)"""
    complete: bool
    """True when attention maps are full (live run), False when only the strongest cells were kept"""
    attention1: np.ndarray | None = None
    """PrediNet (S, heads, N) weights of a1 over cells; NaN where not recorded"""
    attention2: np.ndarray | None = None
    """PrediNet (S, heads, N) weights of a2 over cells; NaN where not recorded"""
    r_vectors: np.ndarray | None = None
    """PrediNet (S, heads, J + 4): D^h then (row, col) of E1 and of E2"""
    mhdpa: dict[int, np.ndarray] = field(default_factory=dict)
    """MHDPA state t -> (heads, N, N) query x key weights; NaN where not recorded"""
    mhdpa_focus: np.ndarray | None = None
    """MHDPA (S, heads) cell the agent's cell attends to most; -1 where unknown"""
    objects: pd.DataFrame = field(default_factory=lambda: pd.DataFrame(columns=OBJECT_COLUMNS))
    """columns t, object, type, row, col: the named objects (ids such as lock_red_2) per state"""
    facing: tuple[str, ...] = ()
    """Minigrid: (S+1,) the agent's direction at each state (``east``, ``south``, ``west``,
    ``north``); empty for the envs whose agent has none"""
    doors: pd.DataFrame = field(default_factory=lambda: pd.DataFrame(columns=DOOR_COLUMNS))
    """Minigrid: columns t, row, col, state (``open``, ``closed``, ``locked``) of each door"""

    @property
    def steps(self) -> int:
        """S, the number of steps taken."""
        return len(self.actions)

    @property
    def shape(self) -> tuple[int, int]:
        """(H, W) of the grid."""
        return self.grids.shape[1], self.grids.shape[2]

    @property
    def title_name(self) -> str:
        """``rgw2-predinet.pt on rgw2, episode 0 (seed 3)`` for figure titles."""
        name = Path(self.checkpoint).name if self.checkpoint else "untitled agent"
        seed = f" (seed {self.seed})" if self.seed is not None else ""
        return f"{name} on {self.env}, episode {self.episode}{seed}"

    @cached_property
    def agent_path(self) -> np.ndarray:
        """(S+1, 2) (row, col) of the agent at each state; (-1, -1) where it is not on the grid."""
        is_agent = self.grids == "agent"  # (S+1, H, W)
        flat = is_agent.reshape(len(self.grids), -1)
        cell = flat.argmax(axis=1)
        w = self.shape[1]
        path = np.stack([cell // w, cell % w], axis=1)
        path[~flat.any(axis=1)] = -1
        return path

    def direction(self, t: int) -> str | None:
        """The agent's direction in state t (Minigrid), else None."""
        return self.facing[t] if 0 <= t < len(self.facing) else None

    def door_states(self, t: int) -> list[tuple[int, int, str]]:
        """(row, col, state) of every door in state t (Minigrid; [] elsewhere)."""
        rows = self.doors[self.doors["t"] == t]
        return [(int(r), int(c), str(s)) for r, c, s in rows[["row", "col", "state"]].to_numpy()]

    def head_index(self, head: int) -> int:
        """Position of head number ``head`` in the arrays, or a one-line error."""
        if head not in self.heads:
            raise ConfigError(
                f"--head {head} is out of range: this agent has heads {_span(self.heads)}"
            )
        return self.heads.index(head)

    def check_state(self, t: int, *, acted: bool = True) -> None:
        """Refuse a state the episode does not have (``acted``: the model must have seen it)."""
        last = self.steps - 1 if acted else self.steps
        if last < 0:
            raise ConfigError("the episode has no steps to show")
        if not 0 <= t <= last:
            raise ConfigError(
                f"--step {t} is out of range: episode {self.episode} has steps 0..{last}"
            )

    def require(self, module: str, what: str) -> None:
        """Refuse a plot that needs the other relational module."""
        require_module(self.module, module, what, self.checkpoint)

    def locate(
        self, t: int, name: str | None = None, cell: tuple[int, int] | None = None
    ) -> tuple[int, int, str]:
        """(row, col, label) of the object a picture is about at state t.

        ``name`` is an entity (``enemy``, ``key(red)``) or an object id
        (``lock_red_2``); an entity held by several cells (walls, pits, the two
        teleport ends) needs ``cell`` or an id to pick one.
        """
        grid = self.grids[t]
        h, w = self.shape
        if cell is not None:
            row, col = cell
            if not (0 <= row < h and 0 <= col < w):
                raise ConfigError(f"--cell {row},{col} is outside the {h} x {w} grid")
            return row, col, str(grid[row, col])
        name = name or "agent"
        hits = np.argwhere(grid == name)
        now = self.objects.loc[self.objects["t"] == t]
        if len(hits) == 1:
            return int(hits[0][0]), int(hits[0][1]), name
        if len(hits) == 0:
            by_id = now.loc[now["object"] == name]
            if len(by_id) == 1:
                r, c = int(by_id["row"].iloc[0]), int(by_id["col"].iloc[0])
                return r, c, f"{name} = {grid[r, c]}"
            present = ", ".join(sorted(set(grid.ravel().tolist()) - {"empty"}))
            raise ConfigError(
                f"--object {name}: no {name} on the grid at step {t} (there are: {present})"
            )
        where = " ".join(f"{r},{c}" for r, c in hits[:4].tolist()) + (
            " ..." if len(hits) > 4 else ""
        )
        ids = now.loc[now["type"] == name, "object"].astype(str).tolist()
        by = f"--cell ({where})" + (
            f" or an id ({', '.join(ids[:4])})" if 0 < len(ids) <= 4 else ""
        )
        raise ConfigError(
            f"--object {name}: {len(hits)} cells hold {name} at step {t}; pick one with {by}"
        )

    def event_text(self, t: int) -> str:
        """Events of the transition out of state t, comma separated."""
        if self.events.empty:
            return ""
        return ", ".join(self.events.loc[self.events["t"] == t, "event"].astype(str))


def require_module(found: str, wanted: str, what: str, checkpoint: str) -> None:
    """One-line refusal when a plot for ``wanted`` is asked of an agent with module ``found``."""
    if found == wanted:
        return
    from neurosym.agent.networks.adapters import adapter_class, module_names

    name = Path(checkpoint).name if checkpoint else "this agent"
    found_text = adapter_class(found).article if found in module_names() else f"a {found!r}"
    raise ConfigError(
        f"{what} needs {adapter_class(wanted).article} agent, but {name} is {found_text} agent"
    )


def _span(values: tuple[int, ...]) -> str:
    if not values:
        return "none"
    if list(values) == list(range(values[0], values[-1] + 1)):
        return f"{values[0]}..{values[-1]}"
    return ", ".join(map(str, values))
