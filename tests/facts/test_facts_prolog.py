"""The written KB: loads in plain swipl without a word, and the rules answer what pandas computes.

The recordings are the scripted routes of test_recorder_scripted (RGW) and the
explorer's Box-World episodes; every rule answer is checked against the same
question asked of the fact tables in pandas.
"""

from __future__ import annotations

import subprocess
from collections.abc import Iterator
from pathlib import Path

import pandas as pd
import pytest

from neurosym.facts.tables import FactSet, extract_facts
from neurosym.prolog.knowledge_base import KnowledgeBase
from neurosym.record.recording import Recording
from neurosym.terms import Term

REPO = Path(__file__).resolve().parents[2]
RULES = REPO / "rules"
ENEMY = ("defeated(enemy)", "hurt_by(enemy)")


@pytest.fixture(scope="module")
def rgw(scripted_recording, tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[FactSet, Path, KnowledgeBase]]:
    facts = extract_facts(scripted_recording(), threshold="abs:0")  # every non-zero value holds
    path = facts.to_prolog(tmp_path_factory.mktemp("kb") / "kb.pl")
    with KnowledgeBase(path, rules=[RULES / "rgw.pl", RULES / "relations.pl"]) as kb:
        yield facts, path, kb


@pytest.fixture(scope="module")
def boxworld(
    explorer_recording,
    tmp_path_factory: pytest.TempPathFactory,
) -> Iterator[tuple[FactSet, Path, KnowledgeBase]]:
    facts = extract_facts(explorer_recording(), threshold="quantile:0.9")
    path = facts.to_prolog(tmp_path_factory.mktemp("kb") / "kb.pl", qlf=True)
    with KnowledgeBase(path, rules=[RULES / "boxworld.pl", RULES / "relations.pl"]) as kb:
        yield facts, path, kb


def values(kb: KnowledgeBase, goal: str, var: str) -> list:
    return [row[var] for row in kb.query(goal)]


def first_t(events: pd.DataFrame, which: tuple[str, ...]) -> pd.Series:
    return events[events["event"].isin(which)].groupby("episode")["t"].min()


def test_kb_loads_in_plain_swipl_without_messages(rgw: tuple, boxworld: tuple, swipl: Path) -> None:
    _, path, _ = rgw
    bw_path = boxworld[1]
    rules = [RULES / "rgw.pl", RULES / "relations.pl", RULES / "boxworld.pl"]
    for files in ([path], [path, *rules], [bw_path, *rules], [bw_path.with_suffix(".qlf"), *rules]):
        proc = subprocess.run(
            [swipl, "-q", "-g", "halt", *files], capture_output=True, text=True, timeout=60
        )
        assert proc.returncode == 0
        assert proc.stderr == "" and proc.stdout == ""


def test_fact_counts_in_prolog(rgw: tuple) -> None:
    facts, _, kb = rgw
    for name in ("episode", "step", "at", "event", "holding", "relation", "holds", "attends"):
        arity = len(facts[name].columns)
        args = ", ".join(["_"] * arity)
        assert kb.count(f"{name}({args})") == len(facts[name]), name
    assert kb.count("attention(_, _, _, _, _, _)") == 0  # declared dynamic: no existence error


def test_sword_before_enemy_matches_pandas(rgw: tuple) -> None:
    facts, _, kb = rgw
    ev = facts["event"]
    sword, enemy = first_t(ev, ("picked(sword)",)), first_t(ev, ENEMY)
    both = sword.index.intersection(enemy.index)
    expected = sorted(int(e) for e in both if sword[e] < enemy[e])
    assert expected == [0]  # only the optimal route picks the sword before meeting the enemy
    assert values(kb, "sword_before_enemy(E)", "E") == expected
    teleport = first_t(ev, ("teleported",))
    both = teleport.index.intersection(enemy.index)
    assert values(kb, "teleport_before_enemy(E)", "E") == sorted(
        int(e) for e in both if teleport[e] < enemy[e]
    )


def test_enemy_beaten_with_sword_matches_pandas(rgw: tuple) -> None:
    facts, _, kb = rgw
    beaten = facts["event"][facts["event"]["event"] == "defeated(enemy)"]
    held = facts["holding"][facts["holding"]["item"] == "sword"]
    expected = sorted(set(beaten.merge(held, on=["episode", "t"])["episode"].astype(int)))
    assert expected == [0, 3]
    assert values(kb, "enemy_beaten_with_sword(E)", "E") == expected


