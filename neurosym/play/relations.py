"""The network's relation facts of live states, as ``neurosym extract`` writes them.

A strategy that reads ``holds/5``, ``attends/8`` or ``attention/6`` needs
them for the state being played: :class:`RelationFacts` runs the network on
the live observations (``introspect=True``) and hands the introspection to the
module's adapter (:mod:`neurosym.agent.networks.adapters`), the one producer of
a state's relation rows that the recorder also uses; for episode E and state T
the rows become

* ``attends(E, T, Head, Arg, Entity, Row, Col, Weight)`` (PrediNet: the argmax
  cell of each head's two attentions), and ``holds(E, T, r(J), A, B)`` for each
  relation row whose |value| exceeds ``threshold(J)``, oriented so the value is
  positive (one fact per E, T, J, A, B, as the fact writer's ``holds_table``);
* ``attention(E, T, Head, Query, Key, Weight)`` (MHDPA, any attention module):
  every query cell that is not empty or wall, with its strongest key.

Entities are the entity grid's names before the step. Thresholds are those of
the KB the strategy was learned from: ``threshold/2`` in the strategy file,
or read from that KB (``thresholds=``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from neurosym.agent.networks.adapters import adapter_class
from neurosym.errors import ConfigError
from neurosym.play import live
from neurosym.play.policy import Policy


class RelationFacts:
    """Relation facts of live states from a loaded network (:class:`~neurosym.agent.agent.Agent`).

    The rows are the recorder's: the module's adapter keeps and tabulates the live
    states' introspection exactly as it does for a recording (top key 1); here they
    become facts at once, table by table."""

    def __init__(
        self, network: Any, kb: Any, policy: Policy, thresholds: dict[int, float] | None = None
    ) -> None:
        self.network = network
        self.adapter = adapter_class(network.config.module)
        self.thresholds: dict[int, float] = {}
        if self.adapter.has("relations"):
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
        rows = np.asarray(live_rows, dtype=np.int64)
        grids = np.asarray(venv.entity_grid())
        n, _, W = grids.shape
        names = np.asarray(venv.names, dtype=object)
        _, intro = self.network.act(obs[rows], greedy=True, introspect=True)
        ep = np.asarray(venv.episode)[rows].astype(np.int64)
        t = np.asarray(venv.t)[rows].astype(np.int64)
        kept = self.adapter.keep(intro, grids.reshape(n, -1)[rows])
        tables = self.adapter.rows(kept, ep, t, names, W)
        sub_env = {(int(e), int(s)): i for e, s, i in zip(ep, t, live_rows, strict=True)}
        out: dict[int, list[Any]] = {i: [] for i in live_rows}
        for name in ("attends", "relations", "attention"):  # the order of the facts in a state
            if name in tables:
                for key, fact in getattr(self, f"_{name}")(tables[name]):
                    out[sub_env[key]].append(fact)
        return out

    @staticmethod
    def _attends(cols: dict[str, np.ndarray]) -> list[tuple[tuple[int, int], Any]]:
        """attends/8: each head's two argmax cells."""
        return [
            ((e, t), _fact("attends", e, t, h, arg, live.encode(str(ent)), r, c, float(w)))
            for e, t, h, arg, ent, r, c, w in zip(
                *(cols[k].tolist() for k in ("episode", "t", "head", "arg")),
                cols["entity"], cols["row"].tolist(), cols["col"].tolist(), cols["weight"],
                strict=True,
            )
        ]  # fmt: skip

    def _relations(self, cols: dict[str, np.ndarray]) -> list[tuple[tuple[int, int], Any]]:
        """holds/5: relation rows above their threshold, oriented so the value is positive,
        one per (E, T, J, A, B) (the fact writer's ``holds_table``)."""
        out: list[tuple[tuple[int, int], Any]] = []
        seen: set[tuple[int, int, int, str, str]] = set()
        for e, t, j, a, b, value in zip(
            cols["episode"].tolist(), cols["t"].tolist(), cols["j"].tolist(),
            cols["a"], cols["b"], cols["value"].tolist(), strict=True,
        ):  # fmt: skip
            if not abs(value) > self.thresholds.get(j, np.inf):
                continue
            a, b = (str(a), str(b)) if value >= 0 else (str(b), str(a))
            if (e, t, j, a, b) not in seen:
                seen.add((e, t, j, a, b))
                out.append(((e, t), _fact("holds", e, t, ("$t", "r", [j]), live.encode(a),
                                          live.encode(b))))  # fmt: skip
        return out

    @staticmethod
    def _attention(cols: dict[str, np.ndarray]) -> list[tuple[tuple[int, int], Any]]:
        """attention/6: each query cell's strongest key."""
        return [
            ((e, t), _fact("attention", e, t, h, live.encode(str(q)), live.encode(str(k)), float(w)))
            for e, t, h, q, k, w in zip(
                *(cols[c].tolist() for c in ("episode", "t", "head")),
                cols["query"], cols["key"], cols["weight"], strict=True,
            )
        ]  # fmt: skip


def _fact(name: str, *args: Any) -> Any:
    return ("$t", name, list(args))
