"""Greedy play of RGW agents on the eight turned and mirrored copies of a fixed map.

One fixed map is one route, and whether a general agent's greedy play of it
earns the optimum can come and go between training states minutes apart.
The map's copies under the square's symmetries (turned 0-3 quarter turns,
with and without a mirror) have the same optimal return, so counting the
copies played at the optimum says more than the one map does. Copy 0 is the
map itself; copies 1-3 are it turned, 4-7 the mirrored map turned::

    python experiments/map_copies.py checkpoints/rgw-random-predinet-cellkeys.pt --map rgw2

Prints one JSON line per checkpoint: each copy's greedy return and optimal
return, and the counts at the optimum, finished short of it, and unfinished.
"""

from __future__ import annotations

import argparse
import json
from typing import Any

import numpy as np

TOLERANCE = 1e-6


def copies(source: str) -> list[str]:
    """The eight symmetric copies of a map (a shipped name, a file or map text), as map text."""
    from neurosym.envs.rgw_maps import load_map

    grid = load_map(source).text().splitlines()
    chars = np.array([list(row) for row in grid])
    out = []
    for mirrored in (False, True):
        base = np.fliplr(chars) if mirrored else chars
        for turns in range(4):
            turned = np.rot90(base, turns)
            out.append("\n".join("".join(row) for row in turned) + "\n")
    return out


def play_copies(agent: Any, source: str) -> dict[str, Any]:
    """Greedy return and optimal return of ``agent`` on each copy of ``source`` (one episode each)."""
    from neurosym.agent.evaluation import evaluate
    from neurosym.agent.rollout import SUCCESS_OUTCOMES

    returns, optimal, counts = [], [], {"at_optimum": 0, "short": 0, "unfinished": 0}
    for text in copies(source):
        report = evaluate(agent, "rgw2", episodes=1, greedy=True, env_kwargs={"map": text}).as_dict()
        ret, best = report["mean_return"], report["mean_optimal_return"]
        returns.append(round(ret, 3))
        optimal.append(round(best, 3))
        if ret >= best - TOLERANCE:
            counts["at_optimum"] += 1
        elif any(o in SUCCESS_OUTCOMES for o in report["outcomes"]):
            counts["short"] += 1
        else:
            counts["unfinished"] += 1
    return {"returns": returns, "optimal": optimal, **counts}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("checkpoints", nargs="+", help="checkpoint files of RGW agents")
    parser.add_argument(
        "--map", default="rgw2", help="rgw1, rgw2 or a map file whose copies to play (rgw2)"
    )
    args = parser.parse_args(argv)

    import torch

    from neurosym.agent.agent import load_agent

    torch.set_num_threads(1)
    for path in args.checkpoints:
        result = play_copies(load_agent(path), args.map)
        print(json.dumps({"bench": "map_copies", "checkpoint": path, "map": args.map, **result}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
