"""Query speed of the shipped rules over a large synthetic RGW KB, this tree's rules beside a baseline's; JSON lines.

The KB (written with neurosym's writer) holds ``--episodes`` Relational-Grid-World
episodes of ``--steps`` states each: episode/4, object/2, the events the rules ask
about (picked(sword), teleported, defeated(enemy) or hurt_by(enemy), reached(terminal),
at random distinct times), holding(E, T, sword) after the pick-up, and per state one
holds/5 and one relation/7 fact between random entity types; also, for the Box-World
rules, the same map of keys, locks and gem at state 0 of every episode (at/5, object/2)
and the got(...) events of its solution. Each rule goal is counted
in Prolog (``aggregate_all(count, Goal, N)``), CPU time:

* ``plain``: in one plain swipl, the KB consulted into module user, this tree's
  rule files loaded as at ``swipl kb.pl rules/rgw.pl rules/relations.pl
  rules/boxworld.pl`` and the
  baseline's consulted into module ``baseline`` (so they must be plain files, as
  the rules were before they became modules);
* ``janus``: in one Python process, two :class:`~neurosym.prolog.KnowledgeBase`
  of the same KB file, one with this tree's rules, one with the baseline's
  (``kb.count(goal)``), each KB in a module of its own with its own indexes.

The two sides are called alternately, ``--calls`` times each after a first call,
so that a busy machine slows both alike; ``ms`` is the median of those calls and
``min_ms`` the fastest. ``first_ms`` (janus only: each KB has its own facts) is the
first call, when SWI-Prolog builds its just-in-time indexes. ``--baseline DIR`` is
a tree holding the old ``rules/`` (``git archive BASE rules | tar -x -C DIR``);
without it only this tree's rules are timed. The first line describes the machine,
its load average included: the figures are times on a machine that may be shared.

    python bench/rules.py --baseline /tmp/base                  # 10k episodes
    python bench/rules.py --episodes 1000 --calls 5             # quick
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from neurosym.facts.prolog_writer import write_prolog  # noqa: E402
from neurosym.prolog.locate import find_swipl  # noqa: E402
from neurosym.terms import atom_text  # noqa: E402

GOALS = (
    "sword_before_enemy(_)",
    "teleport_before_enemy(_)",
    "enemy_beaten_with_sword(_)",
    "visit_order(_, _)",
    "optimal_order(_)",
    "sword_enemy_link(_)",
    "consistently_orders(_, _, _)",
    "head_pairs(_, _)",
    "box(_, _, _)",
    "solution_chain(_, _)",
    "distractor_box(_, _, _)",
    "followed_solution(_)",
)
RULE_FILES = ("rgw.pl", "relations.pl", "boxworld.pl")
TYPES = ["agent", "sword", "enemy", "teleport", "terminal", "wall"]
# The Box-World map of every episode at state 0 (rules/tests/boxworld_facts.pl's
# episode 0): id, type, row, column; key(red) opens a box holding key(blue), which
# opens the gem's box; the other red lock guards a distractor, key(green).
BOX_MAP = [
    ("agent", "agent", 1, 1),
    ("key_red", "key(red)", 2, 3),
    ("key_blue", "key(blue)", 5, 5),
    ("lock_red", "lock(red)", 5, 6),
    ("gem", "gem", 8, 7),
    ("lock_blue", "lock(blue)", 8, 8),
    ("key_green", "key(green)", 10, 2),
    ("lock_red_2", "lock(red)", 10, 3),
]
BOX_EVENTS = ["got(key(red))", "got(key(blue))", "got(gem)"]


def emit(**fields: Any) -> None:
    print(json.dumps(fields), flush=True)


def synthetic_kb(path: Path, episodes: int, steps: int, seed: int = 0) -> int:
    """Write the KB described in the module docstring at ``path``; the number of facts."""
    rng = np.random.default_rng(seed)
    ep = np.arange(episodes)
    times = np.argsort(rng.random((episodes, steps - 1)), axis=1)[:, :3]  # distinct times
    t_sword, t_tele, t_enemy = times.T
    armed = t_sword < t_enemy
    enemy = np.where(armed, "defeated(enemy)", "hurt_by(enemy)")
    events = pd.DataFrame(
        {
            "episode": np.concatenate([ep, ep, ep, ep]),
            "t": np.concatenate([t_sword, t_tele, t_enemy, np.full(episodes, steps - 1)]),
            "event": np.concatenate(
                [
                    ["picked(sword)"] * episodes,
                    ["teleported"] * episodes,
                    enemy,
                    ["reached(terminal)"] * episodes,
                ]
            ),
        }
    )
    box_events = pd.DataFrame(
        {
            "episode": np.repeat(ep, len(BOX_EVENTS)),
            "t": np.tile(np.arange(len(BOX_EVENTS)), episodes),
            "event": np.tile(BOX_EVENTS, episodes),
        }
    )
    events = pd.concat([events, box_events]).sort_values(["episode", "t"], kind="stable")
    ids, types, rows, cols = zip(*BOX_MAP, strict=True)
    held = [(e, t) for e in ep for t in range(t_sword[e] + 1, steps)]
    states = episodes * steps
    pairs = rng.integers(0, len(TYPES), (states, 2))
    net = {
        "episode": np.repeat(ep, steps),
        "t": np.tile(np.arange(steps), episodes),
    }
    tables = {
        "object": pd.DataFrame(
            {
                "id": ["sword", "enemy", "tele_1", *ids[1:]],
                "type": ["sword", "enemy", "teleport", *types[1:]],
            }
        ),
        "at": pd.DataFrame(
            {
                "episode": np.repeat(ep, len(BOX_MAP)),
                "t": 0,
                "id": np.tile(ids, episodes),
                "row": np.tile(rows, episodes),
                "col": np.tile(cols, episodes),
            }
        ),
        "episode": pd.DataFrame(
            {"episode": ep, "steps": steps, "return": 1.0, "outcome": "terminal"}
        ),
        "event": events,
        "holding": pd.DataFrame(held, columns=["episode", "t"]).assign(item="sword"),
        "holds": pd.DataFrame(
            {
                **net,
                "r": [f"r({j})" for j in rng.integers(0, 4, states)],
                "a": np.take(TYPES, pairs[:, 0]),
                "b": np.take(TYPES, pairs[:, 1]),
            }
        ),
        "relation": pd.DataFrame(
            {
                **net,
                "head": rng.integers(0, 4, states),
                "j": 0,
                "a": np.take(TYPES, pairs[:, 0]),
                "b": np.take(TYPES, pairs[:, 1]),
                "value": rng.normal(size=states),
            }
        ),
    }
    write_prolog(
        path,
        tables,
        dynamic=["attention/6"],
        term_columns={"event": ["event"], "holds": ["r"], "object": ["type"]},
    )
    return sum(len(df) for df in tables.values())


_PLAIN = """
time_ms_(G, Ms) :-
    statistics(cputime, C0), aggregate_all(count, G, _), statistics(cputime, C1),
    Ms is (C1 - C0) * 1000.
