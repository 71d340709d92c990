"""Does the default training learn? Wall time and frames to 90 % training success, per seed.

Runs ``neurosym train --env ENV --module MODULE --seed S --target-success 0.9
--minutes M`` (the defaults otherwise; ``--args`` adds options) for each seed,
one after the other, and prints one row per seed: whether the success rate over
the last ``--window`` training episodes reached the target, the wall seconds of
training and the frames when it did (or the rate it had at the end), and the
load average around the run. A summary line follows. Other jobs on the cores
slow every figure: say the load beside them.

    python bench/train_default.py                      # bw1 PrediNet, seeds 1-5, 5 minutes each
    python bench/train_default.py --seeds 1 2 --minutes 5
    python bench/train_default.py --seeds 1 2 --args "--set query=scene"   # the old recipe
"""

from __future__ import annotations

import argparse
import os
import shlex
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


@dataclass
class SeedRun:
    """One seed's run: what ``neurosym train`` recorded in its checkpoint."""

    seed: int
    reached: bool
    solved_wall_s: float | None
    solved_frames: int | None
    frames: int
    wall_s: float
    success_rate: float | None
    load_before: float
    load_after: float
    error: str = ""

    def row(self) -> str:
        if self.error:
            return f"{self.seed:>4}  error: {self.error}"
        when = (
            f"{self.solved_wall_s:8.1f} {self.solved_frames:>10,}"
            if self.reached
            else f"{'-':>8} {'-':>10}"
        )
        rate = "-" if self.success_rate is None else f"{self.success_rate:.1%}"
        return (
            f"{self.seed:>4}  {'yes' if self.reached else 'no':>7}  {when}  "
            f"{self.wall_s:7.1f} {self.frames:>10,} {self.frames / max(self.wall_s, 1e-9):7,.0f}  "
            f"{rate:>8}  "
            f"{self.load_before:4.2f} -> {self.load_after:4.2f}"
        )


HEADER = "seed  reached  to_90%_s  to_90%_frames  train_s     frames  frames/s  success  load (1 min avg)"


def run_seed(args: argparse.Namespace, seed: int) -> SeedRun:
    """Train one seed until the target or the time limit; read its checkpoint's record."""
    import torch

    load_before = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "run"
        command = [
            sys.executable, "-m", "neurosym", "train", "--env", args.env, "--module", args.module,
            "--out", str(out), "--quiet", "--seed", str(seed), "--target-success",
            str(args.target), "--window", str(args.window), "--minutes", str(args.minutes),
            *shlex.split(args.args),
        ]  # fmt: skip
        env = {**os.environ, "PYTHONHASHSEED": "0"}
        proc = subprocess.run(
            command, cwd=ROOT, env=env, capture_output=True, text=True,
            timeout=args.minutes * 60 + 300, check=False,
        )  # fmt: skip
        load_after = os.getloadavg()[0]
        if proc.returncode != 0:
            last = (proc.stderr.strip().splitlines() or ["no output"])[-1]
            return SeedRun(seed, False, None, None, 0, 0.0, None, load_before, load_after, last)
        payload = torch.load(out / "checkpoint.pt", weights_only=True)
    metrics = payload["metrics"]
    reached = metrics.get("stop_reason") == "target"
    return SeedRun(
        seed=seed,
        reached=reached,
        solved_wall_s=metrics.get("solved_wall_s") if reached else None,
        solved_frames=metrics.get("solved_frames") if reached else None,
        frames=int(payload["frames"]),
        wall_s=float(metrics.get("wall_s", 0.0)),
        success_rate=metrics.get("success_rate"),
        load_before=load_before,
        load_after=load_after,
    )


def summary(runs: list[SeedRun], minutes: float) -> str:
    """How many seeds reached the target in time, and the median and worst time and frames."""
    done = [r for r in runs if r.reached]
    text = f"{len(done)} of {len(runs)} seeds reached the target within {minutes:g} min"
    if done:
        times = [r.solved_wall_s or 0.0 for r in done]
        frames = [r.solved_frames or 0 for r in done]
        text += (
            f"; to the target: median {statistics.median(times):.0f} s, "
            f"{statistics.median(frames):,.0f} frames; slowest {max(times):.0f} s, "
            f"{max(frames):,} frames"
        )
    return text


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--env", default="bw1", help="environment (default bw1)")
    parser.add_argument("--module", default="predinet", help="relational module (default predinet)")
    parser.add_argument(
        "--seeds", type=int, nargs="+", default=[1, 2, 3, 4, 5], help="seeds (default 1 2 3 4 5)"
    )
    parser.add_argument(
        "--minutes", type=float, default=5.0, help="time limit per seed (default 5)"
    )
    parser.add_argument(
        "--target", type=float, default=0.9, help="training success to reach (default 0.9)"
    )
    parser.add_argument(
        "--window", type=int, default=100,
        help="training episodes behind the success rate (default 100, neurosym train's)",
    )  # fmt: skip
    parser.add_argument(
        "--args", default="", help="more neurosym train options, one string (default none)"
    )
    args = parser.parse_args(argv)
    print(
        f"neurosym train --env {args.env} --module {args.module} --target-success {args.target} "
        f"--window {args.window} --minutes {args.minutes:g} {args.args}".rstrip()
        + f"; {len(os.sched_getaffinity(0))} cores",
        flush=True,
    )
    print(HEADER, flush=True)
    runs = []
    start = time.monotonic()
    for seed in args.seeds:
        runs.append(run_seed(args, seed))
        print(runs[-1].row(), flush=True)
    print(summary(runs, args.minutes) + f" ({time.monotonic() - start:.0f} s in all)", flush=True)
    return 0 if all(r.reached for r in runs) else 1


if __name__ == "__main__":
    raise SystemExit(main())
