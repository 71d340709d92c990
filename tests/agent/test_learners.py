"""The learners' shared pieces: presets, GAE, advantage normalisation, shared Adam, the PPO update."""

from __future__ import annotations

import math

import pytest
import torch

from neurosym.agent.config import ModelConfig, PPOConfig, TrainConfig, preset_env_kwargs
from neurosym.agent.learners.a3c import a3c_loss
from neurosym.agent.learners.optimizers import SharedAdam, SharedRMSprop, shared_optimizer
from neurosym.agent.learners.ppo import ppo_update
from neurosym.agent.learners.returns import (
    AdvantageScale,
    explained_variance,
    gae_advantages,
    n_step_returns,
)
from neurosym.agent.rollout import Rollout
from neurosym.errors import ConfigError


def test_thesis_preset_is_table_4() -> None:
    bw = TrainConfig.for_family("boxworld", preset="thesis")
    assert (bw.optimizer, bw.lr, bw.rms_eps, bw.rms_alpha, bw.grad_clip) == (
        "rmsprop",
        2e-4,
        0.1,
        0.99,
        400.0,
    )
    assert (bw.entropy, bw.n_steps, bw.envs, bw.explore, bw.a3c.sil) == (0.01, 40, 1, 0.0, 0.0)
    assert (bw.reward_scale, bw.normalize_advantages, bw.gae_lambda) == (1.0, False, 1.0)
    rgw = TrainConfig.for_family("rgw", preset="thesis")
    assert (rgw.lr, rgw.entropy) == (2e-3, 0.02)
    model = ModelConfig.for_family("boxworld", "predinet", (3, 14, 14), 1 / 255, preset="thesis")
    assert (model.entity_norm, model.attention_gain, model.key_size) == (False, 1.0, 64)
    assert preset_env_kwargs("boxworld", "thesis") == {"obs_mode": "rgb"}
    assert preset_env_kwargs("boxworld") == {"obs_mode": "onehot"}
    assert preset_env_kwargs("rgw") == {}


def test_default_preset_departures_and_algo() -> None:
    bw = TrainConfig.for_family("boxworld")
    assert (bw.optimizer, bw.normalize_advantages, bw.reward_scale, bw.a3c.sil) == (
        "adam",
        True,
        0.1,
        1.0,
    )
    ppo = TrainConfig.for_family("boxworld", algo="ppo")
    assert (ppo.algo, ppo.learner, ppo.explore) == ("ppo", PPOConfig(), 0.0)
    with pytest.raises(ConfigError, match="this run's learner is ppo, which has no A3CConfig"):
        ppo.a3c  # noqa: B018 - the property raises
    assert TrainConfig.for_family("rgw", lr=5e-4).lr == 5e-4
    with pytest.raises(ConfigError, match="unknown preset 'fast'"):
        TrainConfig.for_family("rgw", preset="fast")
    with pytest.raises(ConfigError, match="no --algo ppo settings"):
        TrainConfig.for_family("rgw", preset="thesis", algo="ppo")
    with pytest.raises(ConfigError, match="unknown optimizer 'sgd'"):
        TrainConfig(optimizer="sgd")
    with pytest.raises(ConfigError, match="gae_lambda"):
        TrainConfig(gae_lambda=1.5)


def test_box_world_predinets_default_to_learned_queries() -> None:
    """The default preset's Box-World PrediNet learns with learned queries; the others keep
    scene queries, and a checkpoint's recorded (or missing: scene) query is what loads."""
    bw = ModelConfig.for_family("boxworld", "predinet", (26, 14, 14))
    assert bw.query == "learned"
    assert ModelConfig.for_family("boxworld", "mhdpa", (26, 14, 14)).query == "scene"
    assert ModelConfig.for_family("rgw", "predinet", (9, 10, 10)).query == "scene"
    thesis = ModelConfig.for_family("boxworld", "predinet", (3, 14, 14), preset="thesis")
    assert thesis.query == "scene"
    assert ModelConfig.for_family("boxworld", "predinet", (26, 14, 14), query="scene").query == (
        "scene"
    )
    recorded = bw.to_dict()
    del recorded["query"]  # the shipped bw agents predate the setting
    assert ModelConfig.from_dict(recorded).query == "scene"


def test_configs_without_the_new_keys_load_as_the_code_was() -> None:
    """A checkpoint's config predating a setting gets the value the code had then."""
    model = ModelConfig.for_family("rgw", "predinet", (9, 10, 10)).to_dict()
    del model["entity_norm"], model["attention_gain"]
    old = ModelConfig.from_dict(model)
    assert (old.entity_norm, old.attention_gain) == (False, 1.0)
    train = TrainConfig.for_family("rgw").to_dict()
    for key in (
        "algo",
        "optimizer",
        "reward_scale",
        "normalize_advantages",
        "gae_lambda",
        "preset",
    ):
        del train[key]
    old_train = TrainConfig.from_dict(train)
    assert (old_train.optimizer, old_train.normalize_advantages, old_train.gae_lambda) == (
        "rmsprop",
        False,
        1.0,
    )
    assert old_train.preset == "legacy" and old_train.algo == "a3c"


