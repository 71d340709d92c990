"""World rules learned back from a KB: ``predicts(E, T, Event)`` clauses per event.

>>> rules = induce_world("kb_out/rgw-random/kb.pl", holdout="kb_out/held/kb.pl")
>>> rules.scores["picked(sword)"].holdout_precision
1.0
>>> rules.write("world.pl")

An event of the env's vocabulary is *determined* when the KB shows it and
the clauses found cover every one of its training examples and no
counter-example; otherwise it is *undetermined* (no positive example, or
examples no clause of the bias separates) and is written as a comment,
not guessed.
"""

from __future__ import annotations

import os
import textwrap
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from neurosym.errors import ConfigError
from neurosym.induce.background import BACKGROUND, FAMILIES  # noqa: F401 (BACKGROUND: re-exported)
from neurosym.induce.examples import Grounded, ground
from neurosym.induce.foil import Bias, WorldClause, evaluate, head_var, learn, positives
from neurosym.induce.readback import Code, Part, check_reads_back, comment


@dataclass
class EventScore:
    """One event's clauses and scores (precision/recall None where there is nothing to divide)."""

    event: str
    status: str  # "determined" or "undetermined"
    reason: str
    clauses: list[WorldClause]
    train_examples: int
    train_precision: float | None
    train_recall: float | None
    holdout_examples: int | None = None
    holdout_precision: float | None = None
    holdout_recall: float | None = None

    @property
    def solved(self) -> bool:
        """IGGP's "solved perfectly": precision and recall 1.0 on held-out data."""
        return self.holdout_precision == 1.0 and self.holdout_recall == 1.0


@dataclass
class WorldRules:
    """The learned clauses per event, their scores, and where they were learned from."""

    kb: str
    env: str
    family: str
    episodes: int
    states: int
    bias: Bias
    scores: dict[str, EventScore]
    seconds: float
    """learning time: grounding the KB (load and background answers) plus the search"""
    ground_seconds: float = 0.0
    holdout: str | None = None
    holdout_episodes: int | None = None
    notes: list[str] = field(default_factory=list)

    @property
    def clauses(self) -> list[WorldClause]:
        return [c for s in self.scores.values() if s.status == "determined" for c in s.clauses]

    def write(self, path: str | os.PathLike[str]) -> Path:
        """Write the rules as a self-contained Prolog file (atomically)."""
        from neurosym.atomic import atomic_write, make_folder

        text, parts = render_parts(self)
        path = Path(path)
        check_reads_back(text, parts, path)
        make_folder(path.parent)
        atomic_write(path, lambda p: Path(p).write_text(text, encoding="utf-8"))
        return path


def _ratio(num: int, den: int) -> float:
    """num / den, 1.0 when den is 0 (nothing predicted: no false positive; nothing to find)."""
    return num / den if den else 1.0


def score(
    g: Grounded, template: str, clauses: list[WorldClause]
) -> tuple[int, float | None, float | None]:
    """(examples, precision, recall) of ``clauses`` for ``template`` on ``g``."""
    has_var = head_var(template)
    pos = positives(g, template)
    parts = [evaluate(g, c.body, has_var) for c in clauses]
    pred = np.unique(np.concatenate(parts)) if parts else np.zeros(0, np.int64)
    if has_var and len(g.colours) == 0:
        pred = np.zeros(0, np.int64)
    tp = int(np.isin(pred, pos).sum())
    return len(pos), _ratio(tp, len(pred)), _ratio(tp, len(pos))


def induce_world(
    kb: str | os.PathLike[str],
    *,
    holdout: str | os.PathLike[str] | None = None,
    bias: Bias | None = None,
) -> WorldRules:
    """Learn ``predicts/3`` clauses for every event of the KB's env vocabulary it shows.

    ``holdout``: a KB of other episodes to score the clauses on (precision,
    recall, "solved perfectly"). Learning time (``seconds``) counts grounding
    the training KB and the search, not the held-out scoring.
    """
    start = time.perf_counter()
    g = ground(kb)
    grounded = time.perf_counter() - start
    bias = _bias(bias, g)
    scores: dict[str, EventScore] = {}
    for template in FAMILIES[g.family].vocabulary:
        n_pos = len(positives(g, template))
        if n_pos == 0:
            scores[template] = EventScore(
                template, "undetermined", "no positive example in the KB", [], 0, None, None
            )
            continue
        clauses, left = learn(g, template, bias)
        n, p, r = score(g, template, clauses)
        if left or p != 1.0:
            reason = f"{left} of {n_pos} examples separated by no clause of the bias"
            scores[template] = EventScore(template, "undetermined", reason, clauses, n, p, r)
        else:
            scores[template] = EventScore(template, "determined", "", clauses, n, p, r)
    seconds = time.perf_counter() - start
    rules = WorldRules(
        str(kb), g.env, g.family, g.n_episodes, g.n_states, bias, scores, seconds, grounded
    )
    if holdout is not None:
        h = ground(holdout)
        if h.family != g.family:
            raise ConfigError(
                f"held-out KB {holdout} is a {h.family} KB; the rules learned from {kb} are "
                f"{g.family} rules: give a held-out KB of the same env family"
            )
        rules.holdout, rules.holdout_episodes = str(holdout), h.n_episodes
        for template, sc in scores.items():
            if sc.status == "determined":
                sc.holdout_examples, sc.holdout_precision, sc.holdout_recall = score(
                    h, template, sc.clauses
                )
            else:
                sc.holdout_examples = len(positives(h, template))
    return rules


