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
  front to back, or in parallel chunks on a machine with 4 cores or more
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

The first line describes the machine, its load average included: the figures
are wall times on a machine that may be shared.

    python bench/kb.py                    # N = 1e4, 1e5, 1e6
    python bench/kb.py --sizes 10000      # quick
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

from neurosym.export.prolog_writer import write_prolog  # noqa: E402
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


def bench(n: int, directory: Path) -> dict[str, object]:
    df = relation_table(n)
    path = directory / f"relation_{n}.pl"
    out: dict[str, object] = {"bench": "kb", "n": n, "predicate": "relation/7"}
    wall, cpu, _ = timed(lambda: write_prolog(path, {"relation": df}))
    out.update(
        write_s=round(wall, 3), write_cpu_s=round(cpu, 3), pl_mb=round(path.stat().st_size / 1e6, 1)
    )
    wall, _, qlf = timed(lambda: qcompile(path))
    out.update(qcompile_s=round(wall, 3), qlf_mb=round(Path(qlf).stat().st_size / 1e6, 1))
    cpu, wall = swipl_load(path, qlf=False)
    out.update(consult_s=round(wall, 3), consult_cpu_s=round(cpu, 3))
    cpu, wall = swipl_load(Path(qlf), qlf=True)
    out.update(qlf_load_s=round(wall, 3), qlf_load_cpu_s=round(cpu, 3))

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
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--sizes", default="10000,100000,1000000", help="Comma-separated N (default: %(default)s)."
    )
    parser.add_argument(
        "--dir", default=None, help="Where to write the KB files (default: a temporary directory)."
    )
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
            print(json.dumps(bench(n, Path(tmp))), flush=True)


if __name__ == "__main__":
    main()