def test_gae_with_lambda_one_is_the_n_step_advantage() -> None:
    torch.manual_seed(0)
    T, K = 6, 3
    rewards = torch.randn(T, K)
    values = torch.randn(T, K)
    terminated = torch.zeros(T, K, dtype=torch.bool)
    truncated = torch.zeros(T, K, dtype=torch.bool)
    terminated[2, 0] = True
    truncated[3, 1] = True
    next_values = torch.cat([values[1:], torch.randn(1, K)])
    next_values[3, 1] = 7.0  # V of the truncated episode's final observation
    gae = gae_advantages(rewards, values, terminated, truncated, next_values, 0.9, 1.0)
    returns = n_step_returns(rewards, terminated, truncated, next_values, 0.9)
    torch.testing.assert_close(gae, returns - values)
    one_step = gae_advantages(rewards, values, terminated, truncated, next_values, 0.9, 0.0)
    expected = rewards + 0.9 * torch.where(terminated, 0.0, next_values) - values
    torch.testing.assert_close(one_step, expected)


def test_advantage_scale_keeps_signs_and_uses_a_running_rms() -> None:
    scale = AdvantageScale(decay=0.5)
    mask = torch.tensor([[1.0, 1.0], [0.0, 1.0]])
    first = scale(torch.tensor([[-1.0, -3.0], [100.0, -5.0]]), mask)  # invalid 100 ignored
    rms = ((1 + 9 + 25) / 3) ** 0.5
    torch.testing.assert_close(first[mask.bool()], torch.tensor([-1.0, -3.0, -5.0]) / rms)
    assert (first[mask.bool()] < 0).all()  # no centring: an all-negative rollout stays negative
    # a quiet rollout after a loud one is not blown up to unit size
    quiet = scale(torch.full((2, 2), 0.01), torch.ones(2, 2))
    expected_ms = 0.5 * (35 / 3) + 0.5 * 0.0001
    torch.testing.assert_close(quiet, torch.full((2, 2), 0.01 / expected_ms**0.5))


def test_shared_adam_matches_torch_adam_and_shares_state() -> None:
    torch.manual_seed(0)
    a, b = torch.nn.Linear(3, 2), torch.nn.Linear(3, 2)
    b.load_state_dict(a.state_dict())
    shared = SharedAdam(a.parameters(), lr=0.01, eps=1e-5).share_memory()
    assert all(v.is_shared() for s in shared.state.values() for v in s.values())
    plain = torch.optim.Adam(b.parameters(), lr=0.01, eps=1e-5)
    for step in range(3):
        x = torch.randn(5, 3) * (step + 1)
        for model, opt in ((a, shared), (b, plain)):
            opt.zero_grad()
            model(x).pow(2).sum().backward()
            opt.step()
    for p, q in zip(a.parameters(), b.parameters(), strict=True):
        torch.testing.assert_close(p, q)
    assert isinstance(shared_optimizer(b.parameters(), TrainConfig(optimizer="adam")), SharedAdam)
    assert isinstance(
        shared_optimizer(b.parameters(), TrainConfig(optimizer="rmsprop")), SharedRMSprop
    )


class Lookup(torch.nn.Module):
    """Observation id -> that id's logits and value (a model whose every output is a parameter)."""

    def __init__(self, n: int = 10) -> None:
        super().__init__()
        self.logits = torch.nn.Parameter(torch.zeros(n, 4))
        self.values = torch.nn.Parameter(torch.zeros(n))

    def forward(self, obs: torch.Tensor):
        ids = obs.reshape(obs.shape[0], -1)[:, 0].long()
        return self.logits[ids], self.values[ids]


def _bandit_rollout(model: Lookup, T: int = 8, K: int = 4) -> Rollout:
    """Every step observation 1, actions cycling 0..3; action 2 pays 1, the others 0."""
    actions = torch.arange(T * K).view(T, K) % 4
    obs = torch.ones(T, K, 1, 1, 1, dtype=torch.uint8)
    with torch.no_grad():
        logits, values = model(obs.flatten(0, 1))
    return Rollout(
        obs=obs,
        last_obs=obs[0],
        actions=actions,
        rewards=(actions == 2).float(),
        terminated=torch.ones(T, K, dtype=torch.bool),
        truncated=torch.zeros(T, K, dtype=torch.bool),
        valid=torch.ones(T, K, dtype=torch.bool),
        logits=logits.view(T, K, 4),
        values=values.view(T, K),
    )


