"""Can the network fit the planner at all? Offline imitation on a fixed labelled set; JSON lines.

Why: DAgger on rgw-random flattens at a loss of 0.40 (PrediNet) and 0.44
(MHDPA), i.e. the optimal actions hold only about two thirds of the policy's
probability, and the agents stop at 66 % / 82 % sampled success. This
separates the model from the learner: it labels a fixed set of states once
(the planner's optimal-action sets) and fits each model variant to it with
the imitation loss of ``neurosym train --algo imitate`` (Adam 5e-4, batches
of 512), then reports the loss and the greedy action's agreement with the
optimal set on the training states and on states of levels never trained on.
A variant that cannot bring its *training* loss down is short of capacity or
of what it sees, whatever the learner does.

States come from episodes in which each step follows the planner with
probability ``--follow`` (one of its optimal actions, uniformly) and is
otherwise a uniformly random action, so that they cover the planner's routes
and the detours a learner makes.

    python experiments/imitation_capacity.py                          # the table in docs/results.md
    python experiments/imitation_capacity.py --variants predinet:heads=8 mhdpa cnn

``cnn`` is a plain CNN reference (not a relational module).
"""

from __future__ import annotations

import argparse
import json
import time
from typing import Any

import numpy as np
import torch

from neurosym.agent.config import ModelConfig
from neurosym.agent.learners.augment import augment_batch
from neurosym.agent.learners.imitation import imitation_loss, planner_choice
from neurosym.agent.networks.model import ActorCritic
from neurosym.envs import make_batched
from neurosym.envs.rgw_solver import Planner

VARIANTS = [  # the table in docs/results.md (about 35 minutes on 2 cores)
    "predinet",
    "predinet:heads=8",
    "predinet:output_size=64",
    "predinet:kernel_size=3",
    "predinet:conv_channels=32-64",
    "predinet:conv_channels=16-16-16-16-16-24,kernel_size=3",
    "cnn",
]


def labelled_states(env: str, n: int, seed: int, follow: float) -> tuple[np.ndarray, np.ndarray]:
    """n observations and their (n, 4) optimal-action sets."""
    venv = make_batched(env, 64, seed=seed)
    obs, _ = venv.reset(seed=seed)
    planner, rng = Planner(), np.random.default_rng(seed)
    all_obs, all_sets, count = [], [], 0
    pending = np.zeros(venv.num_envs, dtype=bool)
    while count < n:
        optimal, _ = planner.action_sets(venv)
        keep = ~pending  # an autoreset step shows the last episode's end
        all_obs.append(obs[keep].copy())
        all_sets.append(optimal[keep])
        count += int(keep.sum())
        expert = planner_choice(optimal, rng)
        actions = np.where(
            rng.random(len(expert)) < follow, expert, rng.integers(0, 4, len(expert))
        )
        obs, _, terminated, truncated, _ = venv.step(actions)
        pending = terminated | truncated
    return np.concatenate(all_obs)[:n], np.concatenate(all_sets)[:n]


def parse_variant(text: str) -> tuple[str, dict[str, Any]]:
    module, _, rest = text.partition(":")
    overrides: dict[str, Any] = {"entity_norm": True, "attention_gain": 8.0, "init": "orthogonal"}
    for item in filter(None, rest.split(",")):
        key, _, value = item.partition("=")
        default = getattr(ModelConfig, key, 0)
        if isinstance(default, tuple):  # conv_channels=32-64
            overrides[key] = tuple(int(v) for v in value.split("-"))
        else:
            overrides[key] = type(default)(value)
    return module, overrides


class PlainCNN(torch.nn.Module):
    """Reference, not a neurosym model: two 3x3 convolutions, a flatten and an MLP (global view)."""

    def __init__(self, obs_shape: tuple[int, int, int]) -> None:
        super().__init__()
        c, h, w = obs_shape
        self.net = torch.nn.Sequential(
            torch.nn.Conv2d(c, 32, 3, padding=1), torch.nn.ReLU(),
            torch.nn.Conv2d(32, 64, 3, padding=1), torch.nn.ReLU(),
            torch.nn.Flatten(), torch.nn.Linear(64 * h * w, 256), torch.nn.ReLU(),
            torch.nn.Linear(256, 4),
        )  # fmt: skip

    def forward(self, obs: torch.Tensor) -> tuple[torch.Tensor, None]:
        return self.net(obs.float()), None

    def parameter_count(self) -> int:
        return sum(p.numel() for p in self.parameters())


