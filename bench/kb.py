"""Knowledge-base throughput: write, load and query N ground relation/7 facts; JSON lines.

For each N (default 1e4, 1e5, 1e6) it builds a relation/7 table of the
docs/design.md schema, ``relation(E, T, Head, J, A, B, Value)`` (500 facts per
episode: 16 steps x 4 heads x 8 relations, entity atoms including
``key(red)``, normal float values), and measures:

* ``write_s``: ``write_prolog`` of the .pl file (wall; ``write_cpu_s`` CPU);
* ``qcompile_s``: compiling it to .qlf (a swipl subprocess);
* ``consult_s`` / ``qlf_load_s``: loading in a plain ``swipl`` process, timed
  inside Prolog (CPU and wall), i.e. without process start-up;
* ``janus_facts_s``: ``KnowledgeBase(path)`` in this process (wall), the
  default and safe path: the file is read as data (facts only, nothing runs),
  in parallel chunks, one per core (up to 4; front to back on one core)
  (``*_cpu_s``: CPU seconds of all threads, the steadier figure on a shared
  machine); ``janus_facts_1thread_s`` the same read forced into one thread,
  ``janus_facts_Nthreads_s`` forced into N = 2..4 chunk-reading threads;
* ``janus_consult_s``: ``KnowledgeBase(path, trusted=True)``, the file
  consulted as code (what every load did before untrusted KBs were read as
  data); ``janus_qlf_s``: ``KnowledgeBase(path, qlf=True)`` from the signed
  ``.qlf`` (compiled beforehand);
* queries through janus: the first-argument query ``relation(E, ...)`` with E
  bound, as ``once`` (first answer) and as ``query`` (all 500 facts of the
  episode converted to Python), and a third-argument query (Head bound) as
  ``once`` and as ``count``. ``*_first_ms`` is the first call (SWI-Prolog
  builds its just-in-time index then), the other figures are medians of
  later calls with other bindings.

With ``--baseline DIR`` (another neurosym source tree, e.g. ``git archive
main neurosym | tar -x -C /tmp/base``) the safe load and the signed-``.qlf``
load are also timed side by side, each in a fresh process per try, this
tree's code and the baseline's alternately, ``--repeat`` times (best of):
``side_by_side`` holds ``{"facts": {"baseline": s, "this": s}, "qlf": ...}``
with the CPU seconds of all threads beside them. ``--only-loads`` keeps
only the write, the compile, ``qlf_load_s`` (best of ``--repeat``) and the
side-by-side loads: quicker on a busy machine.

The first line describes the machine, its load average included: the figures
are wall times on a machine that may be shared.

    python bench/kb.py                    # N = 1e4, 1e5, 1e6
    python bench/kb.py --sizes 10000      # quick
    python bench/kb.py --sizes 1000000 --baseline /tmp/base --repeat 3
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
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from neurosym.facts.prolog_writer import write_prolog  # noqa: E402
from neurosym.prolog.knowledge_base import KnowledgeBase, _janus  # noqa: E402
from neurosym.prolog.locate import find_swipl  # noqa: E402
from neurosym.prolog.qlf import qcompile  # noqa: E402
from neurosym.terms import atom_text  # noqa: E402

ENTITIES = ["agent", "sword", "enemy", "terminal", "teleport", "wall", "empty", "key(red)"]
PER_EPISODE = 500


def relation_table(n: int, seed: int = 0) -> pd.DataFrame:
    """n relation/7 facts: episode-major, 16 steps x 4 heads x 8 relations per 512 rows."""
    rng = np.random.default_rng(seed)
    i = np.arange(n)
    return pd.DataFrame(
        {
            "episode": i // PER_EPISODE,
            "t": (i % PER_EPISODE) // 32,
            "head": (i // 8) % 4,
            "j": i % 8,
            "a": pd.Categorical.from_codes(rng.integers(0, len(ENTITIES), n), ENTITIES),
            "b": pd.Categorical.from_codes(rng.integers(0, len(ENTITIES), n), ENTITIES),
            "value": rng.normal(size=n),
        }
    )


def timed(fn: Callable[[], object]) -> tuple[float, float, object]:
    """(wall s, cpu s, result) of one call."""
    wall, cpu = time.perf_counter(), time.process_time()
    out = fn()
    return time.perf_counter() - wall, time.process_time() - cpu, out


def swipl_load(path: Path, qlf: bool) -> tuple[float, float]:
    """CPU and wall seconds of loading ``path`` in a fresh plain swipl, timed inside Prolog."""
    load = (
        f"setup_call_cleanup(open({atom_text(str(path))}, read, S, [type(binary)]),"
        f" load_files(neurosym_qlf:kb, [stream(S), format(qlf), silent(true)]), close(S))"
        if qlf
        else f"load_files(user:{atom_text(str(path))}, [silent(true)])"
    )
    goal = (
        f"statistics(cputime, C0), get_time(W0), {load}, statistics(cputime, C1), get_time(W1),"
        " C is C1 - C0, W is W1 - W0, format('~6f ~6f~n', [C, W])"
    )
    proc = subprocess.run(
        [str(find_swipl().executable), "-f", "none", "-q", "-g", goal, "-t", "halt"],
        capture_output=True, text=True, check=True,
    )  # fmt: skip
    cpu, wall = map(float, proc.stdout.split())
    return cpu, wall


def query_ms(fn: Callable[[int], object], keys: list[int]) -> tuple[float, float]:
    """(first call ms, median ms of the other calls)."""
    times = []
    for key in keys:
        start = time.perf_counter()
        fn(key)
        times.append((time.perf_counter() - start) * 1e3)
    return times[0], statistics.median(times[1:])


_CHILD = """
import json, sys, time
from pathlib import Path
from neurosym.prolog.knowledge_base import KnowledgeBase, _janus
_janus()
path, qlf = Path(sys.argv[1]), sys.argv[2] == "qlf"
wall, cpu = time.perf_counter(), time.process_time()
kb = KnowledgeBase(path, qlf=qlf)
wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
kb.close()
print(json.dumps([wall, cpu]))
"""


def child_load(tree: Path, path: Path, how: str) -> tuple[float, float]:
    """(wall s, cpu s) of ``KnowledgeBase(path)`` (how: facts or qlf) in a fresh process
    running the neurosym of ``tree``, timed inside it (start-up and Prolog's own start left out)."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    proc = subprocess.run(
        [sys.executable, "-c", _CHILD, str(path), how],
        capture_output=True, text=True, check=True, env=env, cwd=tree,
    )  # fmt: skip
    wall, cpu = json.loads(proc.stdout.splitlines()[-1])
    return wall, cpu


