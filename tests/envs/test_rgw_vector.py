"""Batched Relational-Grid-World: lockstep with the single env, autoreset, info decoding."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

from neurosym.envs.rgw import RGWEnv
from neurosym.envs.rgw_random import RGWRandomEnv
from neurosym.envs.rgw_vector import RGWRandomVectorEnv, RGWVectorEnv


def run_lockstep(
    make_single: Callable[[], RGWEnv],
    make_vec: Callable[[int], RGWVectorEnv],
    n: int = 5,
    steps: int = 250,
    seed: int = 7,
) -> int:
    """Step n single envs and one batched env on the same random actions; return episodes seen."""
    singles = [make_single() for _ in range(n)]
    vec = make_vec(n)
    obs, info = vec.reset(seed=seed)
    for i, env in enumerate(singles):
        o, inf = env.reset(seed=seed + i)
        assert (obs[i] == o).all(), f"[reset] obs {i}"
        assert vec.decode_info(info, i) == inf, f"[reset] info {i}"
    rng = np.random.default_rng(seed)
    done = np.zeros(n, dtype=bool)
    last_info: list[dict] = [{}] * n
    episodes = 0
    for t in range(steps):
        actions = rng.integers(0, 4, n)
        obs, reward, term, trunc, info = vec.step(actions)
        ent = vec.entity_grid()
        for i, env in enumerate(singles):
            if done[i]:
                o, inf = env.reset()
                r, te, tr = 0.0, False, False
                assert info["_final_info"][i], f"[{t}] env {i}: autoreset not flagged"
                assert vec.decode_info(info["final_info"], i) == last_info[i], (
                    f"[{t}] final_info {i}"
                )
                episodes += 1
            else:
                o, r, te, tr, inf = env.step(int(actions[i]))
            assert (obs[i] == o).all(), f"[{t}] env {i}: observations differ"
            assert (reward[i], term[i], trunc[i]) == (r, te, tr), (
                f"[{t}] env {i}: (reward, terminated, truncated) {(reward[i], term[i], trunc[i])} != {(r, te, tr)}"
            )
            decoded = vec.decode_info(info, i)
            assert decoded == inf, f"[{t}] env {i}: info {decoded} != {inf}"
            assert (ent[i] == env.entity_grid()).all(), f"[{t}] env {i}: entity grids differ"
            done[i] = te or tr
            last_info[i] = inf
        if "final_info" in info:
            assert info["_final_info"].sum() == np.count_nonzero(info["_final_info"])
    return episodes


@pytest.mark.parametrize(
    "kwargs",
    [
        {"map": "rgw2"},
        {"map": "rgw1", "max_steps": 25},
        {"map": "rgw2", "classic": True, "obs_mode": "grey", "max_steps": 30},
        {"map": "rgw2", "classic": True, "max_steps": 40},
        {"map": "rgw1", "enemy": "block", "max_steps": 40},
        {"map": "rgw2", "enemy": "end", "obs_mode": "grey"},
    ],
    ids=["rgw2", "rgw1-short", "rgw2-classic-grey", "rgw2-classic", "rgw1-block", "rgw2-end-grey"],
)
def test_lockstep_fixed_maps(kwargs: dict) -> None:
    single_kwargs = dict(kwargs)
    name = single_kwargs.pop("map")
    episodes = run_lockstep(
        lambda: RGWEnv(name, **single_kwargs), lambda n: RGWVectorEnv(n, map=name, **single_kwargs)
    )
    assert episodes >= 5  # autoresets were exercised


@pytest.mark.parametrize(
    "kw",
    [
        {"classic": False},  # enemy="block", rgw-random's default
        {"classic": True},  # enemy="pass", the only one classic rules have
        {"enemy": "end"},
        {"enemy": "pass"},
    ],
    ids=["block", "classic", "end", "pass"],
)
def test_lockstep_random_levels(kw: dict) -> None:
    kw = {**kw, "max_steps": 30, "num_enemies": 2}
    episodes = run_lockstep(lambda: RGWRandomEnv(**kw), lambda n: RGWRandomVectorEnv(n, **kw))
    assert episodes >= 10


def test_autoreset_step_returns_first_observation_and_zero_reward() -> None:
    env = RGWVectorEnv(2, map="A.T\n", max_steps=50)
    assert env.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    first, _ = env.reset(seed=0)
    env.step([1, 3])
    _, r, term, _, _ = env.step([1, 3])
    assert r.tolist() == [10.0, 0.0] and term.tolist() == [True, False]
    obs, r, term, trunc, info = env.step([1, 1])
    assert (obs[0] == first[0]).all() and r[0] == 0.0 and not term[0] and not trunc[0]
    assert info["_final_info"].tolist() == [True, False]
    assert env.decode_info(info["final_info"], 0)["outcome"] == "terminal"
    assert env.decode_info(info, 0)["agent"] == (0, 0) and info["episode_id"].tolist() == [1, 0]


def test_copy_false_returns_the_buffer_and_copy_true_fresh_arrays() -> None:
    shared = RGWVectorEnv(3, copy=False)
    a, _ = shared.reset(seed=0)
    b, *_ = shared.step([1, 1, 1])
    assert a is b
    fresh = RGWVectorEnv(3)
    a, _ = fresh.reset(seed=0)
    b, *_ = fresh.step([1, 1, 1])
    assert not np.shares_memory(a, b) and not (a == b).all()


def test_returned_info_arrays_are_not_modified_later() -> None:
    env = RGWVectorEnv(4, map="A.T\n")
    env.reset(seed=0)
    _, _, _, _, info = env.step([1, 1, 1, 1])
    before = {k: v.copy() for k, v in info.items() if isinstance(v, np.ndarray)}
    env.step([1, 1, 1, 1])
    env.step([0, 0, 0, 0])  # autoreset of every env
    for key, value in before.items():
        assert (info[key] == value).all(), key


def test_seeds_and_batch_api() -> None:
    env = RGWRandomVectorEnv(3, seed=5)
    obs, info = env.reset()
    assert info["seed"].tolist() == [5, 6, 7]
    again, _ = RGWRandomVectorEnv(3).reset(seed=[5, 6, 7])
    assert (obs == again).all()
    assert env.observation_space.shape == (3, 9, 10, 10) and obs in env.observation_space
    assert env.single_action_space.n == 4 and env.action_space.shape == (3,)
    assert env.entity_grid().shape == (3, 10, 10)
    with pytest.raises(ValueError, match="expected 3 actions"):
        env.step([0, 1])
    with pytest.raises(ValueError, match="actions must be 0 up"):
        env.step([0, 1, 4])
    with pytest.raises(ValueError, match="integers"):
        env.step(np.array([0.5, 1, 2]))


def test_render_modes() -> None:
    env = RGWVectorEnv(2, render_mode="rgb_array")
    env.reset(seed=0)
    frames = env.render()
    assert len(frames) == 2 and frames[0].shape == (240, 240, 3) and frames[0].dtype == np.uint8
    text = RGWVectorEnv(2, render_mode="ansi")
    text.reset(seed=0)
    assert "holding: nothing" in text.render()[1]


@pytest.mark.parametrize(
    ("make_vec", "obs_mode"),
    [
        (lambda: RGWVectorEnv(16, map="rgw2", max_steps=40), "onehot"),
        (lambda: RGWVectorEnv(16, map="rgw2", classic=True, max_steps=40), "onehot"),
        (lambda: RGWVectorEnv(16, map="rgw2", obs_mode="grey", max_steps=40), "grey"),
        (lambda: RGWRandomVectorEnv(16, max_steps=40, num_enemies=3), "onehot"),
        (lambda: RGWVectorEnv(16, map="rgw2", enemy="block", max_steps=40), "onehot"),
        (lambda: RGWRandomVectorEnv(16, max_steps=40, obs_mode="grey", enemy="end"), "grey"),
    ],
    ids=["default", "classic", "grey", "random", "block", "random-end-grey"],
)
def test_incremental_observation_equals_a_full_redraw(make_vec, obs_mode: str) -> None:
    """The in-place updates must give what drawing the state from scratch gives."""
    from neurosym.envs.rgw_rules import GREY_AGENT, GREY_OF_CELL

    env = make_vec()
    obs, _ = env.reset(seed=1)
    rng = np.random.default_rng(1)
    grey_of_entity = GREY_OF_CELL[:9].copy()
    grey_of_entity[0] = GREY_AGENT
    for t in range(200):
        ent = env.entity_grid()
        holding = env._batch.holding.astype(bool)
        if obs_mode == "onehot":
            want = (ent[:, None] == np.arange(9)[None, :, None, None]).astype(np.uint8)
            want[:, 8] = holding[:, None, None]
        else:
            want = grey_of_entity[ent][:, None]
        bad = np.flatnonzero((obs != want).reshape(len(obs), -1).any(axis=1))
        assert not len(bad), f"[{t}] envs {bad.tolist()} differ from a full redraw"
        obs, *_ = env.step(rng.integers(0, 4, 16))


def test_final_info_of_an_undecoded_random_level_is_regenerated() -> None:
    vec = RGWRandomVectorEnv(2, max_steps=3)
    single = RGWRandomEnv(max_steps=3)
    vec.reset(seed=4)
    single.reset(seed=4)
    for _ in range(3):
        last = single.step(0)[4]
        vec.step([0, 0])
    _, first = single.reset()
    _, _, _, _, info = vec.step([0, 0])  # autoreset; nothing of the old level was decoded
    assert vec.decode_info(info["final_info"], 0) == last
    assert vec.decode_info(info, 0) == first


def test_partial_reset_is_refused_not_ignored() -> None:
    from neurosym.envs import make_batched
    from neurosym.errors import ConfigError

    venv = make_batched("rgw2", 4, seed=0)
    with pytest.raises(ConfigError, match="reset_mask is not supported"):
        venv.reset(options={"reset_mask": np.array([True, False, False, False])})
