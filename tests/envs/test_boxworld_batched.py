"""Box-World batched: lockstep agreement with the single environment across autoresets,
the vector API (spaces, autoreset, final_info, partial reset, seeds) and refused input."""

from __future__ import annotations

import numpy as np
import pytest

from neurosym.envs.boxworld import BOXWORLD_CONFIGS, BoxWorldEnv, BoxWorldVectorEnv
from neurosym.envs.boxworld_solver import nearest_interaction
from neurosym.errors import ConfigError


def explorer_actions(grids: np.ndarray, agents, helds, rng: np.random.Generator) -> np.ndarray:
    """Half random, half towards the nearest usable object: keys, boxes, distractors and gems
    all happen (random actions alone rarely open a box)."""
    actions = rng.integers(0, 4, size=len(grids))
    for i, (grid, (row, col), held) in enumerate(zip(grids, agents, helds, strict=True)):
        if rng.random() < 0.5:
            a = nearest_interaction(grid.ravel(), row * 14 + col, held)
            if a is not None:
                actions[i] = a
    return actions


def held_colour(info: dict) -> int:
    from neurosym.envs.boxworld_entities import COLOUR_INDEX

    return COLOUR_INDEX[info["holding"][0][4:-1]] if info["holding"] else -1


@pytest.mark.parametrize(
    ("config", "n", "steps", "max_steps"),
    [
        pytest.param("bw2", 6, 500, 60, marks=pytest.mark.expensive),
        pytest.param("bw3", 5, 400, 60, marks=pytest.mark.expensive),
        ("default", 3, 300, 60),
        # 24 envs: next levels are drawn ahead and refilled in batches of 3
        ("bw1", 24, 60, 4),
    ],
)
def test_lockstep_with_single_environments(config, n, steps, max_steps):
    kwargs = dict(BOXWORLD_CONFIGS.get(config, {}))
    kwargs["max_steps"] = max_steps  # many truncations and autoresets
    seed = 100
    batched = BoxWorldVectorEnv(n, seed=seed, **kwargs)
    singles = [BoxWorldEnv(**kwargs) for _ in range(n)]
    obs, info = batched.reset()
    single_out = [env.reset(seed=seed + i) for i, env in enumerate(singles)]
    for i in range(n):
        assert np.array_equal(obs[i], single_out[i][0]), f"[reset] obs of env {i}"
        assert batched.decode_info(info, i) == single_out[i][1], f"[reset] info of env {i}"
    assert np.array_equal(batched.entity_grid()[0], singles[0].entity_grid())

    rng = np.random.default_rng(0)
    done = np.zeros(n, bool)
    last_info = [out[1] for out in single_out]
    seen = {"gem": 0, "distractor": 0, "timeout": 0, "opened": 0, "autoreset": 0}
    for t in range(steps):
        grids = [env.entity_grid() for env in singles]
        actions = explorer_actions(
            grids, [li["agent"] for li in last_info], [held_colour(li) for li in last_info], rng
        )
        obs, reward, terminated, truncated, info = batched.step(actions)
        for i, env in enumerate(singles):
            if done[i]:  # next-step autoreset: the action is ignored, a new level starts
                s_obs, s_info = env.reset()
                s_reward, s_term, s_trunc = 0.0, False, False
                assert info["_final_info"][i], f"[{t}] env {i}: autoreset not marked"
                final = batched.decode_info(info["final_info"], i)
                assert final == last_info[i], f"[{t}] env {i}: final_info {final} != {last_info[i]}"
                seen["autoreset"] += 1
            else:
                s_obs, s_reward, s_term, s_trunc, s_info = env.step(int(actions[i]))
            assert np.array_equal(obs[i], s_obs), f"[{t}] env {i}: observations differ"
            assert reward[i] == s_reward, f"[{t}] env {i}: reward {reward[i]} != {s_reward}"
            assert terminated[i] == s_term, f"[{t}] env {i}: terminated {terminated[i]} != {s_term}"
            assert truncated[i] == s_trunc, f"[{t}] env {i}: truncated {truncated[i]} != {s_trunc}"
            decoded = batched.decode_info(info, i)
            assert decoded == s_info, f"[{t}] env {i}: info {decoded} != {s_info}"
            if s_info["outcome"]:
                seen[s_info["outcome"]] += 1
            seen["opened"] += any(e.startswith("opened") for e in s_info["events"])
            last_info[i] = s_info
        if "_final_info" in info:
            assert not (info["_final_info"] & ~done).any(), f"[{t}] final_info marks a running env"
        done = terminated | truncated
    # the run covered what it is meant to compare
    assert seen["timeout"] and seen["opened"] and seen["autoreset"] > n, seen
    if max_steps > 10:
        assert seen["gem"], seen
    if config == "bw2":
        assert seen["distractor"], seen


