"""A FOIL-style clause search over a declared language bias, on grounded examples.

Head: ``predicts(E, T, Event)`` for one event template of the vocabulary
(``picked(sword)``, ``opened(lock(C))``). Body literals (the bias), each
about state T of episode E:

* ``P(E, T, Value)`` and ``\\+ P(E, T, Value)`` for P a body predicate of the
  bias (the env family's: RGW and Box-World ahead/3, left_of_ahead/3,
  right_of_ahead/3, holding/3, on_map/3; Minigrid action/3, ahead/3,
  ahead_door/3, carrying/3), Value an uncoloured constant the data shows
  (``sword``, ``wall``, ``border``, ``empty``, ``toggle``, ``nothing``);
* ``P(E, T, F(V))`` for F a coloured type (``key``, ``lock``, ``door``) and V the
  head's colour variable, a variable already in the clause, a new variable
  (at most :attr:`Bias.max_new_vars` in a clause) or ``_``; negated only with
  a bound variable or ``_`` (so negation is always safe).

Colours never appear as constants: a rule about colours says it with
variables or not at all. Clauses are grown one literal at a time by FOIL's
information gain, with one literal of lookahead when no single literal
gains (a literal that only introduces a variable), until they cover no
negative example; then sequential covering removes the positives covered
and starts the next clause. Examples are closed-world: a head instance
a body derives at a state where the KB records no such event is negative.
Finished clauses are pruned (a literal whose removal keeps the clause free
of negatives goes) and clauses whose positives others cover are dropped.
"""

from __future__ import annotations

import math
import re
from collections import Counter
from dataclasses import dataclass, field, replace

import numpy as np

from neurosym.induce.background import FAMILIES, STEP_BOUND
from neurosym.induce.examples import PREDICATES, Grounded
from neurosym.terms import Term, Var, parse_term

HEAD_VAR = "C"
_TEMPLATE_VAR = re.compile(r"\b" + HEAD_VAR + r"\b")


@dataclass(frozen=True)
class Bias:
    """Limits of the clause search."""

    max_literals: int = 5
    max_new_vars: int = 2
    max_clauses: int = 8
    predicates: tuple[str, ...] = PREDICATES


@dataclass(frozen=True)
class Literal:
    """``[\\+] pred(E, T, value)``; value is a constant, or ``functor(var)`` with var a name or ``_``."""

    pred: str
    value: str
    functor: str | None = None
    var: str | None = None
    negated: bool = False

    def text(self) -> str:
        """The literal as Prolog text; ``value`` is already canonical (:func:`neurosym.terms.format_value`)."""
        arg = f"{self.functor}({self.var})" if self.functor else self.value
        neg = "\\+ " if self.negated else ""
        return f"{neg}{self.pred}(E, T, {arg})"

    def term(self) -> Term:
        """The literal as the term its text must read back as."""
        arg = Term(self.functor, (Var(self.var or "_"),)) if self.functor else parse_term(self.value)
        goal = Term(self.pred, (Var("E"), Var("T"), arg))
        return Term("\\+", (goal,)) if self.negated else goal

    @property
    def named_var(self) -> str | None:
        return self.var if self.var not in (None, "_") else None


@dataclass
class WorldClause:
    """``predicts(E, T, head) :- body``."""

    head: str
    body: tuple[Literal, ...]

    def text(self) -> str:
        """The clause as Prolog text; a variable that occurs once is written ``_``."""
        goals = [g if isinstance(g, str) else g.text() for g in self._goals()]
        return f"predicts(E, T, {self.head}) :-\n    " + ",\n    ".join(goals) + "."

    def term(self) -> Term:
        """The clause as the term its text must read back as (:mod:`neurosym.induce.readback`)."""
        goals = [_STEP if isinstance(g, str) else g.term() for g in self._goals()]
        body = goals[-1]
        for goal in reversed(goals[:-1]):
            body = Term(",", (goal, body))
        head = Term("predicts", (Var("E"), Var("T"), template_term(self.head)))
        return Term(":-", (head, body))

    def _goals(self) -> list[Literal | str]:
        """The body in its written order: cell literals first, negations last, step/4 when needed."""
        uses = Counter(lit.named_var for lit in self.body if lit.named_var)
        uses.update([HEAD_VAR] if head_var(self.head) else [])
        body = [
            lit if not lit.named_var or uses[lit.named_var] > 1 else replace(lit, var="_")
            for lit in self.body
        ]
        positive = [lit for lit in body if not lit.negated]
        negative = [lit for lit in body if lit.negated]
        positive.sort(key=lambda lit: lit.pred not in STEP_BOUND)  # bind E, T through step/4
        goals: list[Literal | str] = [*positive, *negative]
        if not any(lit.pred in STEP_BOUND for lit in positive):
            goals.insert(0, "step(E, T, _, _)")
        return goals


