"""neurosym's learners beside an outside peer on Box-World: frames and wall time to a success rate.

Side by side, one after the other on the same cores, the same frame budget:

* ``neurosym-a3c``: ``neurosym train --algo a3c`` (the default preset);
* ``neurosym-ppo``: ``neurosym train --algo ppo``;
* ``sb3-ppo``: Stable-Baselines3's PPO (``pip install stable-baselines3``; it is
  not a neurosym dependency) on the same env and one-hot observation, with a
  small CNN policy (two 3x3 convolutions, 256 units) and the settings of
  neurosym's PPO: 64 envs x 128 steps, 4 epochs of 4 minibatches, lr 5e-4,
  gamma 0.99, GAE 0.95, clip 0.2, entropy 0.01, rewards x 0.1
  (``--sb3-n-steps`` / ``--sb3-epochs`` change the rollout and passes, to
  give the peer what ``--ppo-args`` gives neurosym's PPO).

For each it prints one JSON line: the frames and wall seconds at which the
success rate over the last ``--window`` training episodes first reached
``--target`` (null if never), the final success rate, and the total wall
time. Each run ends when it reaches the target (``neurosym train
--target-success``; SB3 through its callback) or at the frame budget, so a
fast learner costs the bench little; ``--no-stop-at-target`` plays every
budget out. The SB3 policy is a plain CNN, not a relational module: it answers how
fast this machine learns the task at all, and so how much neurosym's learners
and relational modules cost or save::

    python bench/peers.py --env bw1 --frames 1500000            # all three, PrediNet
    python bench/peers.py --runs sb3-ppo --frames 500000
    python bench/peers.py --frames 5000000 --minutes 15          # each run: 15 minutes at most
    python bench/peers.py --runs neurosym-a3c --a3c-args '--envs 32'   # other train flags

neurosym's fastest learners on bw1 (docs/results.md) have
learned PrediNet queries: A3C 4.5-7.1x SB3's PPO in wall time to 90 % (seeds
0-2), PPO with short rollouts and a running advantage scale 2.7-4.2x (seeds 0-3)::

    python bench/peers.py --env bw1 --frames 5000000 --minutes 8 --runs neurosym-a3c \
        --a3c-args '--set query=learned'
    python bench/peers.py --env bw1 --frames 5000000 --minutes 8 --runs neurosym-ppo \
        --ppo-args '--n-steps 64 --ppo-epochs 2 --set query=learned --set ppo_advantages=running'
"""

from __future__ import annotations

import argparse
import collections
import csv
import json
import shlex
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from train import neurosym  # noqa: E402  (bench/train.py: the CLI in a subprocess)

RUNS = ("neurosym-a3c", "neurosym-ppo", "sb3-ppo")


def emit(record: dict) -> None:
    print(json.dumps(record), flush=True)


def first_reaching(
    rows: list[dict[str, str]], target: float, window: int
) -> tuple[int | None, float | None]:
    """(frames, wall_s) of the first metrics row whose success_rate over a full window reached ``target``."""
    for row in rows:
        if (
            int(row["episodes"]) >= window
            and row["success_rate"]
            and float(row["success_rate"]) >= target
        ):
            return int(row["frames"]), float(row["wall_s"])
    return None, None


def run_neurosym(algo: str, env: str, module: str, frames: int, args: argparse.Namespace) -> dict:
    with tempfile.TemporaryDirectory(prefix="neurosym-peers-") as tmp:
        out = Path(tmp) / "run"
        start = time.monotonic()
        proc = neurosym(
            "train", "--env", env, "--module", module, "--algo", algo, "--out", str(out),
            "--frames", str(frames), "--seed", str(args.seed), "--window", str(args.window),
            *(("--minutes", str(args.minutes)) if args.minutes else ()),
            "--eval-interval", "60", "--quiet", *shlex.split(getattr(args, f"{algo}_args")),
            *(("--target-success", str(args.target)) if args.stop_at_target else ()),
            timeout=24 * 3600,
        )  # fmt: skip
        wall = time.monotonic() - start
        if proc.returncode != 0:
            return {"error": proc.stderr.strip()[-500:]}
        with (out / "metrics.csv").open(newline="") as fh:
            rows = list(csv.DictReader(fh))
    hit_frames, hit_wall = first_reaching(rows, args.target, args.window)
    return {
        "frames_to_target": hit_frames,
        "wall_s_to_target": hit_wall,
        "final_success": float(rows[-1]["success_rate"] or 0),
        "frames": int(rows[-1]["frames"]),
        "wall_s": round(wall, 1),
    }


