"""What ``neurosym extract`` prints: episodes and returns, facts, strongest relations, rule answers.

The rule answers come from the written KB loaded with the rule files for the
env's family (``rules/rgw.pl`` or ``rules/boxworld.pl``, plus
``rules/relations.pl``) through :class:`~neurosym.prolog.KnowledgeBase`, so
what is printed is what a user gets by querying the file by hand.
"""

from __future__ import annotations

from collections import Counter
from pathlib import Path
from typing import Any

# (title, goal, variable): goals answered for every KB of a family. Each
# variable's value is printed as Prolog text; a goal with no answer prints "none".
QUERIES: dict[str, tuple[tuple[str, str, str], ...]] = {
    "rgw": (
        ("sword before enemy", "sword_before_enemy(E)", "E"),
        ("teleport before enemy", "teleport_before_enemy(E)", "E"),
        ("enemy beaten with sword", "enemy_beaten_with_sword(E)", "E"),
        ("optimal order (sword, teleport, enemy, terminal)", "optimal_order(E)", "E"),
        ("relations ordering sword before enemy", "orders_sword_before_enemy(R)", "R"),
        ("sword-enemy link in the network", "sword_enemy_link(A)", "A"),
    ),
    "boxworld": (
        ("followed the solution chain", "followed_solution(E)", "E"),
        ("distractor taken", "distractor_taken(E)", "E"),
        ("distractor avoided", "distractor_avoided(E)", "E"),
        ("key opens lock", "key_opens(K, L), X = K-L", "X"),
        ("key-lock links in the network", "key_lock_link(C, L), X = C-L", "X"),
    ),
}
RULE_FILES: dict[str, tuple[str, ...]] = {
    "rgw": ("rgw.pl", "relations.pl"),
    "boxworld": ("boxworld.pl", "relations.pl"),
}


def rules_dir() -> Path | None:
    """The repository's rules/ folder (beside the package), or None when it is not there."""
    import neurosym

    path = Path(neurosym.__file__).resolve().parent.parent / "rules"
    return path if (path / "relations.pl").is_file() else None


def rule_answers(kb_path: Path, family: str) -> list[tuple[str, str, list[str]]]:
    """(title, goal, answers as Prolog text) for the family's queries over the KB at ``kb_path``."""
    from neurosym.prolog.knowledge_base import KnowledgeBase

    folder = rules_dir()
    if folder is None:
        return []
    rules = [str(folder / name) for name in RULE_FILES[family]]
    out = []
    kb = KnowledgeBase(kb_path, rules=rules)
    try:
        for title, goal, var in QUERIES[family]:
            text_goal = f"{goal}, format(atom(Text__), '~q', [{var}])"
            answers = [str(row["Text__"]) for row in kb.query(text_goal)]
            out.append((title, goal, answers))
        visits = (
            [
                str(r["Text__"])
                for r in kb.query("visit_order(_, O), format(atom(Text__), '~q', [O])")
            ]
            if family == "rgw"
            else []
        )
        if visits:
            common = Counter(visits).most_common(3)
            out.append(
                (
                    "visit orders (most common)",
                    "visit_order(_, Order)",
                    [f"{o} x{n}" for o, n in common],
                )
            )
    finally:
        close = getattr(kb, "close", None)
        if close is not None:
            close()
    return out


def _short(values: list[str], of: int | None = None, limit: int = 20) -> str:
    """Answers on one line; ``of``: the episode count, for goals that answer episodes."""
    if not values:
        return "none"
    head = ", ".join(values[:limit]) + (", ..." if len(values) > limit else "")
    if of is not None:
        return f"{head}  ({len(values)} of {of} episodes)"
    return head if len(values) == 1 else f"{head}  ({len(values)})"


def print_report(rec: Any, facts: Any, written: dict[str, Path], kb: Path | None = None) -> None:
    """Print the summary of an extract run with rich (plain text when not a terminal)."""
    from rich.console import Console
    from rich.table import Table

    from neurosym.envs import env_family

    console = Console()
    meta = rec.meta
    ep = rec.episodes
    console.print(
        f"[bold]{meta.get('env')}[/]: {len(ep)} episodes ({'greedy' if meta.get('greedy', True) else 'sampled'}, "
        f"seed {meta.get('seed')}) of {meta.get('checkpoint')} "
        f"({meta.get('module')}, {meta.get('heads')} heads, {meta.get('relations')} relations)"
    )
    table = Table(title="episodes", show_edge=False)
    for col in ("episode", "steps", "return", "outcome"):
        table.add_column(col, justify="right" if col != "outcome" else "left")
    for e, steps, ret, outcome in ep.head(20)[["episode", "steps", "return", "outcome"]].itertuples(
        index=False, name=None
    ):
        table.add_row(str(e), str(steps), f"{ret:.2f}", str(outcome))
    console.print(table)
    if len(ep) > 20:
        console.print(f"... {len(ep) - 20} more episodes")
    if len(ep):
        outcomes = ", ".join(
            f"{k} {v}" for k, v in ep["outcome"].value_counts().sort_index().items()
        )
        console.print(
            f"return: mean {ep['return'].mean():.3f}, min {ep['return'].min():.3f}, max {ep['return'].max():.3f}; {outcomes}"
        )

    counts = facts.counts()
    console.print(
        "facts: "
        + ", ".join(f"{k} {v}" for k, v in counts.items() if v)
        + f"  ({facts.n_facts} in all)"
    )
    thr = facts.thresholds()
    if len(thr):
        console.print(
            f"thresholds ({facts.threshold}): "
            + ", ".join(f"r({j}) {v:.4g}" for j, v in thr.items())
        )

    strongest = facts.strongest_relations(5)
    if len(strongest):
        st = Table(title="strongest relations between object types (holds/5)", show_edge=False)
        for col in ("relation", "from", "to", "states", "mean value"):
            st.add_column(col)
        for r in strongest.itertuples(index=False):
            st.add_row(f"r({r.j})", str(r.a), str(r.b), str(r.held), f"{r.mean_value:.4g}")
        console.print(st)
    elif not facts["attention"].empty:
        console.print(
            "MHDPA: attention/6 facts hold the strongest key per query (no relation values)"
        )

    if kb is not None:
        family = env_family(str(meta.get("env")))
        answers = rule_answers(kb, family)
        if answers:
            qt = Table(title=f"rules/{RULE_FILES[family][0]}", show_edge=False)
            qt.add_column("question")
            qt.add_column("answers")
            for title, goal, values in answers:
                qt.add_row(title, _short(values, of=len(ep) if goal.endswith("(E)") else None))
            console.print(qt)
        else:
            console.print("rules/ not found beside the package: no rule answers")
    if kb is None:
        console.print("rule answers: none (they need the Prolog KB: --format pl)")
    for path in written.values():
        console.print(f"wrote {path}")