def _ppo_prob_of_paying_action(clip_range: float) -> tuple[float, int]:
    model = Lookup()
    config = TrainConfig.build(
        algo="ppo", lr=0.05, entropy=0.0, ppo_epochs=10, ppo_minibatches=2, clip_range=clip_range
    )
    opt = torch.optim.SGD(model.parameters(), lr=config.lr)
    stats = ppo_update(model, opt, _bandit_rollout(model), config, torch.Generator().manual_seed(0))
    assert stats.value_loss > 0 and stats.grad_norm > 0
    probs = torch.softmax(model.logits[1], -1)
    return float(probs[2].detach()), int(probs.argmax())


def test_ppo_update_prefers_the_paying_action_within_the_clip() -> None:
    tight, best = _ppo_prob_of_paying_action(0.05)
    loose, best_loose = _ppo_prob_of_paying_action(100.0)
    assert best == best_loose == 2
    # the clipped surrogate stops pushing once a sample's ratio leaves [0.95, 1.05]
    # (the other actions' ratios fall too, so pi(2) may end a little above 0.25 * 1.05)
    assert 0.25 < tight < 0.3 < loose


def test_ppo_update_reports_how_far_the_policy_moved() -> None:
    def stats_for(clip_range: float, epochs: int):
        model = Lookup()
        config = TrainConfig.build(
            algo="ppo", lr=0.05, entropy=0.0, ppo_epochs=epochs, ppo_minibatches=2,
            clip_range=clip_range,
        )  # fmt: skip
        opt = torch.optim.SGD(model.parameters(), lr=config.lr)
        rollout = _bandit_rollout(model)
        return ppo_update(model, opt, rollout, config, torch.Generator().manual_seed(0))

    one = stats_for(0.05, 1)
    many = stats_for(0.05, 10)
    loose = stats_for(100.0, 10)
    # the first minibatch step starts at the acting policy (ratio 1, KL 0); later ones have moved
    assert 0.0 <= one.approx_kl < many.approx_kl
    assert 0.0 < many.clip_fraction <= 1.0
    assert loose.clip_fraction == 0.0 and loose.approx_kl > many.approx_kl
    # the acting critic's values against the rollout's returns: a number at most 1
    assert one.explained_variance <= 1.0


def test_ppo_running_advantages_keep_a_rewardless_rollout_small() -> None:
    """Per minibatch, a rollout whose advantages are all tiny moves the policy as far as one
    with real rewards; divided by the running RMS of the rollouts before it, it barely does."""

    def paying_prob_after(mode: str, scale: AdvantageScale | None, reward: float) -> float:
        model = Lookup()
        config = TrainConfig.build(
            algo="ppo", lr=0.05, entropy=0.0, ppo_epochs=4, ppo_minibatches=2,
            ppo_advantages=mode,
        )  # fmt: skip
        rollout = _bandit_rollout(model)
        rollout = rollout._replace(rewards=rollout.rewards * reward)
        opt = torch.optim.SGD(model.parameters(), lr=config.lr)
        ppo_update(model, opt, rollout, config, torch.Generator().manual_seed(0), scale)
        return float(torch.softmax(model.logits[1].detach(), -1)[2])

    rewarded = paying_prob_after("minibatch", None, 1.0)
    tiny_minibatch = paying_prob_after("minibatch", None, 1e-3)
    scale = AdvantageScale()
    rewarded_running = paying_prob_after("running", scale, 1.0)  # primes the running RMS
    tiny_running = paying_prob_after("running", scale, 1e-3)
    assert rewarded > 0.27 and rewarded_running > 0.27  # up to the clip (0.25 * 1.2)
    # scaled back up to (nearly) the same step; the gradient clip, which sees the value
    # head's larger gradient under real rewards, makes the difference
    assert abs(tiny_minibatch - rewarded) < 0.05 * (rewarded - 0.25)
    assert 0.25 < tiny_running < 0.25 + 0.01 * (rewarded - 0.25)  # the sign kept, the size too


def test_explained_variance_reads_a_perfect_a_useless_and_a_constant_critic() -> None:
    target = torch.tensor([0.0, 1.0, 2.0, 3.0])
    assert explained_variance(target, target) == 1.0
    assert explained_variance(torch.full((4,), 1.5), target) == 0.0
    assert explained_variance(-target, target) < 0.0  # worse than the mean
    assert math.isnan(explained_variance(target, torch.ones(4)))


def test_a3c_loss_with_normalised_advantages_pushes_both_ways() -> None:
    model = Lookup()
    ro = _bandit_rollout(model)._replace(logits=None, values=None)
    loss, _ = a3c_loss(model, ro, TrainConfig(entropy=0.0))
    loss.backward()
    # descent raises pi(2 | obs 1) and lowers the others
    assert model.logits.grad[1, 2] < 0 and (model.logits.grad[1, [0, 1, 3]] > 0).all()
