"""A KB's acted states grounded on the background predicates: the learner's examples.

:func:`ground` loads a KB, tells its env family, loads the family's background
(:data:`~neurosym.induce.background.FAMILIES`) as its rule file and asks Prolog
for every answer of the family's body predicates (RGW and Box-World
``ahead/3``, ``left_of_ahead/3``, ``right_of_ahead/3``, ``holding/3``,
``on_map/3``; Minigrid ``action/3``, ``ahead/3``, ``ahead_door/3``,
``carrying/3``) at the states with a ``step/4`` fact, plus the events. The learner then works on
these answers as dense boolean matrices (state x value), so what it learns
from is exactly what Prolog derives from the same facts.
"""

from __future__ import annotations

import os
import re
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from neurosym.errors import ConfigError
from neurosym.induce.background import COLOURED, FAMILIES
from neurosym.terms import format_value

PREDICATES = FAMILIES["rgw"].predicates
"""RGW's and Box-World's body predicates (the default bias's)"""
_COLOURED = re.compile(r"(" + "|".join(COLOURED) + r")\(([a-z][A-Za-z0-9_]*)\)")


@dataclass
class Grounded:
    """The acted states of a KB and what the background predicates say about each.

    ``keys`` (S, 2) holds (episode, t) of state s; ``matrix[pred][s, v]`` is
    true when ``pred(E, T, values[v])`` holds; ``events`` has columns ``s,
    event`` (event text).
    """

    source: str
    env: str
    family: str
    keys: np.ndarray
    values: list[str]
    matrix: dict[str, np.ndarray]
    events: pd.DataFrame
    colours: list[str]

    def __post_init__(self) -> None:
        self.value_index = {v: i for i, v in enumerate(self.values)}
        self.colour_index = {c: i for i, c in enumerate(self.colours)}
        nc = len(self.colours)
        self.colour_column: dict[str, np.ndarray] = {}  # functor -> (colours,) value index or -1
        self.functor_columns: dict[str, np.ndarray] = {}
        for f in COLOURED:
            col = np.full(nc, -1, dtype=np.int64)
            for v, text in enumerate(self.values):
                m = _COLOURED.fullmatch(text)
                if m and m.group(1) == f:
                    col[self.colour_index[m.group(2)]] = v
            self.colour_column[f] = col
            self.functor_columns[f] = col[col >= 0]

    @property
    def n_states(self) -> int:
        return len(self.keys)

    @property
    def n_episodes(self) -> int:
        return len(np.unique(self.keys[:, 0])) if len(self.keys) else 0

    def constants(self, pred: str) -> list[str]:
        """The uncoloured values ``pred`` takes somewhere, in value order."""
        seen = self.matrix[pred].any(axis=0)
        return [v for i, v in enumerate(self.values) if seen[i] and not _COLOURED.fullmatch(v)]

    def functors(self, pred: str) -> list[str]:
        """The coloured types (``key``, ``lock``) ``pred`` takes somewhere."""
        m = self.matrix[pred]
        return [
            f
            for f in COLOURED
            if len(self.functor_columns[f]) and m[:, self.functor_columns[f]].any()
        ]


def _canonical(column: pd.Series) -> pd.Series:
    """Each value as its canonical Prolog text (:func:`neurosym.terms.format_value`): the atom
    ``'Wall'`` stays quoted, so a clause written with it reads back as the atom, not a variable."""
    cache: dict[tuple[type, object], str] = {}

    def text(value: object) -> str:
        try:
            key = (type(value), value)
            if key not in cache:
                cache[key] = format_value(value)
            return cache[key]
        except TypeError:  # a list: not hashable
            return format_value(value)

    return column.map(text)


_MINIGRID_TYPE = re.compile(r"(door|ball|box)\(.*\)|goal")


