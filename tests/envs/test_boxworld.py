"""Box-World, single environment: exact transitions on hand-built levels, observation,
entity grid, info, seeding, rendering, gymnasium's checker and refused input."""

from __future__ import annotations

import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.envs.registration import EnvSpec
from gymnasium.utils.env_checker import check_env

from neurosym.envs.boxworld import (
    ACTION_NAMES,
    BOXWORLD_CONFIGS,
    Action,
    Box,
    BoxWorldEnv,
    Level,
)
from neurosym.envs.boxworld_entities import (
    AGENT_RGB,
    BACKGROUND_RGB,
    COLOURS,
    ENTITY_NAMES,
    GEM_RGB,
    WALL_RGB,
)
from neurosym.errors import ConfigError

UP, RIGHT, DOWN, LEFT = Action.UP, Action.RIGHT, Action.DOWN, Action.LEFT
RGB = dict(COLOURS)
ENTRY_POINT = "neurosym.envs.boxworld:BoxWorldEnv"


def play(level: Level, actions, **kwargs):
    """Reset on ``level`` and take ``actions``; returns (env, first info, list of step tuples)."""
    env = BoxWorldEnv(**kwargs)
    _, info = env.reset(options={"level": level})
    return env, info, [env.step(a) for a in actions]


def names(env: BoxWorldEnv) -> np.ndarray:
    return np.array(ENTITY_NAMES)[env.entity_grid()]


def pixel(obs: np.ndarray, row: int, col: int) -> tuple[int, ...]:
    return tuple(int(v) for v in obs[:, row, col])


# ---------------------------------------------------------------- exact transitions


def test_walking_into_a_loose_key_picks_it_up_and_draws_it_top_left():
    level = Level(agent=(5, 5), keys=((5, 6, "red"),))
    env, info0, [(obs, reward, terminated, truncated, info)] = play(level, [RIGHT])
    assert info0["objects"] == (("agent", "agent", 5, 5), ("key_red", "key(red)", 5, 6))
    assert info0["holding"] == () and info0["events"] == () and info0["outcome"] is None
    assert (reward, terminated, truncated) == (0.0, False, False)
    assert info == {
        "agent": (5, 6),
        "holding": ("key(red)",),
        "objects": (("agent", "agent", 5, 6),),
        "events": ("got(key(red))",),
        "outcome": None,
    }
    assert pixel(obs, 0, 0) == RGB["red"]
    assert pixel(obs, 5, 6) == AGENT_RGB and pixel(obs, 5, 5) == BACKGROUND_RGB
    grid = names(env)
    assert grid[0, 0] == "held(red)" and grid[5, 6] == "agent" and grid[5, 5] == "empty"


def test_a_new_loose_key_replaces_the_held_one():
    level = Level(agent=(5, 5), keys=((5, 6, "red"), (5, 8, "blue")))
    env, _, steps = play(level, [RIGHT, RIGHT, RIGHT])
    assert [s[4]["holding"] for s in steps] == [("key(red)",), ("key(red)",), ("key(blue)",)]
    assert steps[2][4]["events"] == ("got(key(blue))",)
    assert pixel(steps[2][0], 0, 0) == RGB["blue"]


def test_a_lock_without_its_key_and_a_box_content_block_like_walls():
    box = Box(row=5, col=7, lock="red", content="gem")  # gem at (5, 6), lock at (5, 7)
    level = Level(agent=(5, 8), boxes=(box,), keys=((9, 9, "blue"),))
    env, info0, steps = play(level, [LEFT])
    obs, reward, terminated, truncated, info = steps[0]
    assert (reward, terminated, truncated) == (0.0, False, False)
    assert info["agent"] == (5, 8) and info["events"] == ()
    assert info["objects"] == info0["objects"] and info["objects"][0] == ("agent", "agent", 5, 8)
    # the content cannot be walked onto either, from above
    env.reset(options={"level": Level(agent=(4, 6), boxes=(box,))})
    _, reward, terminated, _, info = env.step(DOWN)
    assert info["agent"] == (4, 6) and reward == 0.0 and not terminated


