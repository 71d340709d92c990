"""The network's relation facts of live states, as ``neurosym extract`` writes them.

A strategy that reads ``holds/5``, ``attends/8`` or ``attention/6`` needs
them for the state being played: :class:`RelationFacts` runs the network on
the live observations (``introspect=True``) and writes, for episode E and
state T, what the recorder and the fact writer make of a recorded state
(:mod:`neurosym.export.recorder`, :mod:`neurosym.export.facts`):

* PrediNet: ``attends(E, T, Head, Arg, Entity, Row, Col, Weight)`` for the
  argmax cell of each head's two attentions, and ``holds(E, T, r(J), A, B)``
  for each head's relation J whose |value| exceeds ``threshold(J)``,
  oriented so the value is positive (one fact per E, T, J, A, B);
* MHDPA: ``attention(E, T, Head, Query, Key, Weight)`` for every query cell
  that is not empty or wall, with its strongest key.

Entities are the entity grid's names before the step. Thresholds are those of
the KB the strategy was learned from: ``threshold/2`` in the strategy file,
or read from that KB (``thresholds=``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from neurosym.errors import ConfigError
from neurosym.play import live
from neurosym.play.policy import Policy

_BACKGROUND = ("empty", "wall")
"""entities that are never MHDPA queries (as in the recorder)"""


class RelationFacts:
    """Relation facts of live states from a loaded network (:class:`~neurosym.agent.checkpoint.Agent`)."""

    def __init__(
        self, network: Any, kb: Any, policy: Policy, thresholds: dict[int, float] | None = None
    ) -> None:
        self.network = network
        self.module = network.config.module
        self.thresholds: dict[int, float] = {}
        if self.module == "predinet":
            if thresholds is None:
                rows = kb.query("current_predicate(threshold/2), threshold(J, V)")
                thresholds = {int(r["J"]): float(r["V"]) for r in rows}
            if not thresholds:
                raise ConfigError(
                    f"{policy.path} reads the network's relations but has no threshold/2 for "
                    "holds/5: give the KB it was learned from (--kb)"
                )
            self.thresholds = thresholds

    def facts(self, obs: np.ndarray, venv: Any, live_rows: list[int]) -> dict[int, list[Any]]:
        """Sub-env -> the encoded relation facts of its current state (E, T from ``venv``)."""
        rows = np.asarray(live_rows)
        grids = np.asarray(venv.entity_grid())
        n, H, W = grids.shape
        grid = grids.reshape(n, -1)[rows]
        names = np.asarray(venv.names, dtype=object)
        _, intro = self.network.act(obs[rows], greedy=True, introspect=True)
        out: dict[int, list[Any]] = {}
        for k, i in enumerate(live_rows):
            e, t = int(venv.episode[i]), int(venv.t[i])
            if self.module == "predinet":
                out[i] = self._predinet(e, t, grid[k], names, W, intro, k)
            else:
                out[i] = self._mhdpa(e, t, grid[k], names, W, intro, k)
        return out

    def _predinet(
        self, e: int, t: int, grid: np.ndarray, names: np.ndarray, W: int, intro: Any, k: int
    ) -> list[Any]:
        facts: list[Any] = []
        a1, a2 = np.asarray(intro.attention1[k]), np.asarray(intro.attention2[k])  # (H, N)
        rel = np.asarray(intro.relations[k])  # (H, J)
        i1, i2 = a1.argmax(-1), a2.argmax(-1)
        ent1, ent2 = names[grid[i1]], names[grid[i2]]
        for h in range(len(i1)):
            for arg, idx, att in ((1, i1[h], a1), (2, i2[h], a2)):
                entity = ent1[h] if arg == 1 else ent2[h]
                facts.append(_fact("attends", e, t, h, arg, live.encode(str(entity)),
                                   int(idx) // W, int(idx) % W, float(att[h, idx])))  # fmt: skip
        seen: set[tuple[int, str, str]] = set()
        for h in range(rel.shape[0]):
            for j in range(rel.shape[1]):
                value = float(rel[h, j])
                if not abs(value) > self.thresholds.get(j, np.inf):
                    continue
                a, b = (str(ent1[h]), str(ent2[h])) if value >= 0 else (str(ent2[h]), str(ent1[h]))
                if (j, a, b) not in seen:
                    seen.add((j, a, b))
                    facts.append(
                        _fact("holds", e, t, ("$t", "r", [j]), live.encode(a), live.encode(b))
                    )
        return facts

    def _mhdpa(
        self, e: int, t: int, grid: np.ndarray, names: np.ndarray, W: int, intro: Any, k: int
    ) -> list[Any]:
        att = np.asarray(intro.attention[k])  # (H, N, N) query x key
        top = att.argmax(-1)  # (H, N)
        query = names[grid]
        keep = ~np.isin(query, _BACKGROUND)
        facts: list[Any] = []
        for h in range(att.shape[0]):
            for q in np.flatnonzero(keep):
                key = int(top[h, q])
                facts.append(_fact("attention", e, t, h, live.encode(str(query[q])),
                                   live.encode(str(names[grid[key]])), float(att[h, q, key])))  # fmt: skip
        return facts


def _fact(name: str, *args: Any) -> Any:
    return ("$t", name, list(args))
