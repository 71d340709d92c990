"""The A3C pieces in-process: returns, loss masking, shared RMSprop, acting, episode bookkeeping."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from neurosym.agent.config import ModelConfig, TrainConfig
from neurosym.agent.evaluation import play_episodes
from neurosym.agent.learners.a3c import a3c_loss, apply_update
from neurosym.agent.learners.exploration import CountBonus
from neurosym.agent.learners.optimizers import SharedRMSprop
from neurosym.agent.learners.returns import n_step_returns
from neurosym.agent.learners.sil import EpisodeMemory, SILBatch
from neurosym.agent.networks.model import ActorCritic
from neurosym.agent.rollout import EpisodeTracker, Rollout, select_actions


class Lookup(torch.nn.Module):
    """A stand-in model: observation (1, 1, 1) holding an id -> that id's logits and value."""

    def __init__(self, n: int = 10) -> None:
        super().__init__()
        self.logits = torch.nn.Parameter(torch.randn(n, 4))
        self.values = torch.nn.Parameter(torch.randn(n))

    def forward(self, obs: torch.Tensor):
        ids = obs.reshape(obs.shape[0], -1)[:, 0].long()
        return self.logits[ids], self.values[ids]


def rollout_of(ids, rewards, terminated, truncated, valid, last_ids, actions=None) -> Rollout:
    r = torch.tensor(rewards, dtype=torch.float32)
    T, K = r.shape
    return Rollout(
        obs=torch.tensor(ids, dtype=torch.uint8).view(T, K, 1, 1, 1),
        last_obs=torch.tensor(last_ids, dtype=torch.uint8).view(K, 1, 1, 1),
        actions=torch.zeros(T, K, dtype=torch.int64) if actions is None else actions,
        rewards=r,
        terminated=torch.tensor(terminated),
        truncated=torch.tensor(truncated),
        valid=torch.tensor(valid),
    )


def test_n_step_returns_terminal_truncation_and_bootstrap() -> None:
    g = 0.5
    # env 0: steps 0,1 then terminated at 1; step 2 is the autoreset (invalid); step 3 bootstraps
    # env 1: truncated at step 1 -> bootstraps from V(o_2) = 4; later steps bootstrap from the end
    G = n_step_returns(
        rewards=torch.tensor([[1.0, 2.0], [3.0, 1.0], [0.0, 0.0], [5.0, 1.0]]),
        terminated=torch.tensor([[False, False], [True, False], [False, False], [False, False]]),
        truncated=torch.tensor([[False, False], [False, True], [False, False], [False, False]]),
        next_values=torch.tensor([[9.0, 9.0], [9.0, 4.0], [9.0, 9.0], [8.0, 2.0]]),
        gamma=g,
    )
    assert G[3].tolist() == [5 + g * 8, 1 + g * 2]
    assert G[1].tolist() == [3.0, 1 + g * 4]
    assert G[0].tolist() == [1 + g * 3, 2 + g * (1 + g * 4)]


def test_loss_ignores_invalid_steps() -> None:
    torch.manual_seed(0)
    cfg = TrainConfig(entropy=0.1)
    # one env: step 0 terminates, step 1 is the autoreset (observation id 7), step 2 is a new episode
    ro = rollout_of(
        ids=[[1], [7], [2]],
        rewards=[[1.0], [0.0], [2.0]],
        terminated=[[True], [False], [False]],
        truncated=[[False], [False], [False]],
        valid=[[True], [False], [True]],
        last_ids=[3],
    )
    model = Lookup()
    loss_a, _ = a3c_loss(model, ro, cfg)
    with torch.no_grad():
        model.logits[7] = torch.tensor(
            [5.0, -3.0, 2.0, 0.0]
        )  # the autoreset step's outputs do not matter
        model.values[7] = 100.0
    loss_b, _ = a3c_loss(model, ro, cfg)
    assert torch.allclose(loss_a, loss_b)
    with torch.no_grad():
        model.values[3] = 50.0  # the bootstrap value does
    loss_c, _ = a3c_loss(model, ro, cfg)
    assert not torch.allclose(loss_a, loss_c)


