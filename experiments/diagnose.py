"""Does the fresh network see its input? Logit, value and attention spread, gradient split.

Prints one JSON line per (env, module, preset): the figures of
:mod:`neurosym.agent.diagnostics` on 320 observations met by uniformly random
actions, and the per-layer gradient norms of the actor's and critic's losses
on one rollout's worth of those observations with Monte-Carlo-like returns
from the env's rewards (random actions). Run before and after changing the
model or the learner::

    python experiments/diagnose.py                        # rgw2 and bw1, both modules, both presets
    python experiments/diagnose.py --envs bw1 --presets thesis
    python experiments/diagnose.py --envs bw1 --modules predinet --presets default \
        --ppo-updates 3 --query learned     # also after each of the first PPO updates
"""

from __future__ import annotations

import argparse
import json

import numpy as np
import torch

from neurosym.agent.config import ModelConfig, TrainConfig, preset_env_kwargs
from neurosym.agent.diagnostics import gradient_report, input_signal, signal_after_ppo_updates
from neurosym.agent.networks.model import ActorCritic
from neurosym.envs import env_family, make_batched


def random_rollout(env: str, n_envs: int, steps: int, gamma: float, seed: int, **kwargs):
    """Observations, actions and discounted returns of uniformly random play (no bootstrap)."""
    venv = make_batched(env, n_envs, seed=seed, **kwargs)
    obs, _ = venv.reset(seed=seed)
    rng = np.random.default_rng(seed)
    o, a, r, d = [], [], [], []
    for _ in range(steps):
        act = rng.integers(0, 4, size=n_envs)
        nxt, rew, term, trunc, _ = venv.step(act)
        o.append(obs.copy()), a.append(act), r.append(rew), d.append(term | trunc)
        obs = nxt
    ret = np.zeros(n_envs)
    returns = np.zeros((steps, n_envs), np.float32)
    for t in range(steps - 1, -1, -1):
        ret = r[t] + gamma * ret * (~d[t])
        returns[t] = ret
    return (
        torch.from_numpy(np.concatenate(o)),
        torch.from_numpy(np.concatenate(a).astype(np.int64)),
        torch.from_numpy(returns.reshape(-1)),
        float(np.sum(r)),
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--envs", default="rgw2,bw1")
    parser.add_argument("--modules", default="predinet,mhdpa")
    parser.add_argument("--presets", default="thesis,default")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--ppo-updates",
        type=int,
        default=0,
        help="also print the figures after each of this many PPO updates (default preset only)",
    )
    parser.add_argument(
        "--query", choices=("scene", "learned"), default=None, help="PrediNet's queries"
    )
    args = parser.parse_args()
    torch.set_num_threads(1)
    for env in args.envs.split(","):
        family = env_family(env)
        for preset in args.presets.split(","):
            kwargs = preset_env_kwargs(family, preset)
            train = TrainConfig.for_family(family, preset=preset)
            obs, actions, returns, total = random_rollout(
                env, 8, 40, train.gamma, args.seed, **kwargs
            )
            returns = returns * train.reward_scale
            probe = make_batched(env, 1, **kwargs)
            shape = tuple(probe.single_observation_space.shape)
            scale = float(getattr(probe, "obs_scale", 1.0))
            for module in args.modules.split(","):
                torch.manual_seed(args.seed)
                query = args.query if module == "predinet" else None
                config = ModelConfig.for_family(
                    family, module, shape, scale, preset=preset, query=query
                )
                model = ActorCritic(config)
                row = {"env": env, "module": module, "preset": preset, "obs_shape": list(shape)}
                row["query"] = config.query
                row.update(input_signal(model, obs.numpy()))
                row["rollout_reward"] = total
                row["grads"] = gradient_report(
                    model, obs, actions, returns, train.normalize_advantages
                )
                print(json.dumps(row), flush=True)
                if args.ppo_updates and preset != "thesis":  # thesis is A3C only
                    after = signal_after_ppo_updates(
                        model, env, obs.numpy(), args.ppo_updates, args.seed, **kwargs
                    )
                    for update, figures in enumerate(after, 1):
                        short = {k: row[k] for k in ("env", "module", "preset", "query")}
                        print(json.dumps({**short, "ppo_update": update, **figures}), flush=True)


if __name__ == "__main__":
    main()
