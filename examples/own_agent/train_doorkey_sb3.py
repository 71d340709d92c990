"""Train a Stable-Baselines3 PPO agent on MiniGrid-DoorKey-5x5-v0 within a wall-clock budget,
then score it on held-out seeds; the saved .zip goes straight into neurosym.

    python examples/own_agent/train_doorkey_sb3.py --minutes 15 --out ppo_doorkey.zip
    neurosym extract --checkpoint ppo_doorkey.zip --env MiniGrid-DoorKey-5x5-v0 --episodes 20

The policy is SB3's MlpPolicy on neurosym's fully observed Minigrid observation (31 one-hot
planes of the 5 x 5 grid, flattened). Prints one JSON line: steps, minutes, and the greedy
success rate and mean return on --eval-episodes levels from seeds never reset in training.
"""

import argparse
import json
import time

import numpy as np
import torch
from stable_baselines3 import PPO
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.env_util import make_vec_env
from stable_baselines3.common.logger import Logger

from neurosym.envs import make

ENV = "MiniGrid-DoorKey-5x5-v0"
HELD_OUT = 1_000_000_000
"""first evaluation seed: training resets draw levels from the envs' own generators, seeded 0..7"""


class Budget(BaseCallback):
    """Stops learning once the wall-clock budget is spent."""

    def __init__(self, seconds: float) -> None:
        super().__init__()
        self.deadline = time.monotonic() + seconds

    def _on_step(self) -> bool:
        return time.monotonic() < self.deadline


def evaluate(model: PPO, episodes: int, seed: int) -> dict[str, float]:
    """Greedy success rate and mean return on levels reset with seeds seed..seed+episodes-1."""
    env = make(ENV)
    returns, wins = [], 0
    for k in range(episodes):
        obs, _ = env.reset(seed=seed + k)
        total, done = 0.0, False
        while not done:
            action, _ = model.predict(obs, deterministic=True)
            obs, reward, terminated, truncated, _ = env.step(int(action))
            total, done = total + float(reward), terminated or truncated
        returns.append(total)
        wins += total > 0
    return {"success": wins / episodes, "mean_return": float(np.mean(returns))}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=15.0, help="wall-clock training budget")
    parser.add_argument("--steps", type=int, default=2_000_000, help="at most this many env steps")
    parser.add_argument("--out", default="ppo_doorkey.zip")
    parser.add_argument("--eval-episodes", type=int, default=100)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    torch.set_num_threads(1)  # small MLP batches: more threads only contend with the env steps
    venv = make_vec_env(lambda: make(ENV), n_envs=8, seed=args.seed)
    model = PPO("MlpPolicy", venv, n_steps=256, batch_size=256, n_epochs=4, learning_rate=5e-4,
                ent_coef=0.01, gamma=0.99, seed=args.seed, device="cpu",
                policy_kwargs={"net_arch": [128, 128]})  # fmt: skip
    start = time.monotonic()
    model.set_logger(Logger(folder=None, output_formats=[]))  # no SB3-* folder in /tmp
    model.learn(total_timesteps=args.steps, callback=Budget(args.minutes * 60))
    minutes = (time.monotonic() - start) / 60
    model.save(args.out)
    scores = evaluate(model, args.eval_episodes, HELD_OUT)
    print(json.dumps({"env": ENV, "steps": int(model.num_timesteps), "minutes": round(minutes, 2),
                      "eval_seeds": f"{HELD_OUT}..{HELD_OUT + args.eval_episodes - 1}", **scores,
                      "out": args.out}))  # fmt: skip


if __name__ == "__main__":
    main()