def test_self_imitation_only_learns_from_better_than_expected() -> None:
    torch.manual_seed(0)
    cfg = TrainConfig.build(entropy=0.0, sil=1.0)
    ro = rollout_of(
        ids=[[1]],
        rewards=[[0.0]],
        terminated=[[True]],
        truncated=[[False]],
        valid=[[True]],
        last_ids=[1],
    )
    model = Lookup()
    with torch.no_grad():
        model.values[4], model.values[5] = 0.0, 9.0
    base, _ = a3c_loss(model, ro, cfg)
    worse = SILBatch(
        torch.tensor([5], dtype=torch.uint8).view(1, 1, 1, 1),
        torch.tensor([2]),
        torch.tensor([3.0]),
    )
    assert torch.allclose(
        a3c_loss(model, ro, cfg, worse)[0], base
    )  # R = 3 < V = 9: nothing to imitate
    better = SILBatch(
        torch.tensor([4], dtype=torch.uint8).view(1, 1, 1, 1),
        torch.tensor([2]),
        torch.tensor([3.0]),
    )
    loss, _ = a3c_loss(model, ro, cfg, better)
    model.zero_grad()
    loss.backward()
    assert model.logits.grad[4, 2] < 0 and model.values.grad[4] < 0  # raise pi(2|s4) and V(s4)


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
    obs = torch.randint(0, 2, (1, 2, 9, 10, 10), dtype=torch.uint8)
    before = torch.softmax(shared(obs[0])[0], -1)[:, 2]
    ro = Rollout(
        obs=obs,
        last_obs=obs[0],
        actions=torch.full((1, 2), 2),
        rewards=torch.ones(1, 2),
        terminated=torch.ones(1, 2, dtype=torch.bool),
        truncated=torch.zeros(1, 2, dtype=torch.bool),
        valid=torch.ones(1, 2, dtype=torch.bool),
    )
    for _ in range(5):
        local.load_state_dict(shared.state_dict())
        loss, stats = a3c_loss(local, ro, TrainConfig(entropy=0.0))
        norm = apply_update(local, shared, opt, loss, clip=400.0)
        assert norm > 0 and stats.value_loss > 0
    after = torch.softmax(shared(obs[0])[0], -1)[:, 2]
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


def test_count_bonus_counts_and_episodic_gate() -> None:
    a = np.zeros((1, 2, 3, 3), dtype=np.uint8)
    b = a.copy()
    b[0, 0, 1, 1] = 1
    bonus = CountBonus(0.5, episodic=False)
    yes, no = np.array([True]), np.array([False])
    np.testing.assert_allclose(bonus(a, yes), [0.5])
    np.testing.assert_allclose(bonus(a, yes), [0.5 / np.sqrt(2)])
    np.testing.assert_allclose(bonus(b, yes), [0.5])
    np.testing.assert_allclose(
        bonus(a, no), [0.0]
    )  # an autoreset step is not a transition: no bonus, no count
    np.testing.assert_allclose(bonus(a, yes), [0.5 / np.sqrt(3)])
    # episodic: a second visit within an episode pays nothing; a new episode (autoreset) starts afresh
    ep = CountBonus(0.5)
    np.testing.assert_allclose([ep(a, yes)[0], ep(b, yes)[0], ep(a, yes)[0]], [0.5, 0.5, 0.0])
    ep(b, no)
    np.testing.assert_allclose(ep(a, yes), [0.5 / np.sqrt(3)])
    # decayed counts: after two half-lives without visits a count of 4 is back to 1
    dec = CountBonus(1.0, episodic=False, half_life=1.0)
    for _ in range(3):
        dec(a, yes)
    # counts of a: 1, 1.5, 1.75 at steps 1-3; b at steps 4, 5; at step 6 a's count is 1.75 / 8 + 1
    assert dec(b, yes)[0] == 1.0 and dec(b, yes)[0] < 1.0
    np.testing.assert_allclose(dec(a, yes), [1 / np.sqrt(1.75 / 8 + 1)])


