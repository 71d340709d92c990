"""What the attention target's loss (``--set attend_coef``) adds to an imitation update.

    python bench/attend_loss.py --checkpoint checkpoints/bw2-predinet-bottleneck.pt \\
        --checkpoint checkpoints/rgw-random-predinet-bottleneck.pt [--code DIR ...]

For each code tree (``--code``, PYTHONPATH for one process each; default this one) and
checkpoint: 512 observations of the checkpoint's env (random steps), random target cells,
then gradient steps of :func:`imitation_update` with attend_coef 0 and 1 alternately, one
torch thread; prints one JSON line per pair: the median ms of a step with and without the
loss. Trees alternate, ``--repeat`` times, so that a busy machine slows them alike.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path


def worker(checkpoint: str, steps: int) -> dict[str, object]:
    import numpy as np
    import torch

    from neurosym.agent.agent import load_agent
    from neurosym.agent.config import TrainConfig
    from neurosym.agent.learners.imitation import LabelBuffer, imitation_update
    from neurosym.envs import env_family, make_batched

    torch.set_num_threads(1)
    agent = load_agent(checkpoint)
    model = agent.model.float().train()
    venv = make_batched(agent.env_name, 64, seed=0, **agent.env_kwargs)
    obs, _ = venv.reset(seed=0)
    rng = np.random.default_rng(0)
    buf = LabelBuffer(512, obs.shape[1:], obs.dtype)
    n_cells = int(np.prod(obs.shape[2:]))
    for _ in range(8):
        sets = np.zeros((len(obs), 4), dtype=bool)
        sets[np.arange(len(obs)), rng.integers(0, 4, len(obs))] = True
        targets = rng.integers(-1, n_cells, (len(obs), 2)).astype(np.int16)
        buf.add(obs, sets, np.zeros(len(obs), np.float32), targets=targets)
        obs, *_ = venv.step(rng.integers(0, 4, len(obs)))
    family = env_family(agent.env_name)  # Box-World has no planner: a teacher's labels instead
    teacher = {"teacher": checkpoint} if family == "boxworld" else {}
    base = TrainConfig.for_family(family, algo="imitate", augment=False, **teacher)
    opt = torch.optim.Adam(model.parameters(), lr=1e-6)
    ms: dict[float, list[float]] = {0.0: [], 1.0: []}
    for i in range(steps + 3):
        for coef in ms:
            config = base.replace(attend_coef=coef, dagger_batch=512, dagger_steps=1)
            start = time.perf_counter()
            imitation_update(model, opt, buf, config, rng, torch.device("cpu"))
            if i >= 3:
                ms[coef].append(1000 * (time.perf_counter() - start))
    return {
        "without_ms": round(statistics.median(ms[0.0]), 1),
        "with_ms": round(statistics.median(ms[1.0]), 1),
    }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--checkpoint", action="append", required=True)
    p.add_argument("--code", action="append", help="a code tree (default: this one)")
    p.add_argument("--steps", type=int, default=20)
    p.add_argument("--repeat", type=int, default=2)
    p.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = p.parse_args()
    if args.worker:
        print(json.dumps(worker(args.checkpoint[0], args.steps)))
        return
    root = Path(__file__).resolve().parent.parent
    for _ in range(args.repeat):
        for code in args.code or [str(root)]:
            for ck in args.checkpoint:
                env = {**os.environ, "PYTHONPATH": str(Path(code).resolve())}
                out = subprocess.run(
                    [sys.executable, __file__, "--worker", "--checkpoint", ck,
                     "--steps", str(args.steps)],
                    env=env, capture_output=True, text=True, cwd=root, check=True,
                )  # fmt: skip
                result = json.loads(out.stdout.strip().splitlines()[-1])
                print(json.dumps({"code": code, "checkpoint": ck, **result}), flush=True)


if __name__ == "__main__":
    main()