def test_visit_order_matches_pandas(rgw: tuple) -> None:
    facts, _, kb = rgw
    visit = {"picked(sword)": "sword", "teleported": "teleport", "defeated(enemy)": "enemy",
             "hurt_by(enemy)": "enemy", "reached(terminal)": "terminal", "fell(pit)": "pit"}  # fmt: skip
    ev = facts["event"][facts["event"]["event"].isin(visit)].sort_values(
        ["episode", "t"], kind="stable"
    )
    expected = {
        int(e): tuple(dict.fromkeys(g["event"].map(visit))) for e, g in ev.groupby("episode")
    }
    got = {row["E"]: row["O"] for row in kb.query("visit_order(E, O)")}
    assert got == {e: expected.get(e, ()) for e in facts["episode"]["episode"]}
    assert got[0] == ("sword", "teleport", "enemy", "terminal")
    assert values(kb, "optimal_order(E)", "E") == [0]


def test_representational_rules_match_pandas(rgw: tuple) -> None:
    facts, _, kb = rgw
    holds = facts["holds"]
    pairs = set(zip(holds["j"], holds["a"], holds["b"], strict=True))
    consistent = {(j, a, b) for j, a, b in pairs if a != b and (j, b, a) not in pairs}
    got = {(r["J"], r["A"], r["B"]) for r in kb.query("consistently_orders(J, A, B)")}
    assert got == consistent and got
    orders = sorted(j for j, a, b in consistent if (a, b) == ("sword", "enemy"))
    assert sorted(r.args[0] for r in values(kb, "orders_sword_before_enemy(R)", "R")) == orders
    direct = sorted({j for j, a, b in pairs if {a, b} == {"sword", "enemy"}})
    assert sorted(r.args[0] for r in values(kb, "sword_enemy_direct(L)", "L")) == direct
    near, apart, direct_link = _link_in_pandas(facts, "sword", "enemy")
    assert [v.args[0] for v in near] == values(kb, "sword_enemy_via(X)", "X")
    if direct_link is not None:
        expected = direct_link
    elif near:
        expected = Term("indirect", (tuple(near),))
    else:
        expected = Term("co_occurring", (tuple(apart),)) if apart else "none"
    assert kb.once("sword_enemy_link(A)")["A"] == expected


def _link_in_pandas(facts: FactSet, a: str, b: str) -> tuple[list[Term], list[Term], Term | None]:
    """sword_enemy_link/1 from the holds table: (via/2 terms, apart/3 terms, the direct/2 term or
    None). A link holds at states (episode, t); a third object is near when its links to the
    two sides come within one step of each other in one episode."""
    holds = facts["holds"]
    d = int(facts["episode"]["steps"].sum())
    both = pd.concat([holds.rename(columns={"a": "x", "b": "y"}),
                      holds.rename(columns={"a": "y", "b": "x"})])  # fmt: skip
    both = both.assign(state=list(zip(both["episode"], both["t"], strict=True)))
    direct = both[(both.x == a) & (both.y == b)]
    direct_link = None
    if len(direct):
        links = tuple(Term("r", (int(j),)) for j in dict.fromkeys(direct["j"]))
        direct_link = Term("direct", (links, Term("share", (direct["state"].nunique(), d))))
    types = {"agent"} | set(facts["object"]["type"])
    near, apart = [], []
    for z in sorted(types - {a, b}):
        sa = set(both[(both.x == a) & (both.y == z)]["state"])
        sb = set(both[(both.x == b) & (both.y == z)]["state"])
        if not sa or not sb:
            continue
        close = {(e, t) for e, t in sa if any((e, t + k) in sb for k in (-1, 0, 1))}
        close |= {(e, t) for e, t in sb if any((e, t + k) in sa for k in (-1, 0, 1))}
        if close:
            near.append((-len(close), z, Term("via", (z, Term("share", (len(close), d))))))
        else:
            share_a, share_b = Term("share", (len(sa), d)), Term("share", (len(sb), d))
            apart.append(Term("apart", (z, share_a, share_b)))
    return [v for _, _, v in sorted(near)], apart, direct_link


def test_relation_statistics_match_pandas(rgw: tuple) -> None:
    facts, _, kb = rgw
    rel = facts["relation"]
    stats = rel.groupby("j")["value"].agg(["size", "mean", "min", "max"])
    got = {r["J"]: r for r in kb.query("relation_stats(J, N, Mean, Min, Max)")}
    assert sorted(got) == stats.index.tolist()
    for j, row in stats.iterrows():
        assert got[j]["N"] == row["size"]
        assert got[j]["Mean"] == pytest.approx(row["mean"], rel=1e-9, abs=1e-15)
        assert (got[j]["Min"], got[j]["Max"]) == (
            row["min"],
            row["max"],
        )  # written in full precision
    first = rel[rel["j"] == 0]
    counts = first.groupby(["head", "a", "b"]).size().reset_index(name="n")
    for head, group in counts.groupby("head"):
        top = group.sort_values(["n", "a", "b"], ascending=[False, True, True]).iloc[0]
        answer = kb.once("head_top_pair(H, A, B, N)", H=int(head))
        assert (answer["A"], answer["B"], answer["N"]) == (top["a"], top["b"], top["n"])