def test_episode_memory_keeps_best_positive_episodes() -> None:
    mem = EpisodeMemory(2, gamma=0.5, capacity=2)
    obs = np.arange(2, dtype=np.uint8).reshape(2, 1, 1, 1)
    yes = np.array([True, True])
    mem.step(
        obs, np.array([0, 1]), np.array([0.0, -1.0]), yes, np.array([False, True])
    )  # env 1: return -1
    mem.step(
        obs,
        np.array([2, 3]),
        np.array([4.0, 0.0]),
        np.array([True, False]),
        np.array([True, False]),
    )
    assert (
        len(mem.best) == 1 and len(mem) == 2
    )  # env 0: return 4 kept; env 1's negative episode not
    batch = mem.sample(50, torch.Generator().manual_seed(0))
    assert set(batch.returns.tolist()) == {2.0, 4.0}  # discounted returns-to-go 0 + 0.5 * 4 and 4
    for r in (1.0, 9.0):
        mem.step(
            obs,
            np.array([0, 0]),
            np.array([r, 0.0]),
            np.array([True, False]),
            np.array([True, False]),
        )
    assert sorted(e[0][0] for e in mem.best) == [4.0, 9.0]
    # equal returns: the shorter episode wins
    mem = EpisodeMemory(1, gamma=0.5, capacity=1)
    one, no, yes1 = obs[:1], np.array([False]), np.array([True])
    mem.step(one, np.array([0]), np.array([0.0]), yes1, no)
    mem.step(one, np.array([0]), np.array([2.0]), yes1, yes1)  # return 2 in 2 steps
    mem.step(one, np.array([1]), np.array([2.0]), yes1, yes1)  # return 2 in 1 step
    mem.step(one, np.array([0]), np.array([0.0]), yes1, no)
    mem.step(one, np.array([0]), np.array([2.0]), yes1, yes1)  # 2 steps again: not better
    assert len(mem) == 1 and mem.best[0][2].tolist() == [1]


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
    memory = EpisodeMemory(3, 0.99)
    ro, finished = collect_rollout(
        model, state, 5, torch.Generator().manual_seed(0), CountBonus(0.1), memory
    )
    assert (
        ro.obs.shape == (5, 3, 9, 10, 10)
        and ro.obs.dtype == torch.uint8
        and ro.last_obs.shape == (3, 9, 10, 10)
    )
    assert ro.actions.shape == ro.rewards.shape == ro.valid.shape == (5, 3)
    assert bool(ro.valid.all()) and len(finished) == 0
    assert float(ro.rewards.max()) > 0  # the exploration bonus is in the training rewards
    assert [len(c) for c in memory.current] == [5, 5, 5]
    loss, _ = a3c_loss(model, ro, TrainConfig())
    loss.backward()


def test_kept_graph_gives_the_recomputed_loss() -> None:
    from neurosym.agent.rollout import RolloutState, collect_rollout
    from neurosym.envs import make_batched

    torch.manual_seed(0)
    model = ActorCritic(ModelConfig.for_family("rgw", "mhdpa", (9, 10, 10)))
    state = RolloutState(make_batched("rgw2", 2, seed=0), seed=0)
    ro, _ = collect_rollout(model, state, 4, torch.Generator().manual_seed(0), keep_graph=True)
    assert ro.logits.shape == (4, 2, 4) and ro.logits.requires_grad and ro.values.shape == (4, 2)
    kept, _ = a3c_loss(model, ro, TrainConfig())
    recomputed, _ = a3c_loss(model, ro._replace(logits=None, values=None), TrainConfig())
    torch.testing.assert_close(kept, recomputed, rtol=1e-5, atol=1e-5)
    kept.backward()