def _bias(bias: Bias | None, g: Grounded) -> Bias:
    """``bias``, or the default one over the KB's env family's body predicates; a bias naming a
    predicate the family has no background for is a one-line :class:`ConfigError`."""
    family = FAMILIES[g.family]
    if bias is None:
        return replace(Bias(), predicates=family.predicates)
    unknown = [p for p in bias.predicates if p not in g.matrix]
    if unknown:
        raise ConfigError(
            f"the bias names {', '.join(unknown)}, which {g.family} KBs have no background for: "
            f"use {', '.join(family.predicates)}"
        )
    return bias


def _fmt(x: float | None) -> str:
    return "-" if x is None else f"{x:.3f}"


def header(facts: tuple[str, ...]) -> str:
    """The file's PlDoc header: fixed text only (data goes in one-line ``%`` comments);
    ``facts`` are the KB predicates the background reads (the env family's)."""
    load = (
        f"Load beside a KB of the same schema ({', '.join(facts)}): `swipl kb.pl world.pl`. "
        "Where and how the rules were learned, and their scores, follow in the % lines below."
    )
    wrapped = textwrap.fill(load, 84, break_long_words=False, break_on_hyphens=False)
    return (
        "/** <module> World rules learned from recorded facts (neurosym induce world)\n\n"
        "predicts(E, T, Event) holds when the step of state T of episode E has event Event.\n"
        f"{wrapped}\n*/\n"
    )


DISCONTIGUOUS = ":- discontiguous predicts/3."


def render(rules: WorldRules) -> str:
    """The learned file: header, clauses, undetermined events as comments, background."""
    return render_parts(rules)[0]


def render_parts(rules: WorldRules) -> tuple[str, list[Part]]:
    """The learned file's text and what it must read back as (:mod:`neurosym.induce.readback`)."""
    b = rules.bias
    family = FAMILIES[rules.family]
    notes = [
        f"Learned from: {rules.kb} (env {rules.env or '?'}, {rules.episodes} episodes, "
        f"{rules.states} acted states) in {rules.seconds:.1f} s.",
        f"Learner: FOIL-style clause search (neurosym.induce.foil), max_literals={b.max_literals}, "
        f"max_new_vars={b.max_new_vars}, max_clauses={b.max_clauses},",
        f"body predicates {', '.join(b.predicates)} (defined at the end of this file).",
    ]
    if rules.holdout:
        notes.append(f"Held out: {rules.holdout} ({rules.holdout_episodes} episodes).")
    notes += ["", "Scores (train precision/recall; held-out precision/recall):"]
    notes += [f"  - {sc.event}: {_describe(sc)}" for sc in rules.scores.values()]
    lines = [header(family.facts), *(comment(n) for n in notes), "", DISCONTIGUOUS, ""]
    parts: list[Part] = [Code(DISCONTIGUOUS)]
    for sc in rules.scores.values():
        if sc.status == "determined":
            lines.append(comment(f"{sc.event}: {sc.train_examples} training examples"))
            lines += [c.text() for c in sc.clauses]
            parts += [c.term() for c in sc.clauses]
        else:
            lines.append(comment(f"undetermined: {sc.event}: {sc.reason}"))
            lines += [comment("  " + line) for c in sc.clauses for line in c.text().splitlines()]
        lines.append("")
    lines.append("% ---- background predicates (neurosym.induce.background) ----")
    lines.append(family.background.strip())
    parts.append(Code(family.background))
    return "\n".join(lines) + "\n", parts


def _describe(sc: EventScore) -> str:
    if sc.status != "determined":
        return f"undetermined ({sc.reason})"
    text = f"{len(sc.clauses)} clause(s), train {_fmt(sc.train_precision)}/{_fmt(sc.train_recall)}"
    if sc.holdout_examples is not None:
        text += f", held-out {_fmt(sc.holdout_precision)}/{_fmt(sc.holdout_recall)} ({sc.holdout_examples} examples)"
        text += ", solved perfectly" if sc.solved else ""
    return text
