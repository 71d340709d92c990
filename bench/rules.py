"""Query speed of the shipped rules over a large synthetic RGW KB, this tree's rules beside a baseline's; JSON lines.

The KB (written with neurosym's writer) holds ``--episodes`` Relational-Grid-World
episodes of ``--steps`` states each: episode/4, object/2, the events the rules ask
about (picked(sword), teleported, defeated(enemy) or hurt_by(enemy), reached(terminal),
at random distinct times), holding(E, T, sword) after the pick-up, and per state one
holds/5 and one relation/7 fact between random entity types. Each rule goal is counted
in Prolog (``aggregate_all(count, Goal, N)``):

* ``plain``: in a plain ``swipl kb.pl rules/rgw.pl rules/relations.pl`` (the KB in
  module user), timed inside Prolog;
* ``janus``: through :class:`~neurosym.prolog.KnowledgeBase` (``kb.count(goal)``),
  the KB in a module of its own.

``first_ms`` is the goal's first call in a fresh process (SWI-Prolog builds its
just-in-time indexes then), ``ms`` the median of ``--calls`` later calls. Each side
runs in a fresh process per try, this tree's rules and the baseline's alternately,
``--repeat`` times; the figures are the best of the tries. With ``--baseline DIR`` (a
tree holding the old ``rules/``, e.g. ``git archive main rules | tar -x -C /tmp/base``)
both are timed; without it only this tree's. The first line describes the machine,
its load average included: the figures are times on a machine that may be shared.

    python bench/rules.py --baseline /tmp/base                  # 10k episodes
    python bench/rules.py --episodes 1000 --repeat 1            # quick
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from neurosym.export.prolog_writer import write_prolog  # noqa: E402
from neurosym.prolog.locate import find_swipl  # noqa: E402

GOALS = (
    "sword_before_enemy(_)",
    "teleport_before_enemy(_)",
    "enemy_beaten_with_sword(_)",
    "visit_order(_, _)",
    "optimal_order(_)",
    "sword_enemy_link(_)",
    "consistently_orders(_, _, _)",
    "head_pairs(_, _)",
)
RULE_FILES = ("rgw.pl", "relations.pl")
TYPES = ["agent", "sword", "enemy", "teleport", "terminal", "wall"]


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
    ).sort_values(["episode", "t"], kind="stable")
    held = [(e, t) for e in ep for t in range(t_sword[e] + 1, steps)]
    states = episodes * steps
    pairs = rng.integers(0, len(TYPES), (states, 2))
    net = {
        "episode": np.repeat(ep, steps),
        "t": np.tile(np.arange(steps), episodes),
    }
    tables = {
        "object": pd.DataFrame(
            {"id": ["sword", "enemy", "tele_1"], "type": ["sword", "enemy", "teleport"]}
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
        term_columns={"event": ["event"], "holds": ["r"]},
    )
    return sum(len(df) for df in tables.values())


def plain(kb: Path, rules: Path, calls: int) -> dict[str, list[float]]:
    """{goal: [first ms, median ms]} in a fresh plain swipl with ``rules``' rule files."""
    files = [str(kb), *(str(rules / f) for f in RULE_FILES)]
    goals = "[" + ", ".join(GOALS) + "]"
    program = (
        "time_ms_(G, Ms) :- statistics(cputime, C0), aggregate_all(count, G, _),"
        " statistics(cputime, C1), Ms is (C1 - C0) * 1000.\n"
        f"bench_ :- forall(nth0(K, {goals}, G), ( time_ms_(G, First),"
        f" findall(Ms, (between(1, {calls}, _), time_ms_(G, Ms)), L), msort(L, S),"
        " length(S, N), I is N // 2, nth0(I, S, Med),"
        " format('~d ~6f ~6f~n', [K, First, Med]) )).\n"
    )
    with tempfile.NamedTemporaryFile("w", suffix=".pl", delete=False) as f:
        f.write(program)
    try:
        proc = subprocess.run(
            [str(find_swipl().executable), "-q", "-g", "bench_", "-t", "halt", *files, f.name],
            capture_output=True,
            text=True,
            check=True,
        )
    finally:
        os.unlink(f.name)
    if proc.stderr:
        raise SystemExit(f"plain swipl printed: {proc.stderr.strip()}")
    out = {}
    for line in proc.stdout.splitlines():
        k, first, median = line.split()
        out[GOALS[int(k)]] = [float(first), float(median)]
    return out


_CHILD = """
import json, statistics, sys, time
from neurosym.prolog.knowledge_base import KnowledgeBase
kb_path, rules, calls, goals = sys.argv[1], sys.argv[2:4], int(sys.argv[4]), sys.argv[5:]
kb = KnowledgeBase(kb_path, rules=rules)
out = {}
for goal in goals:
    times = []
    for _ in range(calls + 1):
        start = time.process_time()
        kb.count(goal)
        times.append((time.process_time() - start) * 1e3)
    out[goal] = [times[0], statistics.median(times[1:])]
print(json.dumps(out))
"""


def janus(kb: Path, rules: Path, calls: int) -> dict[str, list[float]]:
    """{goal: [first ms, median ms]} through KnowledgeBase in a fresh Python process."""
    args = [str(kb), *(str(rules / f) for f in RULE_FILES), str(calls)]
    proc = subprocess.run(
        [sys.executable, "-c", _CHILD, *args, *GOALS],
        capture_output=True,
        text=True,
        check=True,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    return json.loads(proc.stdout)


def best(tries: list[dict[str, list[float]]]) -> dict[str, list[float]]:
    """Per goal, the smallest first-call and median figures over the tries."""
    return {
        g: [round(min(t[g][0] for t in tries), 2), round(min(t[g][1] for t in tries), 2)]
        for g in tries[0]
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", type=int, default=10_000)
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--calls", type=int, default=5, help="later calls per goal (default 5)")
    ap.add_argument("--repeat", type=int, default=3, help="fresh processes per side (default 3)")
    ap.add_argument("--baseline", type=Path, help="a tree whose rules/ are the baseline")
    args = ap.parse_args()
    if not 1 <= args.episodes <= 1_000_000 or not 4 <= args.steps <= 1000:
        raise SystemExit("--episodes must be 1..1,000,000 and --steps 4..1000")
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
            tries: dict[str, list] = {side: [] for side in sides}
            for _ in range(args.repeat):
                for side, rules in sides.items():
                    tries[side].append(run(kb, rules, args.calls))
            figures = {side: best(t) for side, t in tries.items()}
            for goal in figures["this"]:
                line = {"bench": how, "goal": goal}
                for side, f in figures.items():
                    line[side] = {"first_ms": f[goal][0], "ms": f[goal][1]}
                emit(**line)


if __name__ == "__main__":
    main()