def run_sb3(env_name: str, frames: int, args: argparse.Namespace) -> dict:
    try:
        import gymnasium as gym
        import torch
        from stable_baselines3 import PPO
        from stable_baselines3.common.callbacks import BaseCallback
        from stable_baselines3.common.logger import Logger
        from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
        from stable_baselines3.common.vec_env import DummyVecEnv
    except ImportError:
        return {"error": "stable-baselines3 is not installed: pip install stable-baselines3"}
    from neurosym.agent.rollout import SUCCESS_OUTCOMES
    from neurosym.envs import make

    class SmallCNN(BaseFeaturesExtractor):
        def __init__(self, space: gym.spaces.Box) -> None:
            super().__init__(space, features_dim=256)
            c, h, w = space.shape
            self.net = torch.nn.Sequential(
                torch.nn.Conv2d(c, 32, 3, padding=1), torch.nn.ReLU(),
                torch.nn.Conv2d(32, 32, 3, padding=1), torch.nn.ReLU(),
                torch.nn.Flatten(), torch.nn.Linear(32 * h * w, 256), torch.nn.ReLU(),
            )  # fmt: skip

        def forward(self, obs: torch.Tensor) -> torch.Tensor:
            return self.net(obs)

    class Success(BaseCallback):
        """Success over the last ``window`` episodes; stops at the frame budget."""

        def __init__(self) -> None:
            super().__init__()
            self.recent: collections.deque[bool] = collections.deque(maxlen=args.window)
            self.hit: tuple[int, float] | None = None
            self.start = time.monotonic()

        def _on_step(self) -> bool:
            for info, done in zip(self.locals["infos"], self.locals["dones"], strict=True):
                if done:
                    self.recent.append(info.get("outcome") in SUCCESS_OUTCOMES)
            if (
                self.hit is None
                and len(self.recent) == args.window
                and sum(self.recent) / args.window >= args.target
            ):
                self.hit = (self.num_timesteps, time.monotonic() - self.start)
            if args.minutes and time.monotonic() - self.start >= 60 * args.minutes:
                return False
            return self.hit is None or not args.stop_at_target

    def make_env() -> gym.Env:
        env = make(env_name, obs_mode="onehot")
        return gym.wrappers.TransformReward(env, lambda r: 0.1 * r)

    torch.set_num_threads(args.threads)
    envs, minibatches = 64, 4  # neurosym's PPO: 64 envs, 4 minibatches per pass
    venv = DummyVecEnv([make_env] * envs)
    venv.seed(args.seed)
    model = PPO(
        "CnnPolicy", venv, n_steps=args.sb3_n_steps,
        batch_size=envs * args.sb3_n_steps // minibatches, n_epochs=args.sb3_epochs,
        learning_rate=5e-4,
        gamma=0.99, gae_lambda=0.95, clip_range=0.2, ent_coef=0.01, vf_coef=0.5,
        max_grad_norm=0.5, seed=args.seed, verbose=0,
        policy_kwargs={"features_extractor_class": SmallCNN, "normalize_images": False},
    )  # fmt: skip
    callback = Success()
    model.set_logger(Logger(folder=None, output_formats=[]))  # no SB3-* folder in /tmp
    model.learn(total_timesteps=frames, callback=callback)
    recent = list(callback.recent)
    return {
        "frames_to_target": callback.hit[0] if callback.hit else None,
        "wall_s_to_target": round(callback.hit[1], 1) if callback.hit else None,
        "final_success": sum(recent) / len(recent) if recent else None,
        "frames": int(model.num_timesteps),
        "wall_s": round(time.monotonic() - callback.start, 1),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--env", default="bw1", help="Box-World configuration (bw1)")
    parser.add_argument("--module", default="predinet", help="neurosym's relational module")
    parser.add_argument("--frames", type=int, default=1_500_000, help="frame budget per run")
    parser.add_argument(
        "--minutes", type=float, default=None, help="also a wall-clock budget per run (minutes)"
    )
    parser.add_argument("--runs", default=",".join(RUNS), help=f"any of {', '.join(RUNS)}")
    parser.add_argument("--target", type=float, default=0.9, help="success rate to reach (0.9)")
    parser.add_argument("--window", type=int, default=500, help="training episodes behind it")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--threads", type=int, default=2, help="torch threads for SB3 (2)")
    parser.add_argument(
        "--sb3-n-steps", type=int, default=128, help="SB3: steps per env per update (128)"
    )
    parser.add_argument("--sb3-epochs", type=int, default=4, help="SB3: passes per update (4)")
    parser.add_argument(
        "--stop-at-target",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="end each run when it reaches --target (default) rather than at the frame budget",
    )
    for algo in ("a3c", "ppo"):
        parser.add_argument(
            f"--{algo}-args",
            default="",
            metavar="FLAGS",
            help=f"more `neurosym train` flags for neurosym-{algo}, e.g. '--envs 32' (none)",
        )
    args = parser.parse_args(argv)
    if args.sb3_n_steps < 4 or args.sb3_epochs < 1:
        parser.error("--sb3-n-steps must be >= 4 and --sb3-epochs >= 1")
    runs = [r.strip() for r in args.runs.split(",") if r.strip()]
    unknown = sorted(set(runs) - set(RUNS))
    if unknown:
        parser.error(f"unknown run(s) {', '.join(unknown)}; choose from {', '.join(RUNS)}")
    for run in runs:
        if run == "sb3-ppo":
            result = run_sb3(args.env, args.frames, args)
        else:
            result = run_neurosym(run.split("-")[1], args.env, args.module, args.frames, args)
        emit(
            {
                "bench": "peers",
                "run": run,
                "env": args.env,
                "module": None if run == "sb3-ppo" else args.module,
                "target": args.target,
                "budget_frames": args.frames,
                "budget_minutes": args.minutes,
                "flags": (
                    f"n_steps={args.sb3_n_steps} n_epochs={args.sb3_epochs}"
                    if run == "sb3-ppo"
                    else getattr(args, f"{run.split('-')[1]}_args")
                ),
                **result,
            }
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
