"""A Stable-Baselines3 PPO agent, trained on a neurosym env and then taken through neurosym.

    python examples/own_agent/sb3_agent.py --steps 20000 --out ppo_doorkey.zip
    neurosym extract --checkpoint ppo_doorkey.zip --env MiniGrid-DoorKey-5x5-v0 --episodes 20

SB3 trains on the env as neurosym makes it; neurosym reads the saved .zip without unpickling
anything in it (the weights and the policy's plain settings only) and records its behaviour.
"""

import argparse

from stable_baselines3 import PPO
from stable_baselines3.common.env_util import make_vec_env
from stable_baselines3.common.logger import Logger

from neurosym.envs import make


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--env", default="MiniGrid-DoorKey-5x5-v0", help="a neurosym env")
    parser.add_argument("--steps", type=int, default=20_000, help="training env steps")
    parser.add_argument("--out", default="ppo_doorkey.zip", help="where the model is saved")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    venv = make_vec_env(lambda: make(args.env), n_envs=4, seed=args.seed)
    model = PPO("MlpPolicy", venv, n_steps=64, batch_size=64, seed=args.seed, device="cpu",
                policy_kwargs={"net_arch": [64, 64]})  # fmt: skip
    model.set_logger(Logger(folder=None, output_formats=[]))  # no SB3-* folder in /tmp
    model.learn(total_timesteps=args.steps)
    model.save(args.out)
    print(f"wrote {args.out} ({model.num_timesteps} steps of PPO on {args.env})")


if __name__ == "__main__":
    main()