side_ms_(Sides, G, Times) :- maplist(side_goal_(G), Sides, Gs), maplist(time_ms_, Gs, Times).
side_goal_(G, this, G).
side_goal_(G, baseline, baseline:G).
bench_(Goals, Sides, Calls) :-
    forall(nth0(K, Goals, G),
           ( side_ms_(Sides, G, _),
             forall(between(1, Calls, _),
                    ( side_ms_(Sides, G, Ts), format('~d ~q~n', [K, Ts]) )) )).
"""


def plain(kb: Path, sides: dict[str, Path], calls: int) -> dict[str, dict[str, list[float]]]:
    """{goal: {side: [ms of each later call]}} in one plain swipl holding both sides' rules."""
    load = [f"consult({atom_text(str(kb))})"]
    for side, rules in sides.items():
        for name in RULE_FILES:
            target = "user" if side == "this" else side
            load.append(f"{target}:consult({atom_text(str(rules / name))})")
    goal = ", ".join([*load, f"bench_([{', '.join(GOALS)}], [{', '.join(sides)}], {int(calls)})"])
    with tempfile.NamedTemporaryFile("w", suffix=".pl", delete=False) as f:
        f.write(_PLAIN)
    try:
        proc = subprocess.run(
            [str(find_swipl().executable), "-q", "-g", goal, "-t", "halt", f.name],
            capture_output=True,
            text=True,
            check=True,
        )
    finally:
        os.unlink(f.name)
    if proc.stderr:
        raise SystemExit(f"plain swipl printed: {proc.stderr.strip()}")
    out: dict[str, dict[str, list[float]]] = {g: {side: [] for side in sides} for g in GOALS}
    for line in proc.stdout.splitlines():
        k, times = line.split(" ", 1)
        for side, ms in zip(sides, json.loads(times), strict=True):
            out[GOALS[int(k)]][side].append(ms)
    return out


