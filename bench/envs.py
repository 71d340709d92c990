"""Environment throughput, observations included: one JSON line per measurement.

For each environment: the single env (gymnasium.make, wrappers included); the
batched env with n = 1, 64, 1024, 4096 (``copy=True``, the default, returns a
fresh observation array per step; ``copy=False`` hands out the internal buffer,
RGW only); and a naive Python loop over n single envs. Actions are uniformly
random; episodes reset when they end (the batched envs autoreset). ``tracked``:
the batched env of 512 with episodes cut at 16 steps (a trained agent's pace)
stepped through the learners' ``EpisodeTracker``, which names each ended
episode's outcome.

Figures are steps per second of wall time and of this thread's CPU time (the
latter is less disturbed by other processes on a shared machine). The first
line describes the machine, including its load average.

    python bench/envs.py                       # rgw2, rgw-random, bw1 (and the rest of --envs)
    python bench/envs.py --envs rgw2 --seconds 0.5 --sizes 1,4096
    python bench/envs.py --levels-only         # rgw-random level generation: levels/s

For rgw-random it also measures level generation alone (``generate_levels``
in batches of 1, 64 and 4096, each level searched for its optimal return) and
the first reset of a batched env of 4096 (which generates its 4096 levels).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from collections.abc import Callable

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from neurosym.envs import ENVS, env_family, make, make_batched  # noqa: E402


def timed(step: Callable[[], int], seconds: float) -> tuple[int, float, float]:
    """Call step (which returns the env steps it took) until `seconds` of wall time passed."""
    t0 = time.perf_counter()
    while time.perf_counter() - t0 < seconds / 2:  # warm up (procedural levels: fill buffers)
        step()
    steps, t0, c0 = 0, time.perf_counter(), time.thread_time()
    while time.perf_counter() - t0 < seconds:
        steps += step()
    return steps, time.perf_counter() - t0, time.thread_time() - c0


def single(name: str, seconds: float, **kwargs) -> tuple[int, float, float]:
    env = make(name, **kwargs)
    env.reset(seed=0)
    actions = np.random.default_rng(0).integers(0, 4, 4096).tolist()
    k = [0]

    def chunk() -> int:
        for _ in range(256):
            a = actions[k[0] % 4096]
            k[0] += 1
            _, _, term, trunc, _ = env.step(a)
            if term or trunc:
                env.reset()
        return 256

    return timed(chunk, seconds)


def naive_loop(name: str, n: int, seconds: float) -> tuple[int, float, float]:
    envs = [make(name) for _ in range(n)]
    for i, env in enumerate(envs):
        env.reset(seed=i)
    actions = np.random.default_rng(0).integers(0, 4, (64, n)).tolist()
    k = [0]

    def chunk() -> int:
        row = actions[k[0] % 64]
        k[0] += 1
        for env, a in zip(envs, row, strict=True):
            _, _, term, trunc, _ = env.step(a)
            if term or trunc:
                env.reset()
        return n

    return timed(chunk, seconds)


def batched(name: str, n: int, seconds: float, **kwargs) -> tuple[int, float, float]:
    env = make_batched(name, n, seed=0, **kwargs)
    env.reset()
    actions = np.random.default_rng(0).integers(0, 4, (64, n))
    k = [0]

    def chunk() -> int:
        for _ in range(8):
            env.step(actions[k[0] % 64])
            k[0] += 1
        return 8 * n

    return timed(chunk, seconds)


def level_rates(seconds: float, sizes: tuple[int, ...] = (1, 64, 4096)) -> None:
    """rgw-random: levels generated per second (wall and CPU) per batch size; the first reset."""
    from neurosym.envs.rgw_random import RandomLevelConfig, generate_levels

    cfg = RandomLevelConfig()
    for size in sizes:
        calls = [0]

        def chunk(size: int = size, calls: list[int] = calls) -> int:
            seeds = np.arange(size, dtype=np.uint64) + np.uint64(calls[0] * size)
            generate_levels(cfg, seeds, np.zeros(size, dtype=np.int64))
            calls[0] += 1
            return size

        levels, wall, cpu = timed(chunk, seconds)
        row = {"bench": "levels", "env": "rgw-random", "batch": size, "levels": levels}
        row |= {"wall_s": round(wall, 3), "levels_per_s": round(levels / wall)}
        row |= {"cpu_levels_per_s": round(levels / cpu) if cpu > 0 else None}
        print(json.dumps(row), flush=True)
    t0, c0 = time.perf_counter(), time.thread_time()
    make_batched("rgw-random", 4096, seed=12345).reset()
    first = {"bench": "levels", "env": "rgw-random", "mode": "first_reset", "n": 4096}
    first |= {"wall_s": round(time.perf_counter() - t0, 3)}
    print(json.dumps(first | {"cpu_s": round(time.thread_time() - c0, 3)}), flush=True)
    # What uniformly random actions score against the levels' optimal returns.
    from neurosym.agent.evaluation import score

    rng = np.random.default_rng(0)
    got = score(lambda obs, _venv: rng.integers(0, 4, len(obs)), "rgw-random", 500, seed=0).as_dict()
    keys = ("success_rate", "optimal_rate", "sword_first_guarded", "no_detour_decoy")
    row = {"bench": "random_policy", "env": "rgw-random", "episodes": 500}
    print(json.dumps(row | {k: round(got[k], 4) for k in keys}), flush=True)


def emit(env: str, mode: str, n: int, result: tuple[int, float, float], **extra) -> None:
    steps, wall, cpu = result
    row = {
        "bench": "envs",
        "env": env,
        "mode": mode,
        "n": n,
        **extra,
        "steps": steps,
        "wall_s": round(wall, 3),
        "cpu_s": round(cpu, 3),
        "steps_per_s": round(steps / wall),
        "cpu_steps_per_s": round(steps / cpu) if cpu > 0 else None,
    }
    print(json.dumps(row), flush=True)


def tracked(name: str, n: int, seconds: float) -> tuple[int, float, float]:
    from neurosym.agent.rollout import EpisodeTracker

    env = make_batched(name, n, seed=0, max_steps=16)
    env.reset()
    tracker = EpisodeTracker(n)
    actions = np.random.default_rng(0).integers(0, 4, (64, n))
    k = [0]

    def chunk() -> int:
        for _ in range(8):
            _, reward, terminated, truncated, info = env.step(actions[k[0] % 64])
            tracker.step(env, reward, terminated, truncated, info)
            k[0] += 1
        return 8 * n

    return timed(chunk, seconds)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--envs", default="rgw2,rgw-random,bw1", help="Comma-separated short names.")
    p.add_argument(
        "--sizes", default="1,64,1024,4096", help="Batch sizes (default 1,64,1024,4096)."
    )
    p.add_argument("--seconds", type=float, default=1.0, help="Time per measurement (default 1).")
    p.add_argument("--naive-n", type=int, default=64, help="Envs in the naive loop (default 64).")
    p.add_argument("--levels-only", action="store_true", help="Only rgw-random's level generation.")
    args = p.parse_args(argv)
    names = [s for s in args.envs.split(",") if s]
    for name in names:
        if name not in ENVS:
            p.error(f"unknown environment {name!r}; expected some of {', '.join(ENVS)}")
    sizes = [int(s) for s in args.sizes.split(",") if s]
    print(
        json.dumps(
            {
                "bench": "envs",
                "machine": platform.machine(),
                "python": platform.python_version(),
                "numpy": np.__version__,
                "cpus": os.cpu_count(),
                "load_avg_1m": round(os.getloadavg()[0], 2),
            }
        ),
        flush=True,
    )
    if args.levels_only:
        level_rates(args.seconds)
        return 0
    for name in names:
        if name == "rgw-random":
            level_rates(args.seconds)
        rgw = env_family(name) == "rgw"
        emit(name, "single", 1, single(name, args.seconds))
        emit(name, "naive_loop", args.naive_n, naive_loop(name, args.naive_n, args.seconds))
        emit(name, "tracked", 512, tracked(name, 512, args.seconds), max_steps=16)
        for n in sizes:
            emit(name, "batched", n, batched(name, n, args.seconds), copy=True)
            if rgw:
                emit(name, "batched", n, batched(name, n, args.seconds, copy=False), copy=False)
        if rgw:
            emit(
                name,
                "batched",
                max(sizes),
                batched(name, max(sizes), args.seconds, obs_mode="grey"),
                obs="grey",
                copy=True,
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