def test_a_wrong_key_does_not_open_a_lock():
    level = Level(agent=(5, 9), keys=((5, 10, "blue"),), boxes=(Box(5, 8, "red", "gem"),))
    env, _, steps = play(level, [RIGHT, LEFT, LEFT])
    _, reward, terminated, _, info = steps[2]
    assert info["agent"] == (5, 9) and info["holding"] == ("key(blue)",)
    assert reward == 0.0 and not terminated and info["events"] == ()


def test_opening_a_correct_box_hands_over_its_key():
    level = Level(
        agent=(4, 4),
        keys=((4, 5, "red"),),
        boxes=(Box(5, 5, "red", "blue"), Box(9, 7, "blue", "gem")),
    )
    env, info0, steps = play(level, [RIGHT, DOWN])
    assert [o[0] for o in info0["objects"]] == [
        "agent",
        "key_red",
        "key_blue",
        "lock_red",
        "gem",
        "lock_blue",
    ]
    obs, reward, terminated, truncated, info = steps[1]
    assert (reward, terminated, truncated) == (1.0, False, False)
    assert info["events"] == ("opened(lock(red))", "got(key(blue))")
    assert info["holding"] == ("key(blue)",)
    assert info["agent"] == (5, 5)  # on the lock's cell
    assert [o[0] for o in info["objects"]] == ["agent", "gem", "lock_blue"]
    grid = names(env)
    assert grid[5, 4] == "empty" and grid[5, 5] == "agent" and grid[0, 0] == "held(blue)"
    assert pixel(obs, 5, 4) == BACKGROUND_RGB and pixel(obs, 0, 0) == RGB["blue"]


def test_the_gem_box_pays_eleven_and_ends_the_episode():
    level = Level(agent=(4, 4), keys=((4, 5, "red"),), boxes=(Box(5, 5, "red", "gem"),))
    env, _, steps = play(level, [RIGHT, DOWN])
    obs, reward, terminated, truncated, info = steps[1]
    assert (reward, terminated, truncated) == (11.0, True, False)
    assert info["events"] == ("opened(lock(red))", "got(gem)")
    assert info["outcome"] == "gem" and info["holding"] == ()
    assert info["objects"] == (("agent", "agent", 5, 5),)
    assert pixel(obs, 0, 0) == WALL_RGB  # nothing held any more


def test_a_distractor_box_costs_one_and_ends_the_episode():
    level = Level(
        agent=(4, 4),
        keys=((4, 5, "red"),),
        boxes=(Box(5, 5, "red", "purple", distractor=True), Box(9, 7, "red", "gem")),
    )
    env, info0, steps = play(level, [RIGHT, DOWN])
    ids = [o[0] for o in info0["objects"]]
    assert ids == ["agent", "key_red", "key_purple", "lock_red", "gem", "lock_red_2"]
    _, reward, terminated, truncated, info = steps[1]
    assert (reward, terminated, truncated) == (-1.0, True, False)
    assert info["events"] == ("opened(lock(red))", "got(key(purple))", "hit(distractor)")
    assert info["outcome"] == "distractor"
    # the other red lock keeps its id for the rest of the episode
    assert [o[0] for o in info["objects"]] == ["agent", "gem", "lock_red_2"]


def test_a_loose_gem_pays_ten():
    env, _, steps = play(Level(agent=(3, 3), gem=(3, 4)), [RIGHT])
    _, reward, terminated, _, info = steps[0]
    assert (reward, terminated) == (10.0, True)
    assert info["events"] == ("got(gem)",) and info["outcome"] == "gem"


def test_a_key_with_a_lock_to_its_right_is_locked_in_its_box():
    level = Level(agent=(5, 5), keys=((5, 6, "blue"),), boxes=(Box(5, 7, "red", "gem"),))
    # (5, 6) is a loose key *and* left of a lock: the rules read it as the box's content
    with pytest.raises(ConfigError, match=r"\(5, 6\) shares its cell"):
        play(level, [RIGHT])
    level = Level(agent=(4, 6), boxes=(Box(5, 7, "red", "blue"),))
    env, _, [(_, reward, _, _, info)] = play(level, [DOWN])
    assert info["agent"] == (4, 6) and info["holding"] == () and reward == 0.0


