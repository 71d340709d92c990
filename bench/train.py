"""Training benchmarks; prints one JSON object per line.

Parts (``--only`` takes a comma-separated list; default: all):

* ``fps``: training frames per second of ``neurosym train`` with W workers and
  K envs per worker, K in {1, 8, 32}, for each module (steady state: the
  first metrics row, which includes start-up, is left out).
* ``solve``: wall time until the greedy policy reaches the optimal return on
  rgw2 (10.7), per module and seed (default seeds 0 1 2).
* ``boxworld``: bw1 success rate against frames for a fixed frame budget, per
  module: the training success rate (last ``--window`` episodes) at each
  metrics row, and the final checkpoint's sampled success over 1000 episodes;
  first, the success of uniformly random actions over 1000 episodes.
* ``distributed``: PPO frames per second under ``torchrun --standalone
  --nproc_per_node R`` for R in ``--ranks`` (default 1,2), each rank with the
  default 64 envs (weak scaling: the batch grows with the ranks), and the
  figures behind docs/results.md's plan for N machines: parameters, all-reduce
  bytes per update (DDP reduces every minibatch's gradient), frames per
  update, and seconds per update at each R.

Every part runs the real command (``python -m neurosym train``) in a
subprocess, in a temporary directory. Thesis figures for comparison (Box-World,
success over the last 1000 training episodes): bw1 PrediNet 29.3 %, MHDPA
36.5 %; bw2 22.5 %, 22.8 %; bw3 11.3 %, 8.8 %.

    python bench/train.py --only fps,solve
    python bench/train.py --only fps --fps-env bw1 --fps-algos a3c,ppo
    python bench/train.py --only distributed --modules predinet
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]  # the repository: `python -m neurosym` works from here
sys.path.insert(0, str(ROOT))  # the in-process parts import neurosym from here too
MODULES = ("predinet", "mhdpa")
THESIS_BW = {
    "bw1": {"predinet": 0.293, "mhdpa": 0.365},
    "bw2": {"predinet": 0.225, "mhdpa": 0.228},
    "bw3": {"predinet": 0.113, "mhdpa": 0.088},
}


KEEP: Path | None = None  # --keep: run directories are kept here instead of deleted


@contextlib.contextmanager
def run_dir(name: str) -> Iterator[Path]:
    """A fresh directory for one training run (under --keep, or temporary)."""
    if KEEP is not None:
        out = KEEP / name
        shutil.rmtree(out, ignore_errors=True)
        yield out
        return
    with tempfile.TemporaryDirectory() as tmp:
        yield Path(tmp) / "run"


def emit(record: dict) -> None:
    print(json.dumps(record), flush=True)


def neurosym(*args: str, timeout: float) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONHASHSEED": "0"}
    return subprocess.run(
        [sys.executable, "-m", "neurosym", *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=timeout,
        env=env,
        check=False,
    )


def train(
    env: str, module: str, out: Path, *options: str, timeout: float
) -> subprocess.CompletedProcess[str]:
    """``neurosym train --env ENV --module MODULE --out OUT --quiet OPTIONS...``."""
    return neurosym(
        "train", "--env", env, "--module", module, "--out", str(out), "--quiet", *options,
        timeout=timeout,
    )  # fmt: skip


def failed(proc: subprocess.CompletedProcess[str], **record: object) -> bool:
    """True when the run failed, after printing ``record`` with the end of its stderr."""
    if proc.returncode == 0:
        return False
    emit({**record, "error": proc.stderr.strip()[-500:]})
    return True


def rows(out: Path) -> list[dict[str, str]]:
    with (out / "metrics.csv").open(newline="") as fh:
        return list(csv.DictReader(fh))


def checkpoint_metrics(out: Path) -> dict:
    import torch

    return torch.load(out / "checkpoint.pt", weights_only=True)["metrics"]


def bench_fps(
    workers: int,
    seconds: float,
    modules: tuple[str, ...],
    env: str,
    algos: tuple[str, ...] = ("a3c",),
) -> None:
    for algo in algos:
        for module in modules:
            # A3C: K envs per worker; PPO: one learner, K = its default 64 and Table 4's 32
            for k in (1, 8, 32) if algo == "a3c" else (32, 64):
                bench_fps_run(workers, seconds, module, env, algo, k)


def bench_fps_run(workers: int, seconds: float, module: str, env: str, algo: str, k: int) -> None:
    with run_dir(f"fps-{algo}-{module}-k{k}") as out:
        proc = train(
            env, module, out,
            "--algo", algo, "--envs", str(k), "--minutes", str(seconds / 60),
            "--eval-interval", "1000000",
            *(("--workers", str(workers)) if algo == "a3c" else ()),
            timeout=seconds + 120,
        )  # fmt: skip
        if failed(proc, bench="train_fps", module=module, envs=k, algo=algo):
            return
        frames, wall = steady_frames(out)
        emit(
            {
                "bench": "train_fps",
                "env": env,
                "algo": algo,
                "module": module,
                "workers": workers if algo == "a3c" else 1,
                "envs": k,
                "frames": frames,
                "seconds": round(wall, 2),
                "fps": round(frames / wall, 1),
                "cpus": os.cpu_count(),
            }
        )


def steady_frames(out: Path) -> tuple[int, float]:
    """(frames, seconds) between the first and the last metrics rows: start-up left out."""
    table = rows(out)
    first, last = table[0], table[-1]
    return int(last["frames"]) - int(first["frames"]), float(last["wall_s"]) - float(
        first["wall_s"]
    )


def bench_distributed(env: str, modules: tuple[str, ...], ranks: list[int], seconds: float) -> None:
    """PPO frames/s under torchrun for each rank count, and the all-reduce volume per update."""
    from neurosym.agent.config import ModelConfig, TrainConfig, preset_env_kwargs
    from neurosym.agent.networks.model import ActorCritic
    from neurosym.agent.run.plan import probe_env
    from neurosym.envs import env_family

    kwargs = preset_env_kwargs(env_family(env))
    name, family, shape, scale = probe_env(env, kwargs)
    config = TrainConfig.for_family(family, algo="ppo")
    for module in modules:
        params = sum(
            p.numel()
            for p in ActorCritic(ModelConfig.for_family(family, module, shape, scale)).parameters()
        )
        reductions = config.ppo.ppo_epochs * config.ppo.ppo_minibatches  # one gradient all-reduce each
        for r in ranks:
            with run_dir(f"distributed-{module}-r{r}") as out:
                t0 = time.monotonic()
                proc = subprocess.run(
                    [sys.executable, "-m", "torch.distributed.run", "--standalone",
                     "--nproc_per_node", str(r), "-m", "neurosym", "train", "--env", env,
                     "--module", module, "--algo", "ppo", "--out", str(out), "--quiet",
                     "--minutes", str(seconds / 60), "--eval-interval", "1000000"],
                    cwd=ROOT, capture_output=True, text=True, timeout=seconds + 300,
                    env={**os.environ, "PYTHONHASHSEED": "0"}, check=False,
                )  # fmt: skip
                if failed(proc, bench="train_distributed", module=module, ranks=r):
                    continue
                frames, wall = steady_frames(out)
                per_update = r * config.envs * config.n_steps
                emit(
                    {
                        "bench": "train_distributed",
                        "env": name,
                        "module": module,
                        "ranks": r,
                        "envs_per_rank": config.envs,
                        "frames_per_update": per_update,
                        "parameters": params,
                        "allreduce_bytes_per_update": params * 4 * reductions,
                        "frames": frames,
                        "seconds": round(wall, 2),
                        "fps": round(frames / wall, 1),
                        "seconds_per_update": round(wall * per_update / max(frames, 1), 3),
                        "launch_seconds": round(time.monotonic() - t0, 1),
                        "cpus": os.cpu_count(),
                    }
                )


def bench_solve(
    seeds: list[int], modules: tuple[str, ...], workers: int, limit_minutes: float
) -> None:
    for module in modules:
        for seed in seeds:
            with run_dir(f"solve-{module}-s{seed}") as out:
                start = time.monotonic()
                proc = train(
                    "rgw2", module, out,
                    "--seed", str(seed), "--workers", str(workers), "--target-return", "10.7",
                    "--minutes", str(limit_minutes),
                    timeout=limit_minutes * 60 + 120,
                )  # fmt: skip
                elapsed = time.monotonic() - start
                if failed(proc, bench="rgw2_solve", module=module, seed=seed):
                    continue
                m = checkpoint_metrics(out)
                emit(
                    {
                        "bench": "rgw2_solve",
                        "module": module,
                        "seed": seed,
                        "workers": workers,
                        "solved": m.get("stop_reason") == "target",
                        "wall_s": m.get("solved_wall_s"),
                        "frames": m.get("solved_frames"),
                        "greedy_return": m.get("greedy_return"),
                        "process_s": round(elapsed, 1),
                        "target_s": 300,
                    }
                )


def random_success(env: str, episodes: int = 1000, seed: int = 0) -> float:
    """Success rate of uniformly random actions: the floor a learned policy must clear."""
    import numpy as np

    from neurosym.agent.evaluation import play_episodes
    from neurosym.agent.rollout import SUCCESS_OUTCOMES
    from neurosym.envs import make_batched

    rng = np.random.default_rng(seed)
    done = play_episodes(
        lambda obs: rng.integers(0, 4, size=len(obs)),
        lambda n: make_batched(env, n),
        episodes,
        seed,
        batch=250,
    )
    return sum(o in SUCCESS_OUTCOMES for o in done.outcomes) / episodes


def bench_boxworld(
    env: str,
    frames: int,
    modules: tuple[str, ...],
    workers: int,
    seed: int,
    algos: tuple[str, ...] = ("a3c",),
    preset: str = "default",
) -> None:
    emit({"bench": "boxworld_random", "env": env, "episodes": 1000, "success": random_success(env)})
    for algo in algos:
        for module in modules:
            bench_boxworld_run(env, frames, module, workers, seed, algo, preset)


def bench_boxworld_run(
    env: str, frames: int, module: str, workers: int, seed: int, algo: str, preset: str
) -> None:
    """One training run on Box-World: its success curve and the final agent's sampled success."""
    with run_dir(f"{env}-{module}-{algo}") as out:
        learner = ["--algo", algo] + (["--workers", str(workers)] if algo == "a3c" else [])
        proc = train(
            env, module, out, *learner, "--preset", preset,
            "--frames", str(frames), "--seed", str(seed),
            "--window", "1000", "--eval-interval", "30",
            timeout=24 * 3600,
        )  # fmt: skip
        if failed(proc, bench="boxworld", env=env, module=module, algo=algo):
            return
        table = rows(out)
        step = max(1, len(table) // 10)
        curve = [
            {
                "frames": int(r["frames"]),
                "episodes": int(r["episodes"]),
                "success": float(r["success_rate"] or 0),
            }
            for r in table[step - 1 :: step]
        ]
        sampled = neurosym(
            "eval",
            "--checkpoint",
            str(out / "checkpoint.pt"),
            "--episodes",
            "1000",
            "--sample",
            "--json",
            timeout=3600,
        )
        final = (
            json.loads(sampled.stdout)
            if sampled.returncode == 0
            else {"error": sampled.stderr.strip()}
        )
        emit(
            {
                "bench": "boxworld",
                "env": env,
                "module": module,
                "algo": algo,
                "preset": preset,
                "frames": frames,
                "wall_s": float(table[-1]["wall_s"]),
                "train_success_last_1000": float(table[-1]["success_rate"] or 0),
                "sampled_success_1000": final.get("success_rate"),
                "thesis_success": THESIS_BW.get(env, {}).get(module),
                "curve": curve,
            }
        )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--only",
        default="fps,solve,boxworld",
        help="parts to run: fps, solve, boxworld, distributed (default: the first three)",
    )
    parser.add_argument("--fps-env", default="rgw2", help="env of the fps part (rgw2)")
    parser.add_argument(
        "--fps-algos", default="a3c", help="learners of the fps part: a3c, ppo (a3c)"
    )
    parser.add_argument("--ranks", default="1,2", help="rank counts of the distributed part (1,2)")
    parser.add_argument("--dist-env", default="bw1", help="env of the distributed part (bw1)")
    parser.add_argument(
        "--dist-seconds", type=float, default=90.0, help="seconds per distributed run (90)"
    )
    parser.add_argument("--modules", default="predinet,mhdpa", help="modules (comma-separated)")
    parser.add_argument("--workers", type=int, default=2, help="worker processes (2)")
    parser.add_argument(
        "--fps-seconds", type=float, default=40.0, help="seconds per fps measurement (40)"
    )
    parser.add_argument("--seeds", default="0,1,2", help="seeds for the rgw2 solve part (0,1,2)")
    parser.add_argument(
        "--solve-minutes", type=float, default=10.0, help="give up a solve run after this (10)"
    )
    parser.add_argument("--bw-env", default="bw1", help="Box-World configuration (bw1)")
    parser.add_argument(
        "--bw-frames", type=int, default=1_500_000, help="frame budget per Box-World run"
    )
    parser.add_argument(
        "--bw-algos", default="a3c", help="learners for the Box-World part: a3c, ppo (a3c)"
    )
    parser.add_argument(
        "--bw-preset", default="default", help="settings for the Box-World part (default)"
    )
    parser.add_argument(
        "--keep", type=Path, help="keep the run directories (metrics.csv, checkpoint.pt) here"
    )
    args = parser.parse_args(argv)
    global KEEP
    KEEP = args.keep.resolve() if args.keep else None
    parts = {p.strip() for p in args.only.split(",") if p.strip()}
    unknown = parts - {"fps", "solve", "boxworld", "distributed"}
    if unknown:
        parser.error(
            f"unknown part(s) {', '.join(sorted(unknown))}; "
            "choose from fps, solve, boxworld, distributed"
        )
    modules = tuple(m.strip() for m in args.modules.split(",") if m.strip())
    if "fps" in parts:
        algos = tuple(a.strip() for a in args.fps_algos.split(",") if a.strip())
        bench_fps(args.workers, args.fps_seconds, modules, args.fps_env, algos)
    if "distributed" in parts:
        ranks = [int(r) for r in args.ranks.split(",") if r.strip()]
        bench_distributed(args.dist_env, modules, ranks, args.dist_seconds)
    if "solve" in parts:
        bench_solve(
            [int(s) for s in args.seeds.split(",")], modules, args.workers, args.solve_minutes
        )
    if "boxworld" in parts:
        bench_boxworld(
            args.bw_env,
            args.bw_frames,
            modules,
            args.workers,
            seed=0,
            algos=tuple(a.strip() for a in args.bw_algos.split(",") if a.strip()),
            preset=args.bw_preset,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