@torch.no_grad()
def measure(model: Any, obs: np.ndarray, sets: np.ndarray) -> tuple[float, float]:
    """(imitation loss, share of states whose greedy action is optimal)."""
    losses, hits = [], []
    for start in range(0, len(obs), 2048):
        o = torch.from_numpy(obs[start : start + 2048])
        m = torch.from_numpy(sets[start : start + 2048])
        logits, _ = model(o)
        losses.append(imitation_loss(logits, m).item() * len(o))
        hits.append(m[torch.arange(len(o)), logits.argmax(-1)].float().sum().item())
    return sum(losses) / len(obs), sum(hits) / len(obs)


def fit(
    variant: str,
    data: dict[str, tuple[np.ndarray, np.ndarray]],
    steps: int,
    batch: int,
    seed: int,
    augment: bool = False,
) -> dict[str, Any]:
    module, overrides = parse_variant(variant)
    train_obs, train_sets = data["train"]
    torch.manual_seed(seed)
    if module == "cnn":
        model: Any = PlainCNN(train_obs.shape[1:])
    else:
        model = ActorCritic(ModelConfig.for_family("rgw", module, train_obs.shape[1:], **overrides))
    optimizer = torch.optim.Adam(model.parameters(), lr=5e-4)
    rng = np.random.default_rng(seed)
    generator = torch.Generator().manual_seed(seed)
    curve, t0 = [], time.perf_counter()
    for step in range(1, steps + 1):
        idx = rng.integers(0, len(train_obs), batch)
        obs, sets = torch.from_numpy(train_obs[idx]), torch.from_numpy(train_sets[idx])
        if augment:
            obs, sets = augment_batch(obs, sets, generator)
        logits, _ = model(obs)
        loss = imitation_loss(logits, sets)
        optimizer.zero_grad(set_to_none=True)
        loss.backward()
        torch.nn.utils.clip_grad_norm_(model.parameters(), 0.5)
        optimizer.step()
        if step % max(1, steps // 5) == 0 or step == steps:
            test_loss, test_hit = measure(model, *data["test"])
            curve.append(
                {
                    "step": step,
                    "batch_loss": round(loss.item(), 4),
                    "test_loss": round(test_loss, 4),
                    "test_optimal": round(test_hit, 4),
                }
            )
    seconds = time.perf_counter() - t0
    train_loss, train_hit = measure(model, train_obs[:20000], train_sets[:20000])
    test_loss, test_hit = measure(model, *data["test"])
    return {
        "variant": variant,
        "augment": augment,
        "parameters": model.parameter_count(),
        "steps": steps,
        "seconds": round(seconds, 1),
        "train_loss": round(train_loss, 4),
        "train_optimal": round(train_hit, 4),
        "test_loss": round(test_loss, 4),
        "test_optimal": round(test_hit, 4),
        "curve": curve,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--env", default="rgw-random")
    parser.add_argument(
        "--variants",
        nargs="+",
        default=VARIANTS,
        help="module[:key=value,...] with ModelConfig fields, e.g. predinet:heads=8",
    )
    parser.add_argument("--train-states", type=int, default=200_000)
    parser.add_argument("--test-states", type=int, default=20_000)
    parser.add_argument("--steps", type=int, default=2000, help="Adam steps per variant")
    parser.add_argument("--batch", type=int, default=512)
    parser.add_argument("--follow", type=float, default=0.5)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--augment",
        action="store_true",
        help="train on a random rotation or mirror of each batch (neurosym/agent/augment.py)",
    )
    args = parser.parse_args()
    torch.set_num_threads(2)
    t0 = time.perf_counter()
    data = {
        "train": labelled_states(args.env, args.train_states, args.seed, args.follow),
        "test": labelled_states(args.env, args.test_states, 3_000_000_000, args.follow),
    }
    sets = data["train"][1]
    print(
        json.dumps(
            {
                "env": args.env,
                "train_states": len(sets),
                "test_states": len(data["test"][1]),
                "label_seconds": round(time.perf_counter() - t0, 1),
                "mean_optimal_actions": round(float(sets.sum(1).mean()), 3),
                "uniform_loss": round(float(-np.log(sets.sum(1) / 4).mean()), 4),
            }
        ),
        flush=True,
    )
    for variant in args.variants:
        print(
            json.dumps(fit(variant, data, args.steps, args.batch, args.seed, args.augment)),
            flush=True,
        )


if __name__ == "__main__":
    main()