def test_walls_block_and_the_step_limit_truncates():
    env, _, steps = play(Level(agent=(1, 1)), [UP, LEFT, UP], max_steps=3)
    assert [s[4]["agent"] for s in steps] == [(1, 1)] * 3
    assert [(s[2], s[3]) for s in steps] == [(False, False), (False, False), (False, True)]
    assert [s[4]["outcome"] for s in steps] == [None, None, "timeout"]


def test_ending_on_the_last_step_is_a_termination_not_a_truncation():
    level = Level(agent=(3, 3), gem=(3, 4))
    _, _, [(_, reward, terminated, truncated, info)] = play(level, [RIGHT], max_steps=1)
    assert (reward, terminated, truncated, info["outcome"]) == (10.0, True, False, "gem")


# ---------------------------------------------------------------- observation and grid


def test_observation_colours_and_entity_names_of_a_generated_level():
    env = BoxWorldEnv(**BOXWORLD_CONFIGS["bw2"])
    obs, info = env.reset(seed=7)
    assert obs.shape == (3, 14, 14) and obs.dtype == np.uint8
    assert env.observation_space.contains(obs)
    grid = names(env)
    assert set(grid[0, :]) == {"wall"} and set(grid[:, 13]) == {"wall"}
    assert pixel(obs, 13, 13) == WALL_RGB
    assert tuple(int(v) for v in np.argwhere(grid == "agent")[0]) == info["agent"]
    for oid, typ, row, col in info["objects"]:
        assert grid[row, col] == typ, oid
        colour = typ[typ.index("(") + 1 : -1] if "(" in typ else None
        expected = RGB[colour] if colour else {"gem": GEM_RGB, "agent": AGENT_RGB}[typ]
        assert pixel(obs, row, col) == expected, oid
    # bw2: one loose key, the gem box and a distractor box sharing the gem box's lock colour
    types = sorted(t for _, t, _, _ in info["objects"])
    locks = [t for t in types if t.startswith("lock(")]
    assert len(locks) == 2 and locks[0] == locks[1] and "gem" in types
    assert env.unwrapped.obs_scale == pytest.approx(1 / 255)
    assert ACTION_NAMES == ("up", "right", "down", "left")


def test_boxes_content_shows_as_its_entity_left_of_the_lock():
    env = BoxWorldEnv()
    env.reset(options={"level": Level(agent=(1, 1), boxes=(Box(6, 6, "sky", "navy"),))})
    grid = names(env)
    assert grid[6, 5] == "key(navy)" and grid[6, 6] == "lock(sky)"


# ---------------------------------------------------------------- seeding


def test_same_seed_same_levels_and_episode_sequence():
    a, b = BoxWorldEnv(**BOXWORLD_CONFIGS["bw3"]), BoxWorldEnv(**BOXWORLD_CONFIGS["bw3"])
    for seed in (0, 1, 2**40):
        obs_a, info_a = a.reset(seed=seed)
        obs_b, info_b = b.reset(seed=seed)
        assert np.array_equal(obs_a, obs_b) and info_a == info_b
        for _ in range(3):  # later episodes without a seed follow the same stream
            obs_a, info_a = a.reset()
            obs_b, info_b = b.reset()
            assert np.array_equal(obs_a, obs_b) and info_a == info_b
    first = [BoxWorldEnv().reset(seed=s)[0] for s in range(20)]
    assert len({o.tobytes() for o in first}) == 20


def test_unseeded_environments_differ():
    obs = [BoxWorldEnv().reset()[0].tobytes() for _ in range(5)]
    assert len(set(obs)) == 5


# ---------------------------------------------------------------- rendering and checker


