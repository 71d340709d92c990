"""How much a trained agent's critic knows: explained variance of its values, before fine-tuning.

An imitation agent (``--algo imitate``) never trains its value head, so an A3C
fine-tune (``--init-from``) starts from advantages that are mostly noise. This
plays the agent's sampled policy on ``--envs`` levels for ``--steps`` steps,
takes the Monte-Carlo returns (rewards x ``--reward-scale``) of the steps
whose episode ended inside the window (the autoreset step between two
episodes counts as the next one's first: a few % of the states), and prints
one JSON line per discount:

* ``explained_variance`` of the value head against those returns;
* ``ridge_r2``: 5-fold R^2 of a ridge fit (scikit-learn) on the last hidden
  layer, i.e. what a retrained value head alone could reach;
* ``grad_norms``: the actor's and the critic's gradient norms per part of
  the network (:func:`neurosym.agent.diagnostics.gradient_report`).

Usage::

    python experiments/critic_fit.py checkpoints/rgw-random-predinet-cellkeys.pt
    python experiments/critic_fit.py runs/x/checkpoint.pt --gammas 0.99
"""

from __future__ import annotations

import argparse
import json

import numpy as np
import torch


def play(agent, env: str, n_envs: int, steps: int, seed: int):
    """(obs (T, K, ...), actions (T, K), rewards (T, K), done (T, K)) of the sampled policy."""
    from neurosym.envs import make_batched

    venv = make_batched(env, n_envs, seed=seed)
    obs, _ = venv.reset(seed=seed)
    generator = torch.Generator().manual_seed(seed)
    frames, actions, rewards, done = [], [], [], []
    for _ in range(steps):
        act, _ = agent.act(obs, greedy=False, generator=generator)
        nxt, rew, term, trunc, _ = venv.step(act)
        frames.append(obs.copy()), actions.append(act), rewards.append(rew)
        done.append(term | trunc)
        obs = nxt
    return np.array(frames), np.array(actions), np.array(rewards, np.float32), np.array(done)


def mc_returns(
    rewards: np.ndarray, done: np.ndarray, gamma: float
) -> tuple[np.ndarray, np.ndarray]:
    """Discounted returns to each episode's end, and which steps' episodes ended in the window."""
    T, K = rewards.shape
    returns, known = np.zeros((T, K), np.float32), np.zeros((T, K), bool)
    running, ended = np.zeros(K, np.float32), np.zeros(K, bool)
    for t in reversed(range(T)):
        running = np.where(done[t], 0.0, running) + rewards[t]
        ended = ended | done[t]
        running = running.astype(np.float32)
        returns[t], known[t] = running, ended
        running = gamma * running
    return returns, known


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("checkpoint")
    parser.add_argument("--env", default=None, help="env to play (the agent's own)")
    parser.add_argument("--envs", type=int, default=64, help="levels played at once (64)")
    parser.add_argument("--steps", type=int, default=100, help="steps each (100)")
    parser.add_argument("--gammas", default="0.95,0.99,1.0", help="discounts (0.95,0.99,1.0)")
    parser.add_argument("--reward-scale", type=float, default=0.1, help="as in training (0.1)")
    parser.add_argument("--seed", type=int, default=12345)
    args = parser.parse_args(argv)

    from sklearn.linear_model import Ridge
    from sklearn.model_selection import cross_val_score

    from neurosym.agent.agent import load_agent
    from neurosym.agent.diagnostics import gradient_report
    from neurosym.agent.learners.returns import explained_variance

    agent = load_agent(args.checkpoint)
    model = agent.model
    env = args.env or agent.env_name
    frames, actions, rewards, done = play(agent, env, args.envs, args.steps, args.seed)
    obs = torch.as_tensor(frames).flatten(0, 1)
    with torch.no_grad():
        x = obs.to(torch.float32) * model.config.obs_scale
        hidden = model.body(model.relational(model.encoder(x))[0])
        values = model.value(hidden).squeeze(-1)
    T, K = rewards.shape
    hidden, values = hidden.view(T, K, -1).numpy(), values.view(T, K).numpy()
    for gamma in (float(g) for g in args.gammas.split(",")):
        returns, known = mc_returns(rewards * args.reward_scale, done, gamma)
        target, value = returns[known], values[known]
        r2 = cross_val_score(Ridge(alpha=1.0), hidden[known], target, cv=5, scoring="r2")
        grads = gradient_report(
            model,
            torch.as_tensor(frames[known]),
            torch.as_tensor(actions[known]),
            torch.as_tensor(target),
            normalize_advantages=True,
        )
        print(
            json.dumps(
                {
                    "bench": "critic_fit",
                    "checkpoint": args.checkpoint,
                    "env": env,
                    "gamma": gamma,
                    "states": int(known.sum()),
                    "return_mean": round(float(target.mean()), 3),
                    "value_mean": round(float(value.mean()), 3),
                    "explained_variance": round(
                        explained_variance(torch.as_tensor(value), torch.as_tensor(target)), 3
                    ),
                    "ridge_r2": [round(float(s), 3) for s in r2],
                    "grad_norms": {
                        part: {k: round(v, 5) for k, v in d.items() if k != "per_weight"}
                        for part, d in grads.items()
                    },
                }
            ),
            flush=True,
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
