"""Where an RGW agent's episodes fall short of their level's optimal return.

``neurosym eval`` says how many episodes earned the optimum (``optimal_rate``);
this says what the others did instead, so that a change to the learner can be
aimed at the right loss. Each episode on ``--episodes`` unseen levels (reset
seeds from ``--seed``) goes in one class:

* ``optimal``: earned the level's optimal return;
* ``unfinished``: never reached the terminal (timeout, pit, killed);
* ``decoy_enemy_left``: a decoy level finished 1 or more short of the optimum:
  the +1 for beating the enemy was not taken (with or without the sword);
* ``small_detour``: finished less than 1 short: a few mountain cells (-0.1
  each) more than the best route crossed;

and each class is split by level kind (guarded or decoy)::

    python experiments/optimal_gap.py checkpoints/rgw-random-predinet-cellkeys.pt runs/x/checkpoint.pt

Prints one JSON line per checkpoint and mode (sampled, greedy).
"""

from __future__ import annotations

import argparse
import json
from collections import Counter
from typing import Any

import numpy as np

UNSEEN = 3_000_000_000


def classify(done: Any) -> Counter[str]:
    """``kind:class`` counts of a ScoredEpisodes (neurosym.agent.evaluation)."""
    from neurosym.agent.evaluation import TOLERANCE
    from neurosym.agent.rollout import SUCCESS_OUTCOMES

    counts: Counter[str] = Counter()
    for ret, best, guarded, outcome in zip(
        done.returns, done.optimal_return, done.guarded, done.outcomes, strict=True
    ):
        kind = "guarded" if guarded else "decoy"
        gap = best - ret
        if gap <= TOLERANCE:
            what = "optimal"
        elif outcome not in SUCCESS_OUTCOMES:
            what = "unfinished"
        elif not guarded and gap >= 1 - TOLERANCE:
            what = "decoy_enemy_left"
        elif gap < 1 - TOLERANCE:
            what = "small_detour"
        else:
            what = "other"
        counts[f"{kind}:{what}"] += 1
    return counts


def play(agent: Any, greedy: bool, env: str, episodes: int, seed: int) -> Any:
    """The agent's ScoredEpisodes on ``episodes`` levels from reset seed ``seed``."""
    import torch

    from neurosym.agent.evaluation import play_scored
    from neurosym.envs import make_batched

    generator = None if greedy else torch.Generator().manual_seed(seed)
    return play_scored(
        lambda obs, _venv: agent.act(obs, greedy=greedy, generator=generator)[0],
        lambda n: make_batched(env, n, seed=seed),
        episodes,
        seed,
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("checkpoints", nargs="+", help="checkpoint files of RGW agents")
    parser.add_argument("--env", default="rgw-random", help="an RGW env (rgw-random)")
    parser.add_argument("--episodes", type=int, default=300, help="levels per mode (300)")
    parser.add_argument("--seed", type=int, default=UNSEEN, help="first reset seed (3e9)")
    args = parser.parse_args(argv)

    from neurosym.agent.agent import load_agent

    for path in args.checkpoints:
        agent = load_agent(path)
        for greedy in (False, True):
            done = play(agent, greedy, args.env, args.episodes, args.seed)
            counts = classify(done)
            gaps = np.asarray(done.optimal_return) - np.asarray(done.returns)
            print(
                json.dumps(
                    {
                        "bench": "optimal_gap",
                        "checkpoint": path,
                        "env": args.env,
                        "mode": "greedy" if greedy else "sampled",
                        "episodes": args.episodes,
                        "mean_gap": round(float(gaps.mean()), 3),
                        **dict(sorted(counts.items())),
                    }
                ),
                flush=True,
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
