"""A Stable-Baselines3 PPO agent, trained on a neurosym env and then taken through neurosym.

    python examples/own_agent/sb3_agent.py --steps 20000 --out ppo_rgw2.zip
    neurosym extract --checkpoint ppo_rgw2.zip --env rgw2 --episodes 20

SB3 trains on the env as gymnasium makes it; neurosym reads the saved .zip (nothing in it is
unpickled: the weights and the policy's plain settings only) and records its behaviour.
"""

import argparse

from stable_baselines3 import PPO

import neurosym.envs  # noqa: F401  (registers the neurosym/... gymnasium ids)
from neurosym.envs import ENVS


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--env", default="rgw2", help="a neurosym env's short name")
    parser.add_argument("--steps", type=int, default=20_000, help="training env steps")
    parser.add_argument("--out", default="ppo_rgw2.zip", help="where the model is saved")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    model = PPO("MlpPolicy", ENVS[args.env], n_steps=128, batch_size=64, seed=args.seed,
                policy_kwargs={"net_arch": [64, 64]}, device="cpu")  # fmt: skip
    model.learn(total_timesteps=args.steps)
    model.save(args.out)
    print(f"wrote {args.out} ({args.steps} steps of PPO on {args.env})")


if __name__ == "__main__":
    main()
