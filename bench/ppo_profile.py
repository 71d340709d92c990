"""Where one PPO update's time goes: env stepping, acting forwards, transfers, the update.

Builds the PPO learner's pieces in this process (model, optimiser, batched
env, the same ``collect_rollout`` and ``ppo_update`` as ``neurosym train
--algo ppo``), warms up, then times ``--updates`` rollout+update cycles,
synchronising the device around each phase. Prints one JSON object: seconds
per cycle split into env steps, the rest of acting (forwards, action draws,
transfers), the update; and frames/s. With ``--trace FILE`` it also writes
torch.profiler's table of one more cycle's ops (sorted by device time).

    python bench/ppo_profile.py --env bw1 --envs 512 --device cuda --trace trace.txt
    python bench/ppo_profile.py --env bw1 --envs 16 --n-steps 16 --updates 1   # CPU smoke run
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import torch  # noqa: E402

from neurosym.agent.config import ModelConfig, TrainConfig  # noqa: E402
from neurosym.agent.learners.optimizers import shared_optimizer  # noqa: E402
from neurosym.agent.learners.ppo import ppo_update  # noqa: E402
from neurosym.agent.networks.model import ActorCritic  # noqa: E402
from neurosym.agent.rollout import RolloutState, collect_rollout  # noqa: E402
from neurosym.agent.run.plan import probe_env  # noqa: E402
from neurosym.envs import make_batched  # noqa: E402


class TimedEnv:
    """A batched env whose ``step`` time is added up (the rest of acting is the model's)."""

    def __init__(self, venv: Any) -> None:
        self.venv, self.seconds = venv, 0.0

    def __getattr__(self, name: str) -> Any:
        return getattr(self.venv, name)

    def step(self, actions: Any) -> Any:
        t = time.perf_counter()
        out = self.venv.step(actions)
        self.seconds += time.perf_counter() - t
        return out


def sync(device: torch.device) -> None:
    if device.type == "cuda":
        torch.cuda.synchronize(device)


def cycle(parts: dict[str, Any], config: TrainConfig, device: torch.device) -> dict[str, float]:
    """One rollout and its update; seconds per phase."""
    env: TimedEnv = parts["env"]
    env.seconds = 0.0
    sync(device)
    t0 = time.perf_counter()
    rollout, _ = collect_rollout(parts["acting"], parts["state"], config.n_steps,
                                 parts["gen"], None, record=True, device=device)  # fmt: skip
    sync(device)
    t1 = time.perf_counter()
    ppo_update(parts["model"], parts["opt"], rollout, config, parts["gen"])
    sync(device)
    t2 = time.perf_counter()
    return {"env_s": env.seconds, "acting_other_s": t1 - t0 - env.seconds, "update_s": t2 - t1}


def build(args: argparse.Namespace, device: torch.device) -> tuple[dict, TrainConfig]:
    name, family, shape, scale = probe_env(args.env, {})
    model_config = ModelConfig.for_family(family, args.module, shape, scale)
    config = TrainConfig.for_family(family, algo="ppo", envs=args.envs, n_steps=args.n_steps)
    torch.manual_seed(0)
    local = ActorCritic(model_config).to(device)
    opt = shared_optimizer(local.parameters(), config)
    env = TimedEnv(make_batched(name, args.envs, seed=0))
    parts = {
        "model": local,
        "acting": local,
        "opt": opt,
        "env": env,
        "state": RolloutState(env, 0),
        "gen": torch.Generator().manual_seed(0),
    }
    return parts, config


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--env", default="bw1")
    p.add_argument("--module", default="predinet", choices=("predinet", "mhdpa"))
    p.add_argument("--envs", type=int, default=512)
    p.add_argument("--n-steps", type=int, default=128)
    p.add_argument("--device", default="cuda" if torch.cuda.is_available() else "cpu")
    p.add_argument("--updates", type=int, default=3, help="timed cycles")
    p.add_argument("--trace", type=Path, help="write the profiler's op table of one cycle here")
    args = p.parse_args()
    device = torch.device(args.device)
    parts, config = build(args, device)
    cycle(parts, config, device)  # warm-up: allocator, cuDNN's algorithm search
    times = [cycle(parts, config, device) for _ in range(args.updates)]
    mean = {k: sum(t[k] for t in times) / len(times) for k in times[0]}
    total = sum(mean.values())
    frames = args.envs * args.n_steps
    row = {"env": args.env, "module": args.module, "envs": args.envs, "n_steps": args.n_steps,
           "device": str(device), **{k: round(v, 4) for k, v in mean.items()},
           "cycle_s": round(total, 4), "frames_per_s": round(frames / total)}  # fmt: skip
    print(json.dumps(row), flush=True)
    if args.trace is not None:
        from torch.profiler import ProfilerActivity, profile

        activities = [ProfilerActivity.CPU]
        if device.type == "cuda":
            activities.append(ProfilerActivity.CUDA)
        with profile(activities=activities) as prof:
            cycle(parts, config, device)
        key = "cuda_time_total" if device.type == "cuda" else "cpu_time_total"
        args.trace.write_text(prof.key_averages().table(sort_by=key, row_limit=30))


if __name__ == "__main__":
    main()
