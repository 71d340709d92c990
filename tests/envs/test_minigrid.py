"""Farama Minigrid and BabyAI as neurosym's third env family: the wrapper's state, events,
observation, batched class, registration and the start of a training run.

The scripted episode: MiniGrid-DoorKey-5x5-v0 reset with seed 1 puts the agent at (2, 1)
facing south, the yellow key below it at (3, 1), the locked yellow door east of it at
(2, 2) and the goal at (3, 3).
"""

from __future__ import annotations

import numpy as np
import pytest
import torch

from neurosym.envs import canonical_name, env_family, make, make_batched
from neurosym.envs import minigrid_state as ms
from neurosym.envs.registration import minigrid_entries
from neurosym.errors import ConfigError

DOORKEY = "MiniGrid-DoorKey-5x5-v0"
SEED = 1
LEFT, RIGHT, FORWARD, PICKUP, DROP, TOGGLE, DONE = range(7)
SCRIPT = [FORWARD, PICKUP, LEFT, FORWARD, TOGGLE, FORWARD, FORWARD, RIGHT, FORWARD]
"""bump into the key, pick it up, turn to the door, bump into it, unlock it, walk through,
turn south, step onto the goal"""

EXPECTED = [  # (events, agent, direction, holding, door state) after each step
    (("bumped(key(yellow))",), (2, 1), "south", (), "locked"),
    (("picked(key(yellow))",), (2, 1), "south", ("key(yellow)",), "locked"),
    ((), (2, 1), "east", ("key(yellow)",), "locked"),
    (("bumped(door(yellow))",), (2, 1), "east", ("key(yellow)",), "locked"),
    (("unlocked(door(yellow))", "opened(door(yellow))"), (2, 1), "east", ("key(yellow)",), "open"),
    ((), (2, 2), "east", ("key(yellow)",), "open"),
    ((), (2, 3), "east", ("key(yellow)",), "open"),
    ((), (2, 3), "south", ("key(yellow)",), "open"),
    (("reached(goal)", "achieved(mission)"), (3, 3), "south", ("key(yellow)",), "open"),
]


def test_doorkey_reset_state_is_read_from_the_grid() -> None:
    env = make(DOORKEY)
    obs, info = env.reset(seed=SEED)
    assert info["objects"] == (
        ("agent", "agent", 2, 1),
        ("door_yellow", "door(yellow)", 2, 2),
        ("key_yellow", "key(yellow)", 3, 1),
        ("goal", "goal", 3, 3),
    )
    assert info["doors"] == (("door_yellow", "locked"),)
    assert (info["agent"], info["direction"], info["holding"]) == ((2, 1), "south", ())
    assert info["mission"] == "use the key to open the door and then get to the goal"
    assert info["events"] == () and info["outcome"] is None
    names = np.asarray(env.unwrapped.entity_names, dtype=object)[env.unwrapped.entity_grid()]
    assert names.tolist() == [
        ["wall"] * 5,
        ["wall", "empty", "wall", "empty", "wall"],
        ["wall", "agent", "door(yellow)", "empty", "wall"],
        ["wall", "key(yellow)", "wall", "goal", "wall"],
        ["wall"] * 5,
    ]


def test_doorkey_scripted_events_step_by_step() -> None:
    env = make(DOORKEY)
    env.reset(seed=SEED)
    for k, (action, (events, agent, direction, holding, door)) in enumerate(
        zip(SCRIPT, EXPECTED, strict=True)
    ):
        _, reward, terminated, truncated, info = env.step(action)
        assert info["events"] == events, k
        assert (info["agent"], info["direction"], info["holding"]) == (agent, direction, holding), k
        assert info["doors"] == (("door_yellow", door),), k
        assert terminated == (k == len(SCRIPT) - 1) and not truncated, k
    assert info["outcome"] == "goal" and reward > 0
    # the key left the map with the agent; the door and goal stay
    assert [o[0] for o in info["objects"]] == ["agent", "door_yellow", "goal"]


def test_dropped_key_keeps_its_id() -> None:
    env = make(DOORKEY)
    env.reset(seed=SEED)
    env.step(PICKUP)
    env.step(LEFT)  # facing east: the door
    env.step(RIGHT)
    env.step(RIGHT)  # facing west: a wall
    env.step(LEFT)  # south again: the key's empty cell
    _, _, _, _, info = env.step(DROP)
    assert info["events"] == ("dropped(key(yellow))",)
    assert ("key_yellow", "key(yellow)", 3, 1) in info["objects"] and info["holding"] == ()


def test_observation_planes() -> None:
    env = make(DOORKEY)
    obs, _ = env.reset(seed=SEED)
    assert obs.shape == (ms.NUM_PLANES, 5, 5) == env.observation_space.shape
    assert obs.dtype == np.uint8 and set(np.unique(obs)) <= {0, 1}
    agent_plane = 8
    assert np.argwhere(obs[agent_plane]).tolist() == [[2, 1]]
    assert obs[:, 2, 1].nonzero()[0].tolist() == [agent_plane, ms.DIRECTION_PLANE + 1]  # south
    door, key, goal = 2, 3, 6
    yellow = ms.COLOUR_PLANE + ms.COLOURS.index("yellow")
    locked = ms.STATE_PLANE + ms.DOOR_STATES.index("locked")
    assert obs[:, 2, 2].nonzero()[0].tolist() == [door, yellow, locked]
    assert obs[:, 3, 1].nonzero()[0].tolist() == [key, yellow]
    assert obs[:, 3, 3].nonzero()[0].tolist() == [goal]
    assert not obs[ms.CARRY_PLANE :].any()
    obs, *_ = env.step(PICKUP)
    assert obs[ms.CARRY_PLANE].all() and obs[ms.CARRY_COLOUR_PLANE + 4].all()  # key, yellow
    assert obs[ms.CARRY_PLANE :].sum() == 2 * 25 and not obs[key].any()