def test_rgb_array_render_upscales_tiles():
    env = BoxWorldEnv(render_mode="rgb_array", tile_size=8)
    env.reset(options={"level": Level(agent=(2, 2), boxes=(Box(4, 5, "red", "gem"),))})
    frame = env.render()
    assert frame.shape == (112, 112, 3) and frame.dtype == np.uint8
    tile = frame[4 * 8 : 5 * 8, 5 * 8 : 6 * 8]  # the lock
    assert tuple(tile[0, 0]) == RGB["red"] and tuple(tile[4, 4]) != RGB["red"]  # keyhole
    assert tuple(frame[0, 0]) == WALL_RGB
    agent = frame[2 * 8 : 3 * 8, 2 * 8 : 3 * 8]
    assert tuple(agent[4, 4]) == AGENT_RGB and tuple(agent[0, 0]) == BACKGROUND_RGB


def test_ansi_render_draws_letters_and_legend():
    env = BoxWorldEnv(render_mode="ansi")
    level = Level(agent=(1, 1), keys=((3, 3, "green"),), boxes=(Box(6, 6, "green", "gem"),))
    env.reset(options={"level": level})
    lines = env.render().splitlines()
    assert lines[0] == "#" * 14 and lines[1] == "#@" + "." * 11 + "#"
    assert lines[3][3] == "b" and lines[6][5:7] == "*B"
    assert lines[-1] == "keys/locks: b/B green"
    env.step(DOWN), env.step(DOWN), env.step(RIGHT), env.step(RIGHT)
    assert env.render().splitlines()[0][0] == "b"  # the held key, top left


@pytest.mark.parametrize("config", ["bw1", "bw2", "bw3", None])
@pytest.mark.parametrize("render_mode", [None, "rgb_array", "ansi"])
def test_gymnasium_check_env(config, render_mode):
    kwargs = BOXWORLD_CONFIGS[config] if config else {}
    # made from a spec (not registered: the registry is tested elsewhere) so that the
    # checker can also build the other render modes
    spec = EnvSpec("neurosym/BoxWorldCheck-v0", entry_point=ENTRY_POINT, kwargs=kwargs)
    env = gym.make(spec, render_mode=render_mode).unwrapped
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the checker's warnings are failures here
        check_env(env, skip_render_check=render_mode is None)


# ---------------------------------------------------------------- refused input


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"solution_length": 0}, "solution_length must be at least 1, got 0"),
        ({"num_distractors": -1}, "num_distractors must be 0 or more"),
        ({"distractor_length": 0}, "distractor_length must be at least 1"),
        ({"max_steps": 0}, "max_steps must be at least 1"),
        ({"solution_length": 2.5}, "solution_length must be an integer, got 2.5"),
        ({"solution_length": 20, "num_distractors": 1}, "leaves 0 of the 20 colours"),
        ({"solution_length": 10, "num_distractors": 5}, "would hold 16 objects"),
        ({"render_mode": "human"}, "unknown render_mode 'human'"),
        ({"tile_size": 2}, "tile_size must be an integer of at least 4 pixels, got 2"),
    ],
)
def test_bad_parameters_are_refused_with_one_line(kwargs, message):
    with pytest.raises(ConfigError, match=message) as err:
        BoxWorldEnv(**kwargs)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize(
    ("level", "message"),
    [
        (Level(agent=(0, 3)), r"agent at \(0, 3\) is outside"),
        (Level(agent=(2, 2), keys=((2, 2, "red"),)), r"agent at \(2, 2\) stands on an object"),
        (Level(agent=(2, 2), keys=((4, 4, "rouge"),)), "unknown colour 'rouge'; colours are red"),
        (
            Level(agent=(2, 2), boxes=(Box(4, 1, "red", "gem"),)),
            r"content of the red box at \(4, 0\)",
        ),
    ],
)
def test_bad_levels_are_refused(level, message):
    with pytest.raises(ConfigError, match=message):
        BoxWorldEnv().reset(options={"level": level})


@pytest.mark.parametrize("action", [4, -1, 1.0, "up"])
def test_unknown_actions_raise_value_error(action):
    env = BoxWorldEnv()
    env.reset(seed=0)
    with pytest.raises(ValueError, match="unknown action"):
        env.step(action)