_STEP = Term("step", (Var("E"), Var("T"), Var("_"), Var("_")))
_TEMPLATE = re.compile(r"([a-z][A-Za-z0-9_]*)\((.*)\)")


def template_term(template: str) -> Term | Var | str:
    """An event template of the vocabulary (``opened(lock(C))``) as a term, ``C`` a variable."""
    if template == HEAD_VAR:
        return Var(HEAD_VAR)
    m = _TEMPLATE.fullmatch(template)
    if m is None:
        return template
    return Term(m.group(1), (template_term(m.group(2)),))


@dataclass
class Tuples:
    """Bindings of a partial clause: state index per row and a colour code per variable."""

    s: np.ndarray
    vars: dict[str, np.ndarray] = field(default_factory=dict)

    def take(self, mask: np.ndarray) -> Tuples:
        return Tuples(self.s[mask], {k: v[mask] for k, v in self.vars.items()})


_Best = tuple[float, int, tuple[Literal, ...], int, int]
"""a refinement: (gain, candidate order, literals added, positives, negatives)"""


def head_var(template: str) -> bool:
    return bool(_TEMPLATE_VAR.search(template))


def positives(g: Grounded, template: str) -> np.ndarray:
    """Encoded head keys (s, or s * colours + c) of the KB's events matching ``template``."""
    pattern = (
        re.escape(template).replace(HEAD_VAR, r"([a-z][A-Za-z0-9_]*)")
        if head_var(template)
        else re.escape(template)
    )
    rx = re.compile(pattern)
    keys = []
    for s, text in zip(g.events["s"].tolist(), g.events["event"].tolist(), strict=True):
        m = rx.fullmatch(text)
        if m:
            keys.append(s * len(g.colours) + g.colour_index[m.group(1)] if m.groups() else s)
    return np.unique(np.asarray(keys, dtype=np.int64))


def apply(g: Grounded, lit: Literal, t: Tuples) -> Tuples:
    """The bindings that satisfy ``lit`` as well (new rows for a new variable)."""
    m = g.matrix[lit.pred]
    if lit.functor is None:
        col = g.value_index.get(lit.value)
        hit = m[t.s, col] if col is not None else np.zeros(len(t.s), dtype=bool)
    elif lit.var == "_":
        cols = g.functor_columns[lit.functor]
        hit = m[t.s][:, cols].any(axis=1) if len(cols) else np.zeros(len(t.s), dtype=bool)
    elif lit.var in t.vars:
        col = g.colour_column[lit.functor][t.vars[lit.var]]
        hit = (col >= 0) & m[t.s, np.maximum(col, 0)]
    else:  # a new variable: one row per colour the value takes
        cols = g.functor_columns[lit.functor]
        colour = np.flatnonzero(g.colour_column[lit.functor] >= 0)
        rows, j = np.nonzero(m[t.s][:, cols]) if len(cols) else (np.zeros(0, int), np.zeros(0, int))
        out = Tuples(t.s[rows], {k: v[rows] for k, v in t.vars.items()})
        out.vars[lit.var] = colour[j]
        return out
    return t.take(~hit if lit.negated else hit)


def evaluate(g: Grounded, body: tuple[Literal, ...], has_var: bool) -> np.ndarray:
    """Encoded head keys the body derives on ``g`` (unique)."""
    t = Tuples(np.arange(g.n_states))
    for lit in sorted(body, key=lambda lit: lit.negated):
        t = apply(g, lit, t)
    if has_var:
        if HEAD_VAR not in t.vars:
            return np.zeros(0, dtype=np.int64)
        return np.unique(t.s * len(g.colours) + t.vars[HEAD_VAR])
    return np.unique(t.s)


def _candidates(
    g: Grounded, body: tuple[Literal, ...], bound: list[str], bias: Bias, has_var: bool
) -> list[Literal]:
    new_names = [
        n for n in (f"{HEAD_VAR}{i}" for i in range(1, bias.max_new_vars + 1)) if n not in bound
    ]
    fresh = [HEAD_VAR] if has_var and HEAD_VAR not in bound else []
    if new_names:
        fresh.append(new_names[0])
    out = []
    for pred in bias.predicates:
        for value in g.constants(pred):
            out += [Literal(pred, value), Literal(pred, value, negated=True)]
        for f in g.functors(pred):  # on equal gain a variable wins over `_` (it can link later)
            out += [Literal(pred, f, f, var) for var in [*bound, *fresh, "_"]]
            out += [Literal(pred, f, f, var, negated=True) for var in [*bound, "_"]]
    if has_var and HEAD_VAR not in bound:  # the first literal binds the head's colour
        out = [lit for lit in out if lit.var == HEAD_VAR]
    family = FAMILIES.get(g.family)
    if family is not None and family.links_first:  # ties go to the first candidate
        out.sort(key=lambda lit: lit.negated or lit.var not in bound)
    return [lit for lit in out if lit not in body]


