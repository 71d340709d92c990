"""A training run's success curve: training episodes beside levels it never trained on.

Reads a run directory written by ``neurosym train --snapshot-every MINUTES``:
``metrics.csv`` gives the training success (over the run's ``--window``
episodes) against wall time; every ``snapshots/frames-N.pt`` and the final
``checkpoint.pt`` are played on ``--episodes`` levels from reset seed
``--seed`` (3e9 by default: no training run plays those), sampled and greedy.
Prints one JSON line per checkpoint and draws both curves, with uniformly
random actions as the floor, into ``--out``::

    neurosym train --env boxworld --init-from checkpoints/bw3-predinet.pt \\
        --out runs/bw-hard --minutes 120 --snapshot-every 10
    python experiments/curve.py runs/bw-hard --out docs/images/boxworld-curve.png

Minutes are this run's own (a curriculum's earlier stages are in the
checkpoint's ``init_wall_s``).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

UNSEEN = 3_000_000_000


def checkpoints_of(run: Path) -> list[Path]:
    """The run's snapshots in frame order, then its final checkpoint."""
    snaps = sorted((run / "snapshots").glob("frames-*.pt"))
    final = run / "checkpoint.pt"
    return snaps + ([final] if final.exists() else [])


def held_out(agent: Any, path: Path, episodes: int, seed: int, env: str | None) -> dict[str, Any]:
    """One checkpoint's success on unseen levels, sampled and greedy."""
    from neurosym.agent.evaluation import evaluate

    row: dict[str, Any] = {
        "checkpoint": str(path),
        "frames": agent.meta["frames"],
        "minutes": round(float(agent.meta["metrics"].get("wall_s", 0.0)) / 60, 2),
    }
    for mode in ("sampled", "greedy"):
        report = evaluate(agent, env, episodes, greedy=mode == "greedy", seed=seed)
        row[mode] = report.scores.success_rate
    return row


def draw(metrics: Any, points: list[dict[str, Any]], floor: float, title: str, out: Path) -> Path:
    """Training success against minutes, the held-out points on top; written atomically."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from neurosym.viz.output import save_figure

    fig, ax = plt.subplots(figsize=(7, 3.6))
    ax.plot(metrics["wall_s"] / 60, 100 * metrics["success_rate"], lw=0.8, color="0.55",
            label="training episodes (last window)")  # fmt: skip
    minutes = [p["minutes"] for p in points]
    ax.plot(minutes, [100 * p["sampled"] for p in points], "o-", label="unseen levels, sampled")
    ax.plot(minutes, [100 * p["greedy"] for p in points], "s--", label="unseen levels, greedy")
    ax.axhline(100 * floor, color="k", ls=":", lw=1, label="uniformly random actions")
    ax.set_xlabel("minutes of training (2 CPU cores)")
    ax.set_ylabel("success (%)")
    top = max([10.0, 100 * float(metrics["success_rate"].max())]
              + [100 * p[m] for p in points for m in ("sampled", "greedy")])  # fmt: skip
    ax.set_ylim(0, min(100.0, 1.1 * top))
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=8, loc="best")
    fig.tight_layout()
    path = save_figure(fig, out)
    plt.close(fig)
    return path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path, help="run directory (metrics.csv, snapshots/)")
    parser.add_argument("--episodes", type=int, default=300, help="unseen levels per point (300)")
    parser.add_argument("--seed", type=int, default=UNSEEN, help="first reset seed (3e9)")
    parser.add_argument("--env", help="play another env of the family (default: the run's)")
    parser.add_argument("--out", type=Path, help="PNG or SVG to draw (default: none)")
    args = parser.parse_args(argv)

    import pandas as pd
    from train import random_success

    paths = checkpoints_of(args.run)
    if not paths or not (args.run / "metrics.csv").exists():
        parser.error(
            f"{args.run} holds no metrics.csv and checkpoint: a `neurosym train --out` folder?"
        )
    from neurosym.agent.agent import load_agent

    points = []
    for path in paths:
        final = load_agent(path)  # the last one played is the run's final checkpoint
        points.append(held_out(final, path, args.episodes, args.seed, args.env))
        print(json.dumps(points[-1]), flush=True)
    env = args.env or final.env_name
    floor = random_success(env, 1000, args.seed)
    print(json.dumps({"random_actions": floor, "env": env, "episodes": 1000}), flush=True)
    if args.out is not None:
        metrics = pd.read_csv(args.run / "metrics.csv")
        title = f"{final.config.module} on {env}: {len(points)} checkpoints, {args.episodes} unseen levels each"
        print(json.dumps({"figure": str(draw(metrics, points, floor, title, args.out))}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