def env_family(types: list[str], env: str) -> str:
    """The env family (``rgw``, ``boxworld`` or ``minigrid``) of a KB with these object types
    and this env."""
    env = env.strip("'")
    if env.startswith(("MiniGrid-", "BabyAI-")) or any(_MINIGRID_TYPE.fullmatch(t) for t in types):
        return "minigrid"
    if env.startswith(("bw", "boxworld")) or any(
        _COLOURED.fullmatch(t) or t == "gem" for t in types
    ):
        return "boxworld"
    return "rgw"


def ground(kb_path: str | os.PathLike[str]) -> Grounded:
    """Load the KB at ``kb_path`` and ground the background predicates on its acted states.

    A missing file or a KB without ``step/4`` or ``event/3`` facts is a
    one-line :class:`ConfigError`.
    """
    from neurosym.prolog.knowledge_base import KnowledgeBase

    path = Path(kb_path)
    if not path.is_file():
        raise ConfigError(
            f"KB {path} does not exist (give a knowledge base written by neurosym extract)"
        )
    with tempfile.TemporaryDirectory(prefix="neurosym-induce-") as tmp, KnowledgeBase(path) as kb:
        family = _family(kb)
        rules = Path(tmp) / "background.pl"
        rules.write_text(FAMILIES[family].background)
        kb.load_rules(rules)
        return _ground(kb, path, family)


def _family(kb: object) -> str:
    """The KB's env family, from its ``kb_meta(env, _)`` and its objects' types."""
    meta = kb.query_df("kb_meta(env, V)")  # type: ignore[attr-defined]
    env = str(meta["V"].iloc[0]) if len(meta) else ""
    types = [str(t) for t in kb.query_df("object(_, Ty)")["Ty"]]  # type: ignore[attr-defined]
    return env_family(types, env)


def _ground(kb: object, path: Path, family: str) -> Grounded:
    steps = kb.query_df("step(E, T, _, _)")  # type: ignore[attr-defined]
    if steps.empty:
        raise ConfigError(f"KB {path} has no step/4 facts: nothing to learn world rules from")
    events = kb.query_df("event(E, T, X)")  # type: ignore[attr-defined]
    if events.empty:
        raise ConfigError(f"KB {path} has no event/3 facts: nothing to learn world rules from")
    if kb.query_df("grid(E, _, _)", limit=1).empty:  # type: ignore[attr-defined]
        raise ConfigError(
            f"KB {path} has no grid/3 facts (written by neurosym extract since terrain/4 and grid/3 "
            "were added): extract it again"
        )
    meta = kb.query_df("kb_meta(env, V)")  # type: ignore[attr-defined]
    env = str(meta["V"].iloc[0]) if len(meta) else ""
    keys = steps[["E", "T"]].drop_duplicates().sort_values(["E", "T"]).to_numpy(dtype=np.int64)
    index = pd.DataFrame({"E": keys[:, 0], "T": keys[:, 1], "s": np.arange(len(keys))})
    answers = {}
    for pred in FAMILIES[family].predicates:
        df = kb.query_df(f"{pred}(E, T, W), step(E, T, _, _)")  # type: ignore[attr-defined]
        df = df.assign(W=_canonical(df["W"])).merge(index, on=["E", "T"])
        answers[pred] = df[["s", "W"]].drop_duplicates()
    values = sorted(set().union(*(set(df["W"]) for df in answers.values())))
    ev = events.assign(X=_canonical(events["X"])).merge(index, on=["E", "T"])
    colours = sorted({m.group(2) for v in values + list(ev["X"]) for m in _COLOURED.finditer(v)})
    vindex = {v: i for i, v in enumerate(values)}
    matrix = {}
    for pred, df in answers.items():
        m = np.zeros((len(keys), len(values)), dtype=bool)
        m[df["s"].to_numpy(), df["W"].map(vindex).to_numpy()] = True
        matrix[pred] = m
    return Grounded(
        source=str(path),
        env=env,
        family=family,
        keys=keys,
        values=values,
        matrix=matrix,
        events=pd.DataFrame({"s": ev["s"].to_numpy(), "event": ev["X"].to_numpy()}),
        colours=colours,
    )
