"""Probes and controlled experiments at scale; prints JSON lines.

Lines, in order:

* ``machine``: cores, load average (figures are wall times on a machine that
  may be shared: compare with the load average, and with the CPU seconds given
  beside every wall time);
* ``intervene``: :func:`neurosym.meaning.intervene.intervene` on the
  checkpoint with ``--episodes`` per experiment: experiments, episodes in all,
  wall and CPU seconds, episodes per minute (wall and per CPU minute);
* ``probe``: :func:`neurosym.meaning.probe.probe` with ``--probe-episodes``:
  seconds (wall and CPU) for recording, replay and every probe fit, and the
  probes fitted.

    python bench/meaning.py                                   # rgw2-predinet, 100 / 200 episodes
    python bench/meaning.py --checkpoint checkpoints/rgw2-mhdpa.pt --episodes 200
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def _clock() -> tuple[float, float]:
    return time.perf_counter(), time.process_time()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--checkpoint", default=str(REPO / "checkpoints" / "rgw2-predinet.pt"))
    parser.add_argument("--episodes", type=int, default=100, help="per experiment (default: 100)")
    parser.add_argument("--probe-episodes", type=int, default=200, help="default: 200")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--skip-probe", action="store_true")
    args = parser.parse_args()

    import torch

    from neurosym.agent.agent import load_agent
    from neurosym.meaning.intervene import intervene
    from neurosym.meaning.probe import probe

    print(json.dumps({
        "bench": "machine", "cores": os.cpu_count(), "load_average": os.getloadavg(),
        "torch_threads": torch.get_num_threads(),
    }), flush=True)  # fmt: skip
    agent = load_agent(args.checkpoint)
    wall, cpu = _clock()
    report = intervene(agent, episodes=args.episodes, seed=args.seed)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    total = len(report.experiments) * args.episodes
    print(json.dumps({
        "bench": "intervene", "checkpoint": Path(args.checkpoint).name,
        "experiments": len(report.experiments), "episodes": total,
        "wall_s": round(wall, 2), "cpu_s": round(cpu, 2),
        "episodes_per_min": round(total / wall * 60), "episodes_per_cpu_min": round(total / cpu * 60),
        "load_average": os.getloadavg(),
    }), flush=True)  # fmt: skip
    if args.skip_probe:
        return
    wall, cpu = _clock()
    result = probe(agent, episodes=args.probe_episodes, seed=args.seed)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    print(json.dumps({
        "bench": "probe", "checkpoint": Path(args.checkpoint).name,
        "episodes": args.probe_episodes, "states": result.meta["states"],
        "probes": 2 * len(result.table) * (2 if result.table["untrained_accuracy"].notna().all() else 1),
        "wall_s": round(wall, 2), "cpu_s": round(cpu, 2), "load_average": os.getloadavg(),
    }), flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
