"""What keeping freed memory (neurosym.agent.learners.allocator) saves in an update's forward and backward.

Each measurement runs in a fresh process (the malloc settings are process-wide
and stay), one torch thread, on the batch one A3C update sees: K envs x 40
steps, plus the K last observations and the 40 self-imitation rows. It
prints one JSON line per case with the milliseconds per forward+backward, the
minor page faults per iteration and the kernel (system) time per iteration::

    python experiments/allocator.py                   # rgw2 K = 32 and bw1 K = 8, PrediNet and MHDPA
    python experiments/allocator.py --cases rgw2:32:predinet --iters 20
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys

CHILD = r"""
import json, resource, sys, time
import torch
from neurosym.agent.learners.allocator import keep_freed_memory
from neurosym.agent.config import ModelConfig, preset_env_kwargs
from neurosym.agent.networks.model import ActorCritic
from neurosym.agent.run.plan import probe_env
from neurosym.envs import env_family, make_batched

env, k, module, keep, iters = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4] == "1", int(sys.argv[5])
torch.set_num_threads(1)
kept = keep_freed_memory() if keep else False
kwargs = preset_env_kwargs(env_family(env))
name, family, shape, scale = probe_env(env, kwargs)
model = ActorCritic(ModelConfig.for_family(family, module, shape, scale))
venv = make_batched(env, 64, seed=0, **kwargs)
obs, _ = venv.reset(seed=0)
batch = k * 40 + k + 40
x = torch.as_tensor(obs)[torch.randint(0, 64, (batch,), generator=torch.Generator().manual_seed(0))]

def step():
    logits, value = model(x)
    (logits.logsumexp(-1).sum() + value.pow(2).sum()).backward()

for _ in range(3):
    step()
before, start = resource.getrusage(resource.RUSAGE_SELF), time.perf_counter()
for _ in range(iters):
    step()
after, wall = resource.getrusage(resource.RUSAGE_SELF), time.perf_counter() - start
print(json.dumps({
    "bench": "allocator", "env": env, "module": module, "envs": k, "batch": batch,
    "keep_freed_memory": keep, "settings_taken": kept,
    "ms_per_update": round(wall / iters * 1000, 1),
    "page_faults_per_update": round((after.ru_minflt - before.ru_minflt) / iters),
    "system_ms_per_update": round((after.ru_stime - before.ru_stime) / iters * 1000, 1),
}), flush=True)
"""


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--cases",
        default="rgw2:32:predinet,rgw2:32:mhdpa,bw1:8:predinet,bw1:8:mhdpa",
        help="ENV:K:MODULE, comma-separated (default: rgw2 K = 32 and bw1 K = 8, both modules)",
    )
    parser.add_argument("--iters", type=int, default=10, help="timed iterations per case (10)")
    args = parser.parse_args(argv)
    for case in args.cases.split(","):
        env, k, module = case.split(":")
        for keep in ("0", "1"):
            proc = subprocess.run(
                [sys.executable, "-c", CHILD, env, k, module, keep, str(args.iters)],
                capture_output=True,
                text=True,
            )
            if proc.returncode != 0:
                print(json.dumps({"bench": "allocator", "case": case, "error": proc.stderr[-400:]}))
                continue
            print(proc.stdout.strip(), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
