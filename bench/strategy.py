"""Strategy fidelity per agent and feature set: one JSON line per (agent, feature set, learner).

For each agent, a KB of its training episodes and one of held-out episodes
(made beforehand with ``neurosym extract``, folders ``DIR/NAME-train`` and
``DIR/NAME-test``) are read once; a strategy is learned per feature set
(``world``, ``relations``, ``both``) and learner, and its fidelity (share of
held-out states whose first goal/3 answer is the labelled next object), the
training fidelity, the clause count and the learning time (features and
search, the KBs already read) are printed. The first line describes the
machine.

    # KBs: 200 training episodes (seed 2e9), 100 held-out (seed 3e9)
    neurosym extract --checkpoint checkpoints/bw1-predinet.pt --env bw1 --episodes 200 \\
        --seed 2000000000 --out kbs/bw1-predinet-train
    neurosym extract --checkpoint checkpoints/bw1-predinet.pt --env bw1 --episodes 100 \\
        --seed 3000000000 --out kbs/bw1-predinet-test
    python bench/strategy.py --kbs kbs --agents bw1-predinet [--learners best] [--out DIR]

Both learners are fitted; ``best`` is the one with the higher training
fidelity (``kept``; what ``--learner best`` keeps), its time the sum of the
two. With ``--out DIR`` the best strategy is also written to
``DIR/NAME.FEATURES.pl``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from neurosym.induce.strategy import induce_strategy  # noqa: E402
from neurosym.induce.strategy_data import load_trace  # noqa: E402

AGENTS = (
    "rgw-random-predinet-cellkeys",
    "bw1-predinet",
    "bw2-predinet",
    "bw3-predinet",
    "rgw-random-mhdpa",
    "bw1-mhdpa",
    "bw2-mhdpa",
    "bw3-mhdpa",
)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--kbs", type=Path, required=True, help="folder of NAME-train and NAME-test KBs")
    parser.add_argument("--agents", default=",".join(AGENTS), help="comma-separated agent names")
    parser.add_argument("--features", default="world,relations,both", help="feature sets")
    parser.add_argument(
        "--learners", default="tree,covering,best", help="comma-separated: tree, covering, best"
    )
    parser.add_argument("--out", type=Path, help="write each strategy to OUT/NAME.FEATURES.pl")
    args = parser.parse_args()
    print(json.dumps({"machine": platform.node(), "cpus": os.cpu_count(), "load": os.getloadavg()}))
    for name in args.agents.split(","):
        train_kb = args.kbs / f"{name}-train" / "kb.pl"
        test = load_trace(args.kbs / f"{name}-test" / "kb.pl")
        train = load_trace(train_kb)
        for features in args.features.split(","):
            fitted = {}
            for learner in ("tree", "covering"):
                start = time.perf_counter()
                fitted[learner] = induce_strategy(train, features, holdout=test, learner=learner)
                fitted[learner].seconds = time.perf_counter() - start
            # best: the higher training fidelity, then fewer clauses (as induce_strategy's "best")
            fitted["best"] = max(
                fitted.values(), key=lambda s: (s.train_fidelity, -len(s.model.clauses))
            )
            for learner in args.learners.split(","):
                s = fitted[learner]
                seconds = s.seconds if learner != "best" else sum(
                    fitted[k].seconds for k in ("tree", "covering")
                )
                line = {
                    "agent": name, "features": features, "learner": learner,
                    "kept": s.model.learner,
                    "fidelity": round(s.fidelity, 4), "states": s.states,
                    "train_fidelity": round(s.train_fidelity, 4), "train_states": s.train_states,
                    "clauses": len(s.model.clauses), "seconds": round(seconds, 1),
                }
                print(json.dumps(line), flush=True)
            if args.out:
                best = fitted["best"]
                best.kb = train_kb
                best.write(args.out / f"{name}.{features}.pl")


if __name__ == "__main__":
    main()