def test_boxworld_rules_match_pandas(boxworld: tuple) -> None:
    facts, _, kb = boxworld
    at0 = facts["at"][facts["at"]["t"] == 0].merge(facts["object"], on="id")
    locks = at0[at0["type"].str.startswith("lock(")]
    left = at0.assign(col=at0["col"] + 1)[["episode", "row", "col", "type"]].rename(
        columns={"type": "content"}
    )
    boxes = locks.merge(left, on=["episode", "row", "col"])
    expected = sorted(zip(boxes["episode"], boxes["type"], boxes["content"], strict=True))
    got = sorted((r["E"], str(r["L"]), str(r["X"])) for r in kb.query("box(E, L, X)"))
    assert got == expected and got

    ev = facts["event"]
    got_items = ev[ev["event"].str.startswith("got(")].sort_values(["episode", "t"], kind="stable")
    expected_order = {
        int(e): [s[4:-1] for s in g["event"]] for e, g in got_items.groupby("episode")
    }
    orders = {r["E"]: [str(x) for x in r["Items"]] for r in kb.query("got_order(E, Items)")}
    assert orders == {int(e): expected_order.get(int(e), []) for e in facts["episode"]["episode"]}

    episodes = facts["episode"]
    assert values(kb, "distractor_taken(E)", "E") == sorted(
        episodes[episodes["outcome"] == "distractor"]["episode"]
    )
    assert values(kb, "gem_chain(E, _)", "E") == sorted(
        episodes[episodes["outcome"] == "gem"]["episode"]
    )

    opened = ev[ev["event"].str.startswith("opened(")].merge(facts["holding"], on=["episode", "t"])
    expected_pairs = {
        (item, event[7:-1]) for item, event in zip(opened["item"], opened["event"], strict=True)
    }
    assert {(str(r["K"]), str(r["L"])) for r in kb.query("key_opens(K, L)")} == expected_pairs
    assert all(
        k[4:-1] == lk[5:-1] for k, lk in expected_pairs
    )  # a key opens the lock of its colour


def test_boxworld_solution_chain_is_consistent_with_the_gem_episodes(boxworld: tuple) -> None:
    _, _, kb = boxworld
    for row in kb.query("gem_chain(E, C)"):
        chains = [r["S"] for r in kb.query("solution_chain(E, S)", E=row["E"])]
        assert chains, row["E"]
        assert all(str(c[-1]) == "gem" for c in chains)
    for row in kb.query("followed_solution(E)"):
        assert kb.once("gem_chain(E, C), solution_chain(E, C)", E=row["E"]) is not None


def test_kb_meta_names_the_env_options(scripted_recording, tmp_path: Path, run_neurosym) -> None:  # noqa: ANN001
    """The options the env was made with (the checkpoint's and --env-option's) are in kb_meta,
    after the other keys, and read back through the fact reader and `neurosym query`."""
    rec = scripted_recording()
    rec = Recording(**rec.tables, meta=rec.meta)  # a copy: the fixture is shared
    rec.meta["env_kwargs"] = {"num_mountains": 12, "map": "my map.txt", "max_steps": None,
                              "classic": False, "scale": 0.5}  # fmt: skip
    facts = extract_facts(rec)
    path = facts.to_prolog(tmp_path / "kb.pl")
    text = path.read_text()
    assert text.split("kb_meta(threshold,'quantile:0.9').\n")[1].startswith(
        "kb_meta(env_option(classic),false).\n"
        "kb_meta(env_option(map),'my map.txt').\n"
        "kb_meta(env_option(max_steps),none).\n"
        "kb_meta(env_option(num_mountains),12).\n"
        "kb_meta(env_option(scale),0.5).\n"
    )
    with KnowledgeBase(path) as kb:
        got = {str(r["K"]): r["V"] for r in kb.query("kb_meta(env_option(K), V)")}
    assert got == {"classic": "false", "map": "my map.txt", "max_steps": "none",
                   "num_mountains": 12, "scale": 0.5}  # fmt: skip
    proc = run_neurosym("query", "--kb", path, "--json", "kb_meta(env_option(map), V)")
    assert (proc.returncode, proc.stdout.strip()) == (0, '[{"V": "my map.txt"}]'), proc.stderr
    table = pd.read_parquet(facts.to_parquet(tmp_path / "facts") / "kb_meta.parquet")
    assert dict(zip(table["key"], table["value"], strict=True))["env_option(map)"] == "my map.txt"
    rec.meta["env_kwargs"] = {}  # an env's defaults: no option facts, the rest unchanged
    assert "\nkb_meta(env_option" not in extract_facts(rec).to_prolog(tmp_path / "kb2.pl").read_text()