def _counts(keys: np.ndarray, remaining: np.ndarray, all_pos: np.ndarray) -> tuple[int, int]:
    p = int(np.isin(keys, remaining, assume_unique=True).sum())
    n = int((~np.isin(keys, all_pos, assume_unique=True)).sum())
    return p, n


def _gain(p0: int, n0: int, p1: int, n1: int) -> float:
    if p1 == 0:
        return -math.inf
    return p1 * (math.log2(p1 / (p1 + n1)) - math.log2(p0 / (p0 + n0)))


def _bound(body: tuple[Literal, ...]) -> list[str]:
    return sorted({lit.named_var for lit in body if lit.named_var and not lit.negated})


def _grow(
    g: Grounded, template: str, remaining: np.ndarray, all_pos: np.ndarray, bias: Bias
) -> WorldClause | None:
    """One clause by greedy FOIL gain (with a literal of lookahead); None when none is consistent."""
    has_var = head_var(template)
    body: tuple[Literal, ...] = ()
    p0, n0 = len(remaining), g.n_states if not has_var else g.n_states * max(len(g.colours), 1)
    while len(body) < bias.max_literals:
        best: _Best | None = None
        cands = _candidates(g, body, _bound(body), bias, has_var)
        for order, lit in enumerate(cands):
            p1, n1 = _counts(evaluate(g, (*body, lit), has_var), remaining, all_pos)
            gain = _gain(p0, n0, p1, n1)
            if gain > 0 and (best is None or gain > best[0]):
                best = (gain, order, (lit,), p1, n1)
        if best is None and len(body) + 2 <= bias.max_literals:
            best = _lookahead(g, body, cands, remaining, all_pos, bias, has_var, p0, n0)
        if best is None:
            return None
        _, _, added, p0, n0 = best
        body = (*body, *added)
        if n0 == 0 and (not has_var or HEAD_VAR in _bound(body)):
            return WorldClause(template, body)
    return None


def _lookahead(
    g: Grounded,
    body: tuple[Literal, ...],
    cands: list[Literal],
    remaining: np.ndarray,
    all_pos: np.ndarray,
    bias: Bias,
    has_var: bool,
    p0: int,
    n0: int,
) -> _Best | None:
    """The best pair (a literal that introduces a variable, then one that uses it)."""
    best: _Best | None = None
    for lit in cands:
        if lit.negated or lit.named_var is None or lit.named_var in _bound(body):
            continue
        first = (*body, lit)
        for order, second in enumerate(_candidates(g, first, _bound(first), bias, has_var)):
            if second.var != lit.var:
                continue
            p1, n1 = _counts(evaluate(g, (*first, second), has_var), remaining, all_pos)
            gain = _gain(p0, n0, p1, n1)
            if gain > 0 and (best is None or gain > best[0]):
                best = (gain, order, (lit, second), p1, n1)
    return best


def _safe(body: tuple[Literal, ...], has_var: bool) -> bool:
    bound = set(_bound(body))
    if not any(not lit.negated for lit in body):
        return False
    if has_var and HEAD_VAR not in bound:
        return False
    return all(lit.named_var in bound for lit in body if lit.negated and lit.named_var)


def _prune(g: Grounded, clause: WorldClause, all_pos: np.ndarray) -> WorldClause:
    """Drop literals (last first) while the clause stays safe and covers no negative."""
    has_var = head_var(clause.head)
    body = clause.body
    for lit in reversed(clause.body):
        trial = tuple(x for x in body if x != lit)
        if trial and _safe(trial, has_var):
            _, n = _counts(evaluate(g, trial, has_var), all_pos, all_pos)
            if n == 0:
                body = trial
    return WorldClause(clause.head, body)


def learn(g: Grounded, template: str, bias: Bias = Bias()) -> tuple[list[WorldClause], int]:
    """Clauses for ``template`` by sequential covering; returns them and the positives left uncovered."""
    has_var = head_var(template)
    all_pos = positives(g, template)
    remaining = all_pos
    clauses: list[WorldClause] = []
    while len(remaining) and len(clauses) < bias.max_clauses:
        clause = _grow(g, template, remaining, all_pos, bias)
        if clause is None:
            break
        clause = _prune(g, clause, all_pos)
        covered = evaluate(g, clause.body, has_var)
        left = remaining[~np.isin(remaining, covered)]
        if len(left) == len(remaining):
            break
        clauses.append(clause)
        remaining = left
    kept = list(clauses)
    for clause in clauses:  # drop a clause whose positives the others cover
        others = [c for c in kept if c is not clause]
        if not others:
            break
        rest = np.concatenate([evaluate(g, c.body, has_var) for c in others])
        mine = evaluate(g, clause.body, has_var)
        if np.isin(mine[np.isin(mine, all_pos)], rest).all():
            kept.remove(clause)
    return kept, len(remaining)