_CHILD = """
import json, sys, time
from neurosym.prolog.knowledge_base import KnowledgeBase
kb_path, calls, sides = sys.argv[1], int(sys.argv[2]), json.loads(sys.argv[3])
goals = json.loads(sys.argv[4])
kbs = {side: KnowledgeBase(kb_path, rules=rules) for side, rules in sides.items()}
def ms(kb, goal):
    start = time.process_time()
    kb.count(goal)
    return (time.process_time() - start) * 1e3
out = {}
for goal in goals:
    out[goal] = {side: [ms(kb, goal)] for side, kb in kbs.items()}  # the first call
    for _ in range(calls):
        for side, kb in kbs.items():
            out[goal][side].append(ms(kb, goal))
print(json.dumps(out))
"""


def janus(kb: Path, sides: dict[str, Path], calls: int) -> dict[str, dict[str, list[float]]]:
    """{goal: {side: [first ms, ms of each later call]}}: one KnowledgeBase per side."""
    rules = {side: [str(folder / f) for f in RULE_FILES] for side, folder in sides.items()}
    proc = subprocess.run(
        [sys.executable, "-c", _CHILD, str(kb), str(calls), json.dumps(rules), json.dumps(GOALS)],
        capture_output=True,
        text=True,
        check=True,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    return json.loads(proc.stdout)


def figures(times: list[float], first: bool) -> dict[str, float]:
    """first_ms (when ``times`` starts with the first call), ms (median) and min_ms."""
    later = times[1:] if first else times
    out = {"first_ms": round(times[0], 2)} if first else {}
    return {**out, "ms": round(statistics.median(later), 2), "min_ms": round(min(later), 2)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", type=int, default=10_000)
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--calls", type=int, default=11, help="timed calls per goal and side (11)")
    ap.add_argument("--baseline", type=Path, help="a tree whose rules/ are the baseline")
    args = ap.parse_args()
    if not 1 <= args.episodes <= 1_000_000 or not 4 <= args.steps <= 1000:
        raise SystemExit("--episodes must be 1..1,000,000 and --steps 4..1000")
    if not 1 <= args.calls <= 1000:
        raise SystemExit("--calls must be 1..1000")
    emit(
        bench="machine",
        cpus=os.cpu_count(),
        load_avg=[round(x, 2) for x in os.getloadavg()],
        python=platform.python_version(),
        swipl=find_swipl().version_text,
    )
    sides = {"this": ROOT / "rules"}
    if args.baseline:
        sides["baseline"] = args.baseline / "rules"
    with tempfile.TemporaryDirectory(prefix="neurosym-bench-rules-") as tmp:
        kb = Path(tmp) / "kb.pl"
        n = synthetic_kb(kb, args.episodes, args.steps)
        emit(bench="kb", episodes=args.episodes, steps=args.steps, facts=n)
        for how, run in (("plain", plain), ("janus", janus)):
            for goal, by_side in run(kb, sides, args.calls).items():
                line = {"bench": how, "goal": goal}
                for side, times in by_side.items():
                    line[side] = figures(times, first=how == "janus")
                emit(**line)


if __name__ == "__main__":
    main()
