"""Where an RGW agent's policy puts probability on actions that lose return.

The DAgger loss (``-log sum_{a optimal} p(a)``) asks for the fastest route's
actions everywhere, and most of its weight falls on states where a slower
move loses nothing (RGW has no step cost). An episode misses its optimum only
on the few states where some action gives return up for good: a mountain a
free route avoids, the enemy met unarmed, the decoy's +1 walked past. This
plays the agent's sampled policy on procedural levels and splits the visited
states by the planner's per-action regret (:meth:`rgw_solver.Plan.regret`)::

    python experiments/regret_profile.py checkpoints/rgw-random-mhdpa.pt --episodes 300

Prints one JSON line per checkpoint: the share of ``critical`` states (some
action loses return), the mean NLL on critical and on other states, the
policy's mass on losing actions at critical states (mean, and the share of
critical states where it exceeds 0.05), the share where the argmax loses, and
the expected return lost per episode (sum over steps of ``sum_a p(a) regret(a)``).
The default seed (2e9) keeps the held-out levels of ``neurosym eval`` (3e9) out.
"""

from __future__ import annotations

import argparse
import json

import numpy as np


def profile(path: str, env: str, episodes: int, seed: int) -> dict[str, object]:
    """The figures above for one checkpoint, over ``episodes`` sampled episodes from ``seed``."""
    import torch

    from neurosym.agent.agent import load_agent
    from neurosym.agent.learners.planner_loss import optimal_set_nll
    from neurosym.envs import make_batched
    from neurosym.envs.rgw_solver import Planner

    torch.set_num_threads(1)
    agent = load_agent(path)
    venv = make_batched(env, episodes, seed=seed)
    obs, _ = venv.reset(seed=[seed + i for i in range(episodes)])
    planner = Planner()
    generator = torch.Generator().manual_seed(seed)
    live = np.ones(episodes, dtype=bool)
    nll, lost_mass, argmax_loses, critical, expected = [], [], [], [], np.zeros(episodes)
    for _ in range(venv.unwrapped.rules.max_steps or 100):
        optimal, _values, regret = planner.labels(venv)
        with torch.no_grad():
            logits, _ = agent.model(torch.as_tensor(obs))
        p = torch.softmax(logits, -1).numpy()
        crit = regret.max(1) > 0
        nll.append(optimal_set_nll(logits, torch.as_tensor(optimal)).numpy()[live])
        critical.append(crit[live])
        lost_mass.append((p * (regret > 0)).sum(1)[live & crit])
        argmax_loses.append((regret[np.arange(episodes), p.argmax(1)] > 0)[live & crit])
        expected += np.where(live, (p * regret).sum(1), 0.0)
        actions = torch.multinomial(torch.as_tensor(p), 1, generator=generator).squeeze(1)
        obs, _r, terminated, truncated, _info = venv.step(actions.numpy())
        live &= ~(terminated | truncated)
        if not live.any():
            break
    nll_all, crit_all = np.concatenate(nll), np.concatenate(critical)
    mass = np.concatenate(lost_mass)
    return {
        "bench": "regret_profile",
        "checkpoint": path,
        "env": env,
        "episodes": episodes,
        "states": int(len(crit_all)),
        "critical_share": round(float(crit_all.mean()), 3),
        "nll_critical": round(float(nll_all[crit_all].mean()), 4),
        "nll_other": round(float(nll_all[~crit_all].mean()), 4),
        "lost_mass_critical": round(float(mass.mean()), 4),
        "lost_mass_over_5pct": round(float((mass > 0.05).mean()), 4),
        "argmax_loses_critical": round(float(np.concatenate(argmax_loses).mean()), 4),
        "expected_loss_per_episode": round(float(expected.mean()), 4),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("checkpoints", nargs="+", help="checkpoint files of RGW agents")
    parser.add_argument("--env", default="rgw-random", help="an RGW env (rgw-random)")
    parser.add_argument("--episodes", type=int, default=300, help="levels, one episode each (300)")
    parser.add_argument("--seed", type=int, default=2_000_000_000, help="first reset seed (2e9)")
    args = parser.parse_args(argv)
    for path in args.checkpoints:
        print(json.dumps(profile(path, args.env, args.episodes, args.seed)), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
