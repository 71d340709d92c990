"""The knowledge bases' fact schema, declared once.

Every predicate a neurosym KB holds is one :class:`Predicate`: its name, its
arguments (the table column each comes from, the name rules and docs call it,
and its kind), one line of meaning, and the commands that write it. The fact
tables, the writers' ``:- dynamic`` lines and ``%!`` header lines, and the
schema tables of docs/design.md are made from these declarations.

A new predicate is one declaration here plus the code that fills its table
(docs/design.md, "Facts", says where).

Argument kinds: ``int``, ``float``, ``atom`` (a plain name), ``term`` (a table
column of Prolog term text such as ``key(red)``, written as the term, not a
quoted atom) and ``value`` (any Python value the writer spells: a number, a
name, a :class:`~neurosym.terms.Term`).
"""

from __future__ import annotations

import re
import textwrap
from collections.abc import Iterable
from dataclasses import dataclass

KINDS = ("int", "float", "atom", "term", "value")
_VARIABLE = re.compile(r"[A-Z_][A-Za-z0-9_]*|[a-z][A-Za-z0-9_]*\([A-Z_][A-Za-z0-9_]*\)")
"""what a reader's goal puts in an argument: a variable, or one wrapped (``r(J)`` of holds/5)"""


@dataclass(frozen=True)
class Arg:
    """One argument: the table column it is read from, its name in rules and docs, its kind."""

    column: str
    name: str
    kind: str

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"argument {self.column}: unknown kind {self.kind!r}")

    @property
    def dtype(self) -> str:
        """The column's dtype in a recording table (``str``: Prolog text)."""
        return {"int": "int64", "float": "float64"}.get(self.kind, "str")


@dataclass(frozen=True)
class Predicate:
    """One KB predicate: ``name(args...)``, what it means, which group of KBs and commands hold it."""

    name: str
    args: tuple[Arg, ...]
    meaning: str
    group: str
    """``trace`` (extract's KBs; intervene's hold the behavioural part), ``probe``, ``experiment``"""
    writers: tuple[str, ...]

    @property
    def arity(self) -> int:
        return len(self.args)

    @property
    def indicator(self) -> str:
        return f"{self.name}/{self.arity}"

    @property
    def columns(self) -> tuple[str, ...]:
        return tuple(a.column for a in self.args)

    @property
    def term_columns(self) -> tuple[str, ...]:
        return tuple(a.column for a in self.args if a.kind == "term")

    @property
    def head(self) -> str:
        """``name(Arg, ...)`` as rules and docs write it."""
        return f"{self.name}({', '.join(a.name for a in self.args)})"

    @property
    def per_state(self) -> bool:
        """Whether each fact is of one state: the first arguments are the episode and the state."""
        return self.columns[:2] == ("episode", "t")

    def __post_init__(self) -> None:
        if len(self.meaning.splitlines()) != 1:
            raise ValueError(f"{self.name}: the meaning must be one line (it is a KB comment)")

    def goal(self, **variables: str) -> str:
        """A reader's goal: ``name(...)`` with the named columns as those variables, ``_`` elsewhere.

        ``SCHEMA["at"].goal(episode="E", t="T", id="O")`` is ``at(E, T, O, _, _)``;
        a column the predicate lacks, or a name that is not a Prolog variable, is
        refused, so a reader's goals follow the declarations.
        """
        unknown = sorted(set(variables) - set(self.columns))
        if unknown:
            raise ValueError(
                f"{self.indicator} has no column {', '.join(unknown)}; "
                f"its columns: {', '.join(self.columns)}"
            )
        bad = [v for v in variables.values() if not _VARIABLE.fullmatch(v)]
        if bad:
            raise ValueError(f"{self.indicator}: {bad[0]!r} is not a Prolog variable (or r(J))")
        return f"{self.name}({', '.join(variables.get(c, '_') for c in self.columns)})"


def _p(name: str, args: str, meaning: str, group: str, writers: str) -> Predicate:
    """A declaration from ``column:Name:kind`` words (``column:kind`` when Name is the column)."""
    parsed = []
    for word in args.split():
        parts = word.split(":")
        column, kind = parts[0], parts[-1]
        parsed.append(Arg(column, parts[1] if len(parts) == 3 else column.capitalize(), kind))
    return Predicate(name, tuple(parsed), meaning, group, tuple(writers.split()))


TRACE, PROBE, EXPERIMENT = "trace", "probe", "experiment"