def side_by_side(path: Path, baseline: Path, repeat: int) -> dict[str, object]:
    """Best-of-``repeat`` safe and signed-.qlf loads of ``path``, baseline and this tree alternately."""
    this = Path(__file__).resolve().parent.parent
    out: dict[str, object] = {}
    for how in ("facts", "qlf"):
        best: dict[str, list[float]] = {"baseline": [], "this": []}
        for _ in range(repeat):
            for label, tree in (("baseline", baseline), ("this", this)):
                best[label].append(child_load(tree, path, how))
        out[how] = {label: round(min(t[0] for t in times), 3) for label, times in best.items()} | {
            f"{label}_cpu": round(min(t[1] for t in times), 3) for label, times in best.items()
        }
    return out


def bench(
    n: int, directory: Path, baseline: Path | None = None, repeat: int = 3, only_loads: bool = False
) -> dict[str, object]:
    df = relation_table(n)
    path = directory / f"relation_{n}.pl"
    out: dict[str, object] = {"bench": "kb", "n": n, "predicate": "relation/7"}
    wall, cpu, _ = timed(lambda: write_prolog(path, {"relation": df}))
    out.update(
        write_s=round(wall, 3), write_cpu_s=round(cpu, 3), pl_mb=round(path.stat().st_size / 1e6, 1)
    )
    wall, _, qlf = timed(lambda: qcompile(path))
    out.update(qcompile_s=round(wall, 3), qlf_mb=round(Path(qlf).stat().st_size / 1e6, 1))
    if not only_loads:
        cpu, wall = swipl_load(path, qlf=False)
        out.update(consult_s=round(wall, 3), consult_cpu_s=round(cpu, 3))
    walls = [swipl_load(Path(qlf), qlf=True) for _ in range(repeat if only_loads else 1)]
    cpu, wall = min(walls, key=lambda t: t[1])
    out.update(qlf_load_s=round(wall, 3), qlf_load_cpu_s=round(cpu, 3))
    if only_loads:
        if baseline is not None:
            out["side_by_side"] = side_by_side(path, baseline, repeat)
        return out

    wall, cpu, kb = timed(lambda: KnowledgeBase(path))
    out.update(janus_facts_s=round(wall, 3), janus_facts_cpu_s=round(cpu, 3))
    assert kb.count("relation(_, _, _, _, _, _, _)") == n
    kb.close()
    janus = _janus()
    threads = max(2, min(os.cpu_count() or 1, 4))
    for label, count in (("1thread", 1), (f"{threads}threads", threads)):
        janus.query_once("neurosym_facts:set_reader_threads(T)", {"T": count})
        wall, cpu, kb = timed(lambda: KnowledgeBase(path))
        out[f"janus_facts_{label}_s"] = round(wall, 3)
        out[f"janus_facts_{label}_cpu_s"] = round(cpu, 3)
        kb.close()
    janus.query_once("neurosym_facts:set_reader_threads(auto)")
    wall, cpu, kb = timed(lambda: KnowledgeBase(path, trusted=True))
    out.update(janus_consult_s=round(wall, 3), janus_consult_cpu_s=round(cpu, 3))
    kb.close()
    wall, _, kb = timed(lambda: KnowledgeBase(path, qlf=True))
    out["janus_qlf_s"] = round(wall, 3)
    with kb:
        goal = "relation(E, T, H, J, A, B, V)"
        episodes = list(range(0, n // PER_EPISODE, max(1, n // PER_EPISODE // 200)))[:200]
        first, median = query_ms(lambda e: kb.once(goal, E=e), episodes)
        out.update(first_arg_once_first_ms=round(first, 3), first_arg_once_ms=round(median, 3))
        first, median = query_ms(lambda e: kb.query(goal, E=e), episodes[::-1])
        rows = len(kb.query(goal, E=0))
        out.update(first_arg_query_ms=round(median, 3), first_arg_query_rows=rows)
        heads = [0, 1, 2, 3] * 25
        first, median = query_ms(lambda h: kb.once(goal, H=h), heads)
        out.update(third_arg_once_first_ms=round(first, 3), third_arg_once_ms=round(median, 3))
        first, median = query_ms(lambda h: kb.count(goal, H=h), heads[:9])
        out.update(third_arg_count_ms=round(median, 3), third_arg_count_rows=kb.count(goal, H=0))
    if baseline is not None:
        out["side_by_side"] = side_by_side(path, baseline, repeat)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--sizes", default="10000,100000,1000000", help="Comma-separated N (default: %(default)s)."
    )
    parser.add_argument(
        "--dir", default=None, help="Where to write the KB files (default: a temporary directory)."
    )
    parser.add_argument(
        "--baseline", type=Path, default=None,
        help="Another neurosym source tree: time its safe and .qlf loads beside this one's.",
    )  # fmt: skip
    parser.add_argument(
        "--repeat", type=int, default=3, help="Tries per side-by-side figure, best of (default: 3)."
    )
    parser.add_argument(
        "--only-loads", action="store_true",
        help="Skip consult, the other janus loads and the queries (quicker on a busy machine).",
    )  # fmt: skip
    args = parser.parse_args()
    swipl = find_swipl()
    machine = {
        "bench": "kb",
        "machine": platform.machine(),
        "cpus": os.cpu_count(),
        "loadavg": [round(x, 2) for x in os.getloadavg()],
        "python": platform.python_version(),
        "swipl": swipl.version_text,
    }
    print(json.dumps(machine), flush=True)
    with tempfile.TemporaryDirectory(dir=args.dir) as tmp:
        for n in (int(float(s)) for s in args.sizes.split(",")):
            print(
                json.dumps(bench(n, Path(tmp), args.baseline, args.repeat, args.only_loads)),
                flush=True,
            )


if __name__ == "__main__":
    main()
