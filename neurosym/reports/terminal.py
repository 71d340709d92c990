"""What ``neurosym extract`` prints: episodes, facts, heads worth reading, relations, rule answers.

The rule answers come from the written KB loaded with the rule files for the
env's family (``rules/rgw.pl`` or ``rules/boxworld.pl``, plus
``rules/relations.pl``) through :class:`~neurosym.prolog.KnowledgeBase`, so
what is printed is what a user gets by querying the file by hand.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from neurosym.display import show

# (title, goal, variable): goals answered for every KB of a family. Each
# variable's value is printed as Prolog text; a goal with no answer prints "none".
QUERIES: dict[str, tuple[tuple[str, str, str], ...]] = {
    "rgw": (
        ("sword before enemy", "sword_before_enemy(E)", "E"),
        ("teleport before enemy", "teleport_before_enemy(E)", "E"),
        ("enemy beaten with sword", "enemy_beaten_with_sword(E)", "E"),
        ("level's optimal order followed", "optimal_order(E)", "E"),
        ("relations ordering sword before enemy", "orders_sword_before_enemy(R)", "R"),
    ),
    "boxworld": (
        ("followed the solution chain", "followed_solution(E)", "E"),
        ("distractor taken", "distractor_taken(E)", "E"),
        ("distractor avoided", "distractor_avoided(E)", "E"),
        ("key opens lock", "key_opens(K, L), X = K-L", "X"),
    ),
    "minigrid": (
        ("key before door", "key_before_door(E)", "E"),
        ("key opens door", "opens(K, D), X = K-D", "X"),
        ("mission done", "mission_done(E)", "E"),
        ("key-door links in the network", "key_door_link(C, L), X = C-L", "X"),
    ),
}
LINKS: dict[str, tuple[tuple[str, str, str, str, tuple[str, str]], ...]] = {
    "rgw": (
        ("sword-enemy link in the network", "sword_enemy_link(A)", "", "A", ("sword", "enemy")),
    ),
    "boxworld": (
        ("key-lock link in the network", "key_lock_link(C, A)", "C", "A", ("key", "lock")),
    ),
}
"""family -> (title, goal, the variable naming what is linked (a colour) or "", the answer's
variable, the two sides' names): link answers (rules/lib/kb_common.pl), printed in words
with their shares of the states the agent acted in (:func:`link_text`)"""
LINK_NOTE = (
    "  (links: states out of all the states the agent acted in; indirect: through",
    "  an object at one state or two consecutive ones; co-occurring: only in one",
    "  recording)",
)
RULE_FILES: dict[str, tuple[str, ...]] = {
    "rgw": ("rgw.pl", "relations.pl"),
    "boxworld": ("boxworld.pl", "relations.pl"),
    "minigrid": ("minigrid.pl", "relations.pl"),
}


def rules_dir() -> Path | None:
    """The shipped rule files' folder (:func:`neurosym.shipped.rules_dir`), or None."""
    from neurosym.shipped import rules_dir as shipped_rules

    return shipped_rules()


_WITH_DISTRACTOR = (
    "episode(E, _, _, _), once(distractor_box(E, _, _))",
    "episodes with a distractor",
    "no distractor on these levels",
)
SCOPES: dict[str, dict[str, tuple[str, str, str]]] = {
    "rgw": {
        "level's optimal order followed": (
            "current_predicate(optimal_visits/2), optimal_visits(E, _)",
            "episodes of solved levels",
            "no optimal order in this KB (recorded before optimal_visits/2, or no level solved)",
        ),
    },
    "boxworld": {"distractor taken": _WITH_DISTRACTOR, "distractor avoided": _WITH_DISTRACTOR},
}
"""family -> title -> (goal over E naming the episodes the question is about, what they
are, what to say when there are none): questions that only some levels can answer"""


@dataclass
class Answer:
    """One question's answers, and what a count of them is out of."""

    title: str
    goal: str
    values: list[str]
    """the answers as Prolog text (visit orders: ``[sword,enemy] x3``, most common first)"""
    of: int | None = None
    """the episodes asked about (goals over episodes) or the distinct visit orders"""
    unit: str = ""
    """what ``of`` counts: ``episodes``, ``episodes with a distractor``, ``distinct orders``;
    ``states`` for link answers, whose words say their shares (:func:`link_text`)"""
    empty: str | None = None
    """said instead of a count when ``of`` is 0 (no distractor on these levels)"""


def answers(kb_path: Path, family: str) -> list[Answer]:
    """The family's questions answered over the KB at ``kb_path``, with what each counts."""
    from neurosym.prolog.knowledge_base import KnowledgeBase

    folder = rules_dir()
    if folder is None:
        return []
    rules = [str(folder / name) for name in RULE_FILES[family]]
    out = []
    kb = KnowledgeBase(kb_path, rules=rules)
    try:
        episodes = kb.count("episode(_, _, _, _)")
        scopes = SCOPES.get(family, {})
        for title, goal, var in QUERIES[family]:
            text_goal = f"{goal}, format(atom(Text__), '~q', [{var}])"
            found = [str(row["Text__"]) for row in kb.query(text_goal)]
            if title in scopes:
                scope, unit, empty = scopes[title]
                out.append(Answer(title, goal, found, kb.count(scope), unit, empty))
            elif goal.endswith("(E)"):
                out.append(Answer(title, goal, found, episodes, "episodes"))
            else:
                out.append(Answer(title, goal, found))
        out += _link_answers(kb, family)
        if family == "rgw":
            out += _order_answers(kb)
    finally:
        kb.close()
    return out


def link_text(answer: Any, sides: tuple[str, str]) -> str:
    """A link answer of rules/lib/kb_common.pl in words, with the states it counts.

    ``direct([r(1)], share(4, 124))`` -> ``direct: r(1) on 4 of 124 states``;
    ``indirect([via(agent, share(2, 124))])`` -> ``indirect via agent on 2 of 124 states``;
    ``co_occurring([apart(agent, share(6, 40), share(8, 40))])`` -> ``co-occurring only:
    agent: with sword on 6, with enemy on 8 of 40 states, never within one step``.
    """
    from neurosym.terms import Term

    if not isinstance(answer, Term):
        return str(answer)
    a, b = sides
    if answer.functor == "direct":
        links, share = answer.args
        n, d = share.args
        return f"direct: {', '.join(map(str, links))} on {n} of {d} states"
    if answer.functor == "indirect":
        parts = [f"{v.args[0]} on {v.args[1].args[0]} of {v.args[1].args[1]} states"
                 for v in answer.args[0]]
        return "indirect via " + "; ".join(parts)
    if answer.functor == "co_occurring":
        parts = [f"{v.args[0]}: with {a} on {v.args[1].args[0]}, with {b} on "
                 f"{v.args[2].args[0]} of {v.args[1].args[1]} states"
                 for v in answer.args[0]]
        return "co-occurring only: " + "; ".join(parts) + ", never within one step"
    return str(answer)


def _link_answers(kb: Any, family: str) -> list[Answer]:
    """The family's link questions (:data:`LINKS`), each answer in words (:func:`link_text`)."""
    out = []
    for title, goal, what, var, sides in LINKS.get(family, ()):
        values = []
        for row in kb.query(goal):
            text = link_text(row[var], sides)
            values.append(f"{row[what]}: {text}" if what else text)
        out.append(Answer(title, goal, values, unit="states"))
    return out


def _order_answers(kb: Any) -> list[Answer]:
    """The most common visit orders, and the levels' optimal orders (optimal_visits/2)."""
    out = []
    for title, goal in (
        ("visit orders (most common)", "visit_order(_, Order)"),
        ("levels' optimal orders (most common)", "optimal_visit_order(_, Order)"),
    ):
        rows = kb.query(goal.replace("Order", "O") + ", format(atom(Text__), '~q', [O])")
        orders = Counter(str(r["Text__"]) for r in rows)
        if orders:
            common = [f"{o} x{n}" for o, n in orders.most_common(3)]
            out.append(Answer(title, goal, common, len(orders), "distinct orders"))
    return out


def rule_answers(kb_path: Path, family: str) -> list[tuple[str, str, list[str]]]:
    """(title, goal, answers as Prolog text) for the family's queries over the KB at ``kb_path``."""
    return [(a.title, a.goal, a.values) for a in answers(kb_path, family)]


def _count(answer: Answer, shown: int) -> str:
    """What the answers are out of: ``3 of 20 episodes``, ``3 of 7 distinct orders``."""
    n = len(answer.values)
    if answer.unit == "distinct orders":
        of = answer.of or n
        if shown >= of:
            return f"{of} distinct orders"
        return f"{shown} most common of {of} distinct orders"
    if answer.of is not None:
        return f"{n} of {answer.of} {answer.unit}"
    return f"{n} answers"


def _short(answer: Answer, limit: int = 20) -> str:
    """Answers on one line, then what they count (the verbose report)."""
    if answer.of == 0 and answer.empty:
        return answer.empty
    values = answer.values
    if not values:
        return "none"
    shown = values[:limit]
    head = ", ".join(shown) + (", ..." if len(values) > limit else "")
    if answer.unit == "states":
        return "\n".join(values)
    if len(values) == 1 and (answer.of is None or answer.unit == "distinct orders"):
        return head
    return f"{head}  ({_count(answer, len(shown))})"


def _brief(answer: Answer) -> str:
    """The short report's answer cell: episode answers as a count, others the first three."""
    if answer.of == 0 and answer.empty:
        return answer.empty
    if answer.unit.startswith("episodes"):
        return _count(answer, len(answer.values))
    if answer.unit == "states":  # link answers: one per line, each says what it counts
        return "\n".join(answer.values) or "none"
    return _short(answer, limit=3)


def add_rows(table: Any, rows: list[tuple[str, ...]], whole: tuple[int, ...]) -> None:
    """Add ``rows`` (rich markup) to a rich table; the columns ``whole`` are never made
    narrower than their widest cell, so that a narrow terminal wraps the text columns
    and the headers, never a value such as ``29 %`` over two lines."""
    from rich.text import Text

    for row in rows:
        table.add_row(*row)
    for i in whole:
        column = table.columns[i]
        widest = max((Text.from_markup(row[i]).cell_len for row in rows), default=0)
        column.min_width = max(column.min_width or 0, widest)


def _print_episodes(ep: Any, say: Any, table_type: Any) -> None:
    """The first 20 episodes, a row each (the verbose report)."""
    table = table_type(title="episodes", show_edge=False)
    for col in ("episode", "steps", "return", "outcome"):
        table.add_column(col, justify="left" if col == "outcome" else "right")
    shown = ep.head(20)[["episode", "steps", "return", "outcome"]]
    rows = [
        (show(e), show(steps), f"{ret:.2f}", show(outcome))
        for e, steps, ret, outcome in shown.itertuples(index=False, name=None)
    ]
    add_rows(table, rows, whole=(0, 1, 2, 3))
    say(table)
    say("  (steps, return and how each episode ended)")
    if len(ep) > 20:
        say(f"... {len(ep) - 20} more episodes")


def _print_heads(rec: Any, say: Any, table_type: Any, verbose: bool = True) -> None:
    """The per-head table of :func:`neurosym.record.heads.head_summary` (PrediNet only);
    ``verbose`` adds the table that counts arguments beside objects."""
    from neurosym.record.heads import head_summary

    heads = head_summary(rec)
    if heads.empty:
        return
    table = table_type(title="heads: two arguments on two different objects", show_edge=False)
    for col in ("head", "states", "two objects", "next object", "top pairs (share of states)"):
        table.add_column(col, justify="left" if col.startswith("top") else "right")
    rows = []
    for row in heads.to_dict("records"):
        pairs = [
            f"{row[f'pair_{k}']} {100 * row[f'share_{k}']:.0f} %"
            for k in ((1, 2, 3) if verbose else (1, 2))
            if row.get(f"pair_{k}") is not None
        ]
        rows.append(
            (
                show(row["head"]),
                show(row["states"]),
                f"{100 * row['two_objects']:.0f} %",
                "-" if row["next_object"] is None else f"{100 * row['next_object']:.0f} %",
                show(", ".join(pairs) or "none"),
            )
        )
    add_rows(table, rows, whole=(0, 1, 2, 3))
    say(table)
    say("  (share of states with the head's two arguments on two objects; top pairs)")
    if not verbose or heads["beside_objects"].isna().all():
        return
    beside = table_type(title="heads: arguments on or beside two different objects", show_edge=False)
    for col in ("head", "on or beside two objects", "top pair (share of states)"):
        beside.add_column(col, justify="left" if col.startswith("top") else "right")
    rows = [
        (
            show(row["head"]),
            "-" if row["beside_objects"] is None else f"{100 * row['beside_objects']:.0f} %",
            "none"
            if row["beside_pair"] is None
            else show(f"{row['beside_pair']} {100 * row['beside_share']:.0f} %"),
        )
        for row in heads.to_dict("records")
    ]
    add_rows(beside, rows, whole=(0, 1))
    say(beside)
    say("  (the same, with an argument beside an object counted as on it)")


def say_phrases(console: Any, phrases: list[str], indent: str = "  ") -> None:
    """Print ``phrases`` (rich markup) joined by spaces, breaking lines only between phrases.

    Rich would wrap a long line at the console's width (80 columns when output
    is not a terminal) wherever a space falls, splitting ``4 heads`` or
    ``event 140``; here a line ends before a phrase that does not fit, and the
    next one starts indented. A phrase wider than the console is not broken.
    """
    from rich.text import Text

    width = console.width
    lines: list[list[str]] = []
    used = 0
    for phrase in phrases:
        size = Text.from_markup(phrase).cell_len
        if lines and used + 1 + size <= width:
            lines[-1].append(phrase)
            used += 1 + size
        else:
            lines.append([phrase])
            used = size + (len(indent) if len(lines) > 1 else 0)
    for i, line in enumerate(lines):
        console.print((indent if i else "") + " ".join(line), soft_wrap=True)


def _print_summary(rec: Any, facts: Any, console: Any, table_type: Any, verbose: bool) -> None:
    """The run in a line, its episodes (verbose), returns, fact counts and thresholds."""
    meta = rec.meta
    ep = rec.episodes
    say = console.print
    mode = "greedy" if meta.get("greedy", True) else "sampled"
    say_phrases(
        console,
        [
            f"[bold]{show(meta.get('env'))}[/]: {len(ep)} episodes",
            f"({mode}, seed {show(meta.get('seed'))})",
            f"of {show(meta.get('checkpoint'))}",
            f"({show(meta.get('module'))}, {show(meta.get('heads'))} heads, "
            f"{show(meta.get('relations'))} relations)",
        ],
    )
    if verbose:
        _print_episodes(ep, say, table_type)
    if len(ep):
        outcomes = [show(f"{k} {v}") for k, v in ep["outcome"].value_counts().sort_index().items()]
        r = ep["return"]
        say_phrases(
            console,
            [f"return: mean {r.mean():.3f},", f"min {r.min():.3f},", f"max {r.max():.3f};"]
            + _commas(outcomes),
        )
    if not verbose:
        say(f"facts: {facts.n_facts} (--verbose: by predicate, and the relation tables)")
        return
    counts = [f"{k} {v}" for k, v in facts.counts().items() if v]
    say_phrases(console, ["facts:", *_commas(counts), f"({facts.n_facts} in all)"])
    thr = facts.thresholds()
    if len(thr):
        values = [f"r({j}) {v:.4g}" for j, v in thr.items()]
        say_phrases(console, [f"thresholds ({show(facts.threshold)}):", *_commas(values)])


def _commas(items: list[str]) -> list[str]:
    """``items`` as phrases of a comma-separated list: every one but the last ends in a comma."""
    return [f"{item}," for item in items[:-1]] + items[-1:]


def _print_relations(facts: Any, say: Any, table_type: Any, verbose: bool) -> None:
    """The strongest relations between object types (verbose), or what stands in for them."""
    strongest = facts.strongest_relations(5) if verbose else []
    if len(strongest):
        st = table_type(title="strongest relations between object types (holds/5)", show_edge=False)
        for col in ("relation", "from", "to", "states", "mean value"):
            st.add_column(col)
        rows = [
            (show(f"r({r.j})"), show(r.a), show(r.b), show(r.held), f"{r.mean_value:.4g}")
            for r in strongest.itertuples(index=False)
        ]
        add_rows(st, rows, whole=(0, 3, 4))
        say(st)
        say("  (r(j) above threshold from one object type to another: states, mean value)")
    elif not facts["attention"].empty:
        say("MHDPA: attention/6 holds the strongest key of every query cell (no relation values)")
    elif verbose and not facts["relation"].empty:
        say("strongest relations between object types: none held above threshold")


def _print_answers(kb: Path | None, family: str, say: Any, table_type: Any, verbose: bool) -> None:
    """The rule files' answers from the written KB (episode lists as counts unless verbose)."""
    if kb is None:
        say("rule answers: none (they need the Prolog KB: --format pl)")
        return
    found = answers(kb, family)
    if not found:
        say("rule answers: none (neurosym's rule files are missing: no rules/ folder found)")
        return
    qt = table_type(title=f"rules/{RULE_FILES[family][0]}", show_edge=False)
    qt.add_column("question")
    qt.add_column("answers")
    for answer in found:
        qt.add_row(show(answer.title), show(_short(answer) if verbose else _brief(answer)))
    say(qt)
    if any(answer.unit == "states" for answer in found):
        for line in LINK_NOTE:
            say(line)
    say(f"  (answers from kb.pl; ask your own with neurosym query --rules {family})")


FAITHFULNESS_COLUMNS = (
    ("relations", "relations"),
    ("world", "world"),
    ("untrained_relations", "untrained"),
    ("chance", "chance"),
)
"""faithfulness/5's feature sets -> the printed table's column"""


def faithfulness_rows(table: Any) -> list[tuple[str, ...]]:
    """The printed faithfulness rows (target, then a score per feature set, then the states) of
    a faithfulness/5 table: what the KB holds, to two decimals (``-``: not measured)."""
    rows = []
    for target in dict.fromkeys(table["target"]):
        mine = table[table["target"] == target]
        scores = dict(zip(mine["features"], mine["score"], strict=True))
        cells = [f"{scores[f]:.2f}" if f in scores else "-" for f, _ in FAITHFULNESS_COLUMNS]
        rows.append((target.replace("_", " "), *cells, str(int(mine["states"].max()))))
    return rows


def _print_faithfulness(facts: Any, measured: Any, say: Any, table_type: Any) -> None:
    """The faithfulness/5 facts in one table, with what they count and why a figure is missing."""
    table = facts["faithfulness"]
    notes = tuple(getattr(measured, "notes", ()))
    if table.empty and not notes:
        return
    if not table.empty:
        held = int(table["episodes"].max())
        total = getattr(measured, "episodes", None)
        of = f" of {total}" if total else ""
        ft = table_type(
            title=f"faithfulness (held out: {held}{of} episodes)",
            show_edge=False,
        )
        for col in ("target", *(name for _, name in FAITHFULNESS_COLUMNS), "states"):
            ft.add_column(col)
        add_rows(ft, faithfulness_rows(table), whole=tuple(range(6)))
        say(ft)
        say(
            "  (share of the held-out states whose next object or action a tree learned on the "
            "other episodes predicts from: the relation facts, world facts, an untrained network's "
            "relation facts on the same states; chance: a uniform pick, the commonest action)"
        )
    for note in notes:
        say(f"  faithfulness: {show(note)}")


def print_report(
    rec: Any,
    facts: Any,
    written: dict[str, Path],
    kb: Path | None = None,
    verbose: bool = True,
    faithfulness: Any = None,
) -> None:
    """Print the summary of an extract run with rich (plain text when not a terminal).

    Every value printed from the recording, the facts or the KB goes through
    :func:`neurosym.display.show`: Prolog lists such as ``[sword,enemy]`` would
    otherwise be read as rich markup and vanish, and an atom holding escape
    codes would style the terminal. Values never wrap (:func:`add_rows`).
    Without ``verbose`` it is the short report: the episodes in one line, the
    heads and the rule answers (episode lists as counts); ``verbose`` adds the
    episodes, fact counts, thresholds and relation tables and every answer.
    The faithfulness table is ``facts``' faithfulness/5 (``faithfulness``, the
    :class:`~neurosym.record.faithfulness.Faithfulness` measured, adds its notes).
    """
    from rich.console import Console
    from rich.table import Table

    from neurosym.envs import env_family

    console = Console(highlight=False)
    say = console.print
    _print_summary(rec, facts, console, Table, verbose)
    _print_heads(rec, say, Table, verbose)
    _print_relations(facts, say, Table, verbose)
    _print_faithfulness(facts, faithfulness, say, Table)
    _print_answers(kb, env_family(str(rec.meta.get("env"))), say, Table, verbose)
    for path in written.values():
        say(f"wrote {show(path)}", soft_wrap=True)  # a path is never broken over two lines


def print_figures(report: dict[str, Any]) -> None:
    """The report's figure lines, from mean return to outcomes (``neurosym play`` prints the same)."""
    from neurosym.display import plain

    outcomes = plain(", ".join(f"{k} {v}" for k, v in report["outcomes"].items()))
    print(f"mean return  {report['mean_return']:.3f} (std {report['std_return']:.3f})")
    print(f"success      {100 * report['success_rate']:.1f} %")
    for key, label in (
        ("optimal_rate", "optimal     "),
        ("sword_first_guarded", "sword first "),
        ("no_detour_decoy", "no detour   "),
    ):
        if report.get(key) is not None:
            print(f"{label} {100 * report[key]:.1f} %{_of(report, key)}")
    print(f"mean length  {report['mean_length']:.1f} steps")
    print(f"outcomes     {outcomes}")


def _of(report: dict[str, Any], key: str) -> str:
    """' (of N guarded levels)' for the shares that count only some episodes."""
    if key == "sword_first_guarded":
        return f" (of {report['guarded_episodes']} guarded levels)"
    if key == "no_detour_decoy":
        return f" (of {report['decoy_episodes']} decoy levels)"
    return f" (mean optimal return {report['mean_optimal_return']:.3f})"
