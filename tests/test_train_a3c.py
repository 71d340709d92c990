"""The A3C pieces in-process: returns, loss masking, shared RMSprop, acting, episode bookkeeping."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from neurosym.agent.a3c import SharedRMSprop, a3c_loss, apply_update, n_step_returns
from neurosym.agent.config import ModelConfig, TrainConfig
from neurosym.agent.exploration import CountBonus
from neurosym.agent.model import ActorCritic
from neurosym.agent.rollout import EpisodeTracker, Rollout, play_episodes, select_actions


def rollout_of(
    rewards, terminated, truncated, valid, next_values, values=None, logits=None, actions=None
) -> Rollout:
    r = torch.tensor(rewards, dtype=torch.float32)
    T, K = r.shape
    return Rollout(
        logits=torch.zeros(T, K, 4, requires_grad=True) if logits is None else logits,
        values=torch.zeros(T, K, requires_grad=True) if values is None else values,
        actions=torch.zeros(T, K, dtype=torch.int64) if actions is None else actions,
        rewards=r,
        terminated=torch.tensor(terminated),
        truncated=torch.tensor(truncated),
        valid=torch.tensor(valid),
        next_values=torch.tensor(next_values, dtype=torch.float32),
    )


def test_n_step_returns_terminal_truncation_and_bootstrap() -> None:
    g = 0.5
    # env 0: steps 0,1 then terminated at 1; step 2 is the autoreset (invalid); step 3 bootstraps
    # env 1: truncated at step 1 -> bootstraps from V(o_2) = 4; later steps bootstrap from the end
    ro = rollout_of(
        rewards=[[1.0, 2.0], [3.0, 1.0], [0.0, 0.0], [5.0, 1.0]],
        terminated=[[False, False], [True, False], [False, False], [False, False]],
        truncated=[[False, False], [False, True], [False, False], [False, False]],
        valid=[[True, True], [True, True], [False, False], [True, True]],
        next_values=[[9.0, 9.0], [9.0, 4.0], [9.0, 9.0], [8.0, 2.0]],
    )
    G = n_step_returns(ro, g)
    assert G[3].tolist() == [5 + g * 8, 1 + g * 2]
    assert G[1].tolist() == [3.0, 1 + g * 4]
    assert G[0].tolist() == [1 + g * 3, 2 + g * (1 + g * 4)]


def test_loss_ignores_invalid_steps() -> None:
    cfg = TrainConfig(entropy=0.1)
    kw = dict(
        rewards=[[1.0], [0.0], [2.0]],
        terminated=[[True], [False], [False]],
        truncated=[[False], [False], [False]],
        valid=[[True], [False], [True]],
        next_values=[[0.0], [0.0], [1.0]],
    )
    logits = torch.randn(3, 1, 4)
    loss_a, _ = a3c_loss(rollout_of(**kw, logits=logits.clone().requires_grad_()), cfg)
    logits[1] = torch.tensor([5.0, -3.0, 2.0, 0.0])  # the autoreset step's outputs do not matter
    loss_b, _ = a3c_loss(rollout_of(**kw, logits=logits.clone().requires_grad_()), cfg)
    assert torch.allclose(loss_a, loss_b)


def test_shared_rmsprop_matches_torch_rmsprop_and_shares_state() -> None:
    torch.manual_seed(0)
    a, b = torch.nn.Linear(3, 2), torch.nn.Linear(3, 2)
    b.load_state_dict(a.state_dict())
    shared = SharedRMSprop(a.parameters(), lr=0.01, alpha=0.99, eps=0.1).share_memory()
    assert all(v.is_shared() for s in shared.state.values() for v in s.values())
    plain = torch.optim.RMSprop(b.parameters(), lr=0.01, alpha=0.99, eps=0.1)
    for step in range(3):
        x = torch.randn(5, 3) * (step + 1)
        for model, opt in ((a, shared), (b, plain)):
            opt.zero_grad()
            model(x).pow(2).sum().backward()
            opt.step()
    for p, q in zip(a.parameters(), b.parameters(), strict=True):
        torch.testing.assert_close(p, q)
    restored = SharedRMSprop(torch.nn.Linear(3, 2).parameters(), lr=0.5, alpha=0.9, eps=1.0)
    restored.load_state_dict(shared.state_dict())
    restored.set_hyperparameters(lr=0.02, alpha=0.99, eps=0.1)
    assert restored.param_groups[0]["lr"] == 0.02
    assert torch.equal(
        restored.state_dict()["state"][0]["square_avg"],
        shared.state_dict()["state"][0]["square_avg"],
    )


def test_update_moves_policy_towards_advantaged_action() -> None:
    torch.manual_seed(0)
    config = ModelConfig.for_family("rgw", "predinet", (9, 10, 10))
    shared, local = ActorCritic(config), ActorCritic(config)
    shared.share_memory()
    opt = SharedRMSprop(shared.parameters(), lr=1e-3, alpha=0.99, eps=1e-5)
    obs = torch.randint(0, 2, (2, 9, 10, 10), dtype=torch.uint8)
    before = torch.softmax(shared(obs)[0], -1)[:, 2]
    for _ in range(5):
        local.load_state_dict(shared.state_dict())
        logits, values = local(obs)
        ro = rollout_of(
            rewards=[[1.0, 1.0]],
            terminated=[[True, True]],
            truncated=[[False, False]],
            valid=[[True, True]],
            next_values=[[0.0, 0.0]],
            logits=logits.unsqueeze(0),
            values=values.unsqueeze(0),
            actions=torch.full((1, 2), 2),
        )
        loss, stats = a3c_loss(ro, TrainConfig(entropy=0.0))
        norm = apply_update(local, shared, opt, loss, clip=400.0)
        assert norm > 0 and stats.value_loss > 0
    after = torch.softmax(shared(obs)[0], -1)[:, 2]
    assert bool((after > before + 0.01).all()), (before, after)


def test_select_actions() -> None:
    logits = torch.tensor([[0.0, 3.0, 1.0, -1.0], [2.0, 0.0, 0.0, 0.0]])
    assert select_actions(logits, greedy=True).tolist() == [1, 0]
    probs = torch.softmax(logits, -1)
    draws = torch.stack(
        [
            select_actions(logits, greedy=False, generator=torch.Generator().manual_seed(s))
            for s in range(4000)
        ]
    )
    freq = torch.stack([(draws == a).float().mean(0) for a in range(4)], dim=1)
    torch.testing.assert_close(freq, probs, atol=0.03, rtol=0)
    g1, g2 = torch.Generator().manual_seed(7), torch.Generator().manual_seed(7)
    assert torch.equal(select_actions(logits, False, g1), select_actions(logits, False, g2))


def test_episode_tracker_skips_autoreset_steps() -> None:
    tracker = EpisodeTracker(2)
    no = np.zeros(2, dtype=bool)
    valid, done = tracker.step(None, np.array([1.0, 2.0]), np.array([False, True]), no, {})
    assert valid.tolist() == [True, True] and done.returns == [2.0] and done.lengths == [1]
    assert done.outcomes == ["terminal"]  # no decode_info: terminated means terminal
    valid, done = tracker.step(None, np.array([3.0, 0.0]), no, np.array([True, False]), {})
    assert valid.tolist() == [True, False] and done.returns == [4.0] and done.lengths == [2]
    assert done.outcomes == ["timeout"]
    valid, done = tracker.step(None, np.array([0.0, 5.0]), no, no, {})
    assert valid.tolist() == [False, True] and len(done) == 0
    assert tracker.ret.tolist() == [0.0, 5.0]


def test_count_bonus() -> None:
    bonus = CountBonus(0.5)
    obs = np.zeros((3, 2, 3, 3), dtype=np.uint8)
    obs[1, 0, 1, 1] = 1
    got = bonus(obs, np.array([True, True, False]))
    # rows 0 and 2 are the same observation, but row 2 is not a transition: not counted, no bonus
    np.testing.assert_allclose(got, [0.5, 0.5, 0.0])
    got = bonus(obs, np.array([True, True, True]))
    np.testing.assert_allclose(got, [0.5 / np.sqrt(3), 0.5 / np.sqrt(2), 0.5 / np.sqrt(3)])


def test_play_episodes_on_rgw() -> None:
    from neurosym.envs import make_batched

    # always "up" from the start corner: every episode times out at the env's 100 steps with return 0
    done = play_episodes(
        lambda obs: np.zeros(len(obs), dtype=np.int64),
        lambda n: make_batched("rgw2", n),
        5,
        0,
        batch=3,
    )
    assert (
        done.returns == [0.0] * 5 and done.lengths == [100] * 5 and done.outcomes == ["timeout"] * 5
    )


@pytest.mark.parametrize("module", ["predinet", "mhdpa"])
def test_collect_rollout_shapes(module: str) -> None:
    from neurosym.agent.rollout import RolloutState, collect_rollout
    from neurosym.envs import make_batched

    torch.manual_seed(0)
    model = ActorCritic(ModelConfig.for_family("rgw", module, (9, 10, 10)))
    state = RolloutState(make_batched("rgw2", 3, seed=0), seed=0)
    ro, finished = collect_rollout(
        model, state, 5, torch.Generator().manual_seed(0), CountBonus(0.1)
    )
    assert (
        ro.logits.shape == (5, 3, 4)
        and ro.values.shape == (5, 3)
        and ro.next_values.shape == (5, 3)
    )
    assert ro.logits.requires_grad and not ro.next_values.requires_grad
    assert bool(ro.valid.all()) and len(finished) == 0
    assert float(ro.rewards.max()) > 0  # the exploration bonus is in the training rewards
    loss, _ = a3c_loss(ro, TrainConfig())
    loss.backward()