SCHEMA: dict[str, Predicate] = {
    p.name: p
    for p in (
        _p("kb_meta", "key:value value:value",
           "checkpoint, env, module, heads, relations, seed, actions (`agent` or `random`), "
           "created, version, threshold; then `env_option(Name)` for each option the env was "
           "made with (the checkpoint's and `--env-option`'s: `kb_meta(env_option(num_mountains), "
           "12)`, `none` for None; none on an env's defaults)",
           TRACE, "extract probe intervene"),
        _p("object", "id:Id:atom type:term", "every named object of the recorded maps",
           TRACE, "extract intervene"),
        _p("episode", "episode:E:int steps:int return:float outcome:atom",
           "Outcome: `terminal`, `pit`, `enemy`, `timeout`, `gem`, `distractor`; Minigrid `goal`, "
           "`mission`, `lava`, `failure`",
           TRACE, "extract intervene"),
        _p("grid", "episode:E:int rows:int cols:int",
           "the size of episode E's map (the entity grid's shape)", TRACE, "extract intervene"),
        _p("terrain", "episode:E:int type:term row:int col:int",
           "every non-empty cell of E's map after the reset that holds no object and is not "
           "the agent (RGW `wall`, `mountain`; Box-World `wall`; Minigrid `wall`, `lava`, "
           "`floor`); terrain never changes within an episode", TRACE, "extract intervene"),
        _p("optimal_visits", "episode:E:int order:term",
           "the key objects of E's level in the order its fastest optimal route first reaches "
           "them, as the env's own solver plays it (RGW: `[sword, teleport, enemy, terminal]` on "
           "rgw2; the first of equally fast routes); none for a level without an optimal return "
           "(unsolvable, or too large to search) and none on Box-World or Minigrid",
           TRACE, "extract intervene"),
        _p("step", "episode:E:int t:T:int action:atom reward:float",
           "the action taken in state T (`up, right, down, left`; Minigrid `left, right, forward, "
           "pickup, drop, toggle, done`) and its reward",
           TRACE, "extract intervene"),
        _p("at", "episode:E:int t:T:int id:Id:atom row:int col:int",
           "where object Id is in state T (T in 0..S)", TRACE, "extract intervene"),
        _p("holding", "episode:E:int t:T:int item:term",
           "what the agent holds in state T (`sword`, `key(red)`)", TRACE, "extract intervene"),
        _p("event", "episode:E:int t:T:int event:term",
           "an event of the step from state T to T+1 (`picked(sword)`, `defeated(enemy)`, "
           "`opened(lock(red))`, ...)", TRACE, "extract intervene"),
        _p("facing", "episode:E:int t:T:int direction:Dir:atom",
           "the agent's direction in state T (Minigrid: `east`, `south`, `west`, `north`)",
           TRACE, "extract"),
        _p("door_state", "episode:E:int t:T:int id:Id:atom state:atom",
           "the state of door Id in state T (Minigrid: `open`, `closed`, `locked`)",
           TRACE, "extract"),
        _p("mission", "episode:E:int text:atom",
           "episode E's mission as the env words it (Minigrid, BabyAI: `go to the red ball`)",
           TRACE, "extract"),
        _p("attends",
           "episode:E:int t:T:int head:int arg:int entity:term row:int col:int weight:float",
           "PrediNet: Arg 1 or 2, the argmax cell of a1 or a2, the entity there and its weight",
           TRACE, "extract"),
        _p("relation", "episode:E:int t:T:int head:int j:J:int a:A:term b:B:term value:float",
           "PrediNet: D^h_j between the two attended entities A (arg 1) and B (arg 2)",
           TRACE, "extract"),
        _p("holds", "episode:E:int t:T:int j:r(J):term a:A:term b:B:term",
           "relation J's value had |value| above `threshold(J, _)`, oriented so that it is "
           "positive", TRACE, "extract"),
        _p("threshold", "j:J:int value:float", "the threshold used for relation J",
           TRACE, "extract"),
        _p("attention", "episode:E:int t:T:int head:int query:term key:term weight:float",
           "MHDPA: each query cell's strongest key (`--top-keys N`: N of them)",
           TRACE, "extract"),
        _p("faithfulness", "target:atom features:atom score:float states:int episodes:int",
           "Target `next_object` or `action`: the share Score of States held-out states (of "
           "Episodes held-out episodes) whose target a decision tree learned on the other "
           "episodes predicts from Features: `relations` (the network's relation facts), "
           "`world` (world facts only), `untrained_relations` (an untrained network of the same "
           "config on the same states: the control) or `chance` (a uniform pick among the "
           "objects; the commonest action)",
           TRACE, "extract"),
        _p("probe", "head:int j:J:value predicate:term accuracy:float control:float",
           "held-out accuracy and control accuracy", PROBE, "probe"),
        _p("probe_untrained", "head:int j:J:value predicate:term accuracy:float control:float",
           "the same on an untrained network of the same shape", PROBE, "probe"),
        _p("probe_skipped", "predicate:term reason:atom",
           "predicates constant on the recorded states", PROBE, "probe"),
        _p("experiment", "x:X:atom kind:value detail:value",
           "X `baseline` or e.g. `remove_sword`; Kind `baseline`, `remove(sword)`, "
           "`remove(enemy)`, `move(enemy, R, C)`, `move(sword, R, C)`, `swap(sword, enemy)`, "
           "`ablate(head(H))`, `ablate(heads)`; Detail what was changed (the cells, or "
           "`every_level(Edit)` on rgw-random)", EXPERIMENT, "intervene"),
        _p("experiment_episode", "x:X:atom episode:E:int", "episode E belongs to experiment X",
           EXPERIMENT, "intervene"),
        _p("experiment_skipped", "kind:value reason:atom",
           "an experiment that does not apply (moving an object on procedural levels)",
           EXPERIMENT, "intervene"),
        _p("measure", "experiment:X:atom measure:value value:float",
           "Measure `return`, `success`, `steps`, `sword_picked`, `sword_before_enemy`, "
           "`enemy_met`, `enemy_unarmed`, `enemy_defeated` (means over X's episodes; RGW)",
           EXPERIMENT, "intervene"),
        _p("effect", "experiment:X:atom measure:value value:Change:float",
           "the measure's change against the baseline, and at the baseline's own states `kl` "
           "(of the action distributions), `relation_shift(H, J)` (PrediNet: mean absolute "
           "change of D^h_j) or `head_shift(H)` (MHDPA)", EXPERIMENT, "intervene"),
        _p("relates", "head:int a:A:term b:B:term share:float",
           "the share of baseline states on which Head relates A to B", EXPERIMENT, "intervene"),
    )
}