def test_batched_plays_the_single_env_seeded_s_plus_i_through_autoresets() -> None:
    n, seed = 3, 7
    venv = make_batched(DOORKEY, n, seed=seed, max_steps=6)
    singles = [make(DOORKEY, max_steps=6) for _ in range(n)]
    obs, info = venv.reset()
    firsts = [env.reset(seed=seed + i) for i, env in enumerate(singles)]
    for i, (o, inf) in enumerate(firsts):
        assert np.array_equal(obs[i], o) and venv.decode_info(info, i) == inf
    rng = np.random.default_rng(0)
    pending = np.zeros(n, bool)
    for _ in range(15):  # episodes end at 6 steps: two autoresets per sub-env
        actions = rng.integers(0, 7, n)
        obs, reward, terminated, truncated, info = venv.step(actions)
        for i, env in enumerate(singles):
            if pending[i]:
                o, inf = env.reset()
                r = 0.0
            else:
                o, r, _, _, inf = env.step(int(actions[i]))
            assert np.array_equal(obs[i], o) and reward[i] == r
            assert venv.decode_info(info, i) == inf
        pending = terminated | truncated
    assert venv.entity_grid().shape == (n, 5, 5)


def test_registration_and_listing(neurosym_main) -> None:
    assert canonical_name(DOORKEY) == DOORKEY == canonical_name(f"neurosym/{DOORKEY}")
    assert env_family("BabyAI-GoToObj-v0") == "minigrid"
    ids = {e.short for e in minigrid_entries()}
    assert {DOORKEY, "BabyAI-GoToObj-v0", "BabyAI-BossLevel-v0"} <= ids
    assert not any("Dynamic-Obstacles" in i or "WFC" in i for i in ids)
    proc = neurosym_main("envs", "--json")
    assert proc.returncode == 0, proc.stderr
    import json

    rows = [json.loads(line) for line in proc.stdout.splitlines()]
    listed = {r["name"]: r for r in rows}
    assert {r["name"] for r in rows if r["family"] == "minigrid"} == ids
    assert listed[DOORKEY] == {
        "name": DOORKEY,
        "id": f"neurosym/{DOORKEY}",
        "family": "minigrid",
        "description": "Minigrid DoorKeyEnv (size=5)",
    }


@pytest.mark.parametrize(
    ("name", "message"),
    [
        (
            "MiniGrid-DoorKey-5x5-v1",
            "unknown Minigrid environment 'MiniGrid-DoorKey-5x5-v1'; did you mean "
            "MiniGrid-DoorKey-5x5-v0, MiniGrid-DoorKey-8x8-v0 or MiniGrid-DoorKey-6x6-v0? "
            "`neurosym envs` lists the 166 Minigrid and BabyAI ids",
        ),
        (
            "BabyAI-MazeOfTwistyPassages-v0",
            "unknown Minigrid environment 'BabyAI-MazeOfTwistyPassages-v0'; `neurosym envs` lists the 166 "
            "Minigrid and BabyAI ids",
        ),
        (
            "MiniGrid-Dynamic-Obstacles-5x5-v0",
            "Minigrid environment 'MiniGrid-Dynamic-Obstacles-5x5-v0' is not one neurosym plays: "
            "its env takes 3 actions (left, right, forward), not Minigrid's 7",
        ),
    ],
)
def test_unknown_minigrid_id_is_one_line(neurosym_main, name: str, message: str) -> None:
    with pytest.raises(ConfigError) as caught:
        make(name)
    assert str(caught.value) == message
    proc = neurosym_main("envs", "--show", name)
    assert proc.returncode != 0
    assert proc.stderr.strip().splitlines() == [f"neurosym envs: error: {message}"]


def test_babyai_mission_and_show(neurosym_main) -> None:
    env = make("BabyAI-GoToObj-v0")
    _, info = env.reset(seed=0)
    assert info["mission"] == "go to the green key"
    proc = neurosym_main("envs", "--show", "BabyAI-GoToObj-v0")
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert len(lines) == 9 and lines[0] == "WG" * 8 and lines[-1] == "go to the green key"


def test_a_training_run_starts_on_a_minigrid_id(tmp_path) -> None:
    """The run's plan (the family's presets, 7 actions), one rollout and one PPO update."""
    from neurosym.agent.learners.optimizers import shared_optimizer
    from neurosym.agent.learners.ppo import ppo_update
    from neurosym.agent.networks.model import ActorCritic
    from neurosym.agent.rollout import RolloutState, collect_rollout
    from neurosym.agent.run.plan import resolve_run

    plan = resolve_run(DOORKEY, "predinet", tmp_path, algo="ppo")
    assert plan.family == "minigrid" and plan.env_name == DOORKEY
    assert plan.model_config.obs_shape == (ms.NUM_PLANES, 5, 5)
    assert plan.model_config.n_actions == 7
    torch.manual_seed(0)
    model = ActorCritic(plan.model_config)
    venv = make_batched(DOORKEY, 4, seed=0)
    rollout, _ = collect_rollout(
        model, RolloutState(venv, 0), 8, torch.Generator().manual_seed(0), record=True
    )
    before = [p.detach().clone() for p in model.parameters()]
    opt = shared_optimizer(model.parameters(), plan.train_config)
    ppo_update(model, opt, rollout, plan.train_config, torch.Generator().manual_seed(0))
    assert any(not torch.equal(a, b) for a, b in zip(before, model.parameters(), strict=True))