def test_spaces_and_returned_types():
    env = BoxWorldVectorEnv(4, seed=0, **BOXWORLD_CONFIGS["bw1"])
    obs, info = env.reset()
    assert env.observation_space.shape == (4, 3, 14, 14) and env.observation_space.contains(obs)
    assert env.single_observation_space.shape == (3, 14, 14)
    assert env.action_space.shape == (4,) and env.single_action_space.n == 4
    assert env.metadata["autoreset_mode"].value == "NextStep"
    obs2, reward, terminated, truncated, info = env.step(np.zeros(4, np.int64))
    assert obs2.dtype == np.uint8 and reward.shape == (4,) and terminated.dtype == bool
    assert info["agent"].shape == (4, 2) and info["outcome"].shape == (4,)
    assert env.entity_grid().shape == (4, 14, 14)
    obs2[:] = 0  # returned arrays are copies: the environment keeps its own state
    assert env.step(np.zeros(4, np.int64))[0].any()


def test_seeds_map_to_single_environments_and_reset_continues_the_stream():
    env = BoxWorldVectorEnv(3, **BOXWORLD_CONFIGS["bw3"])
    singles = [BoxWorldEnv(**BOXWORLD_CONFIGS["bw3"]) for _ in range(3)]
    obs, info = env.reset(seed=42)
    for i, single in enumerate(singles):
        s_obs, s_info = single.reset(seed=42 + i)
        assert np.array_equal(obs[i], s_obs) and env.decode_info(info, i) == s_info
    obs, _ = env.reset()  # the next level of each stream
    for i, single in enumerate(singles):
        assert np.array_equal(obs[i], single.reset()[0])
    # a list of seeds, one per sub-environment
    obs, _ = env.reset(seed=[7, 8, 9])
    assert np.array_equal(obs[1], singles[0].reset(seed=8)[0])


def test_partial_reset_with_reset_mask():
    env = BoxWorldVectorEnv(3, seed=1, **BOXWORLD_CONFIGS["bw2"])
    first, _ = env.reset()
    again, info = env.reset(options={"reset_mask": np.array([False, True, False])})
    assert np.array_equal(first[0], again[0]) and np.array_equal(first[2], again[2])
    assert not np.array_equal(first[1], again[1])
    single = BoxWorldEnv(**BOXWORLD_CONFIGS["bw2"])
    single.reset(seed=2)
    assert np.array_equal(again[1], single.reset()[0])  # sub-env 1's second level


def test_copy_false_hands_out_the_live_buffer():
    shared = BoxWorldVectorEnv(3, seed=5, copy=False)
    copied = BoxWorldVectorEnv(3, seed=5)
    first, _ = shared.reset()
    assert np.array_equal(first, copied.reset()[0])
    actions = np.array([0, 1, 2])
    obs, *_ = shared.step(actions)
    expected = copied.step(actions)[0]
    assert np.shares_memory(obs, first)
    assert np.array_equal(first, expected)  # the array handed out at reset shows the new state


def test_render_modes():
    frames = BoxWorldVectorEnv(2, seed=0, render_mode="rgb_array", tile_size=4)
    frames.reset()
    assert [f.shape for f in frames.render()] == [(56, 56, 3)] * 2
    text = BoxWorldVectorEnv(2, seed=0, render_mode="ansi")
    text.reset()
    assert all(t.startswith("#" * 14) for t in text.render())


def test_bad_input_is_refused():
    with pytest.raises(ConfigError, match="num_envs must be a positive integer, got 0"):
        BoxWorldVectorEnv(0)
    with pytest.raises(ConfigError, match="seed must be a non-negative integer, got -3"):
        BoxWorldVectorEnv(2, seed=-3)
    with pytest.raises(ConfigError, match="solution_length must be at least 1"):
        BoxWorldVectorEnv(2, solution_length=0)
    env = BoxWorldVectorEnv(2, seed=0)
    with pytest.raises(RuntimeError, match="reset"):
        env.step(np.zeros(2, np.int64))
    env.reset()
    with pytest.raises(ValueError, match="unknown action 4"):
        env.step(np.array([0, 4]))
    with pytest.raises(ValueError, match="actions must be 2 integers"):
        env.step(np.zeros(3, np.int64))
    with pytest.raises(ConfigError, match="reset got 3 seeds for 2 environments"):
        env.reset(seed=[1, 2, 3])