def group(name: str) -> list[Predicate]:
    """The predicates of one group, in declaration order."""
    return [p for p in SCHEMA.values() if p.group == name]


def written_by(command: str, group_name: str | None = None) -> list[Predicate]:
    """The predicates ``command`` writes (of one group if given), in declaration order."""
    return [
        p for p in SCHEMA.values()
        if command in p.writers and group_name in (None, p.group)
    ]


def indicators(names: Iterable[str]) -> list[str]:
    """``name/arity`` of the named predicates (for ``:- dynamic``)."""
    return [SCHEMA[n].indicator for n in names]


def term_columns(names: Iterable[str]) -> dict[str, tuple[str, ...]]:
    """The writer's ``term_columns`` for the named predicates (those that have any)."""
    return {n: SCHEMA[n].term_columns for n in names if SCHEMA[n].term_columns}


def header_lines(name: str) -> list[str]:
    """The PlDoc comment a KB writes above the predicate's dynamic declaration.

    ``%!  grid(?E, ?Rows, ?Cols)`` (its arguments; every one ``?``: a fact
    answers any mode), then ``%   the size of episode E's map ...`` (its
    meaning, wrapped at 100 columns).
    """
    p = SCHEMA[name]
    head = f"%!  {p.name}({', '.join('?' + a.name for a in p.args)})"
    body = textwrap.wrap(
        p.meaning, 100, initial_indent="%   ", subsequent_indent="%   ",
        break_long_words=False, break_on_hyphens=False,
    )
    return [head, *body]


def comments(names: Iterable[str]) -> dict[str, list[str]]:
    """``name/arity`` -> :func:`header_lines`, the writer's ``comments`` for the named predicates."""
    return {SCHEMA[n].indicator: header_lines(n) for n in names}


def markdown_table(name: str) -> str:
    """The schema table of one group, as docs/design.md shows it."""
    rows = ["| fact | arguments |", "| --- | --- |"]
    rows += [f"| `{p.head}` | {p.meaning} |" for p in group(name)]
    return "\n".join(rows)