def test_recorded_queries_give_the_recomputed_loss() -> None:
    """A PrediNet rollout carries acting's queries; the update's loss is the same without them."""
    from neurosym.agent.rollout import RolloutState, collect_rollout
    from neurosym.envs import make_batched

    torch.manual_seed(0)
    model = ActorCritic(ModelConfig.for_family("rgw", "predinet", (9, 10, 10)))
    state = RolloutState(make_batched("rgw2", 3, seed=0), seed=0)
    ro, _ = collect_rollout(model, state, 4, torch.Generator().manual_seed(0))
    assert ro.queries is not None and [q.shape for q in ro.queries.parts] == [(3, 256)] * 4
    reused, _ = a3c_loss(model, ro, TrainConfig())
    recomputed, _ = a3c_loss(model, ro._replace(queries=None), TrainConfig())
    torch.testing.assert_close(reused, recomputed, rtol=1e-5, atol=1e-6)
    reused.backward()


def test_optimal_set_nll_is_minus_log_of_the_sets_probability() -> None:
    from neurosym.agent.learners.planner_loss import optimal_set_nll

    logits = torch.tensor([[1.0, 2.0, 3.0, 4.0], [0.0, 0.0, 0.0, 0.0], [5.0, -1.0, 0.0, 2.0]])
    optimal = torch.tensor(
        [[False, True, False, True], [True, False, False, False], [False, False, False, False]]
    )
    p = torch.softmax(logits, -1)
    expected = [-torch.log(p[0, 1] + p[0, 3]).item(), -np.log(0.25), 0.0]  # empty set: 0
    torch.testing.assert_close(optimal_set_nll(logits, optimal), torch.tensor(expected).float())


def test_metrics_row_averages_each_loss_part_over_the_updates_that_measured_it() -> None:
    """A3C reports no PPO parts (blank), and one PPO update without an explained variance
    (its returns did not vary) does not blank the row's mean of the others."""
    from neurosym.agent.learners.messages import LossStats, Update
    from neurosym.agent.rollout import Finished
    from neurosym.agent.run.metrics import RunningStats as _Stats

    def update(*losses: float) -> Update:
        return Update(0, 8, Finished.empty(), LossStats(*losses))

    nan = float("nan")
    stats = _Stats(0, 0, window=10)
    stats.add(update(1.0, 2.0, 1.3, 0.5, 1e-3, 0.1, nan))
    stats.add(update(3.0, 4.0, 1.1, 0.7, 3e-3, 0.3, 0.6))
    row = stats.row(1.0, 8.0, None, None)
    assert (row["policy_loss"], row["entropy"], row["grad_norm"]) == ("2", "1.2", "0.6")
    assert (row["approx_kl"], row["clip_fraction"], row["explained_variance"]) == (
        "0.002",
        "0.2",
        "0.6",
    )
    stats.add(update(1.0, 2.0, 1.3, 0.5))  # an A3C worker's report
    row = stats.row(2.0, 8.0, None, None)
    assert row["policy_loss"] == "1" and row["approx_kl"] == row["explained_variance"] == ""
    assert stats.row(3.0, 8.0, None, None)["policy_loss"] == ""  # no update since the last row


def test_frame_rate_spans_updates_not_one_log_row() -> None:
    """A learner that reports 8,000 frames every 8 s runs at 1,000 frames/s, on every row.

    Logged every 2 s over the row's own interval, the rate read 4,000 on one
    row in four and 0 on the others (PPO's metrics.csv before the window)."""
    from neurosym.agent.run.metrics import FrameRate

    rate = FrameRate(0.0, 0, window=30.0)
    frames, rates = 0, []
    for tick in range(1, 61):  # 120 s of rows every 2 s, an update every 8 s
        now = 2.0 * tick
        if tick % 4 == 0:
            frames += 8000
        rates.append(rate.update(now, frames))
    assert rates[:3] == [0.0, 0.0, 0.0]  # nothing reported yet
    assert rates[3:] == pytest.approx([1000.0] * 57)
    assert len(rate.points) <= 6  # the window's reports, not the run's
    # a learner that stopped: after a window without a report the rate falls away
    for tick in range(61, 101):
        last = rate.update(2.0 * tick, frames)
    assert last < 250.0
