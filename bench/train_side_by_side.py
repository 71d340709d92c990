"""Training frames/s of several code trees or settings, run one after another on one machine.

Each ``--run LABEL=CODE_DIR[ EXTRA ARGS]`` runs ``python -m neurosym train`` with
``PYTHONPATH=CODE_DIR`` (e.g. a copy of an older revision made with ``git archive REV neurosym
| tar -x -C DIR``, or ``.`` for this tree) for ``--seconds`` with the shared ``-- TRAIN ARGS``,
then prints one JSON line: steady frames/s (the first metrics row, start-up, left out), frames,
and the last training success rate. Runs alternate in the order given, ``--repeat`` times.

    python bench/train_side_by_side.py --seconds 50 --run "before=.base" \\
        --run "after=. --set precision=bf16" -- --env bw1 --module predinet --algo ppo \\
        --device cuda --envs 512
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path


def steady(out: Path) -> dict[str, float]:
    """frames/s between the first and last metrics rows, and the last row's figures."""
    with open(out / "metrics.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    if len(rows) < 2:
        return {"fps": float("nan"), "frames": float(rows[-1]["frames"]) if rows else 0.0}
    first, last = rows[0], rows[-1]
    frames = int(last["frames"]) - int(first["frames"])
    wall = float(last["wall_s"]) - float(first["wall_s"])
    success = [r["success_rate"] for r in rows if r["success_rate"]]
    return {
        "fps": round(frames / wall, 1),
        "frames": int(last["frames"]),
        "wall_s": round(float(last["wall_s"]), 1),
        "success_rate": float(success[-1]) if success else float("nan"),
    }


def one(label: str, spec: str, seconds: float, train_args: list[str]) -> dict[str, object]:
    code, *extra = shlex.split(spec)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "run"
        env = {**os.environ, "PYTHONPATH": os.pathsep.join(
            [str(Path(code).resolve()), os.environ.get("PYTHONPATH", "")])}  # fmt: skip
        cmd = [sys.executable, "-m", "neurosym", "train", "--out", str(out), "--quiet",
               "--minutes", str(seconds / 60), *train_args, *extra]  # fmt: skip
        proc = subprocess.run(cmd, env=env, capture_output=True, text=True)
        if proc.returncode != 0 or not (out / "metrics.csv").exists():
            return {"label": label, "error": proc.stderr.strip().splitlines()[-1:]}
        return {"label": label, "code": code, "extra": " ".join(extra), **steady(out)}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--run", action="append", required=True, metavar="LABEL=CODE_DIR[ ARGS]")
    p.add_argument("--seconds", type=float, default=60.0)
    p.add_argument("--repeat", type=int, default=1)
    p.add_argument("train_args", nargs="*", help="after --: arguments every run shares")
    args = p.parse_args()
    runs = [r.split("=", 1) for r in args.run]
    for _ in range(args.repeat):
        for label, spec in runs:
            print(json.dumps(one(label, spec, args.seconds, args.train_args)), flush=True)


if __name__ == "__main__":
    main()
