"""Every registered environment: gymnasium's checker, names, factories, seeding, rendering, CLI."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import neurosym.envs as envs
from neurosym.envs import ACTION_NAMES, ENVS, Action, canonical_name, env_family, make, make_batched
from neurosym.errors import ConfigError

NAMES = list(ENVS)
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def test_names_ids_and_families() -> None:
    assert NAMES == ["rgw1", "rgw2", "rgw-random", "bw1", "bw2", "bw3", "boxworld"]
    assert ENVS["rgw2"] == "neurosym/RGW2-v0" and ENVS["boxworld"] == "neurosym/BoxWorld-v0"
    for name, env_id in ENVS.items():
        assert canonical_name(name) == canonical_name(env_id) == name
        assert env_id in gymnasium.registry
        assert env_family(env_id) == ("rgw" if name.startswith("rgw") else "boxworld")
    assert [a.name.lower() for a in Action] == list(ACTION_NAMES) == ["up", "right", "down", "left"]
    assert set(envs.__all__) >= {"make", "make_batched", "ENVS", "env_family", "canonical_name"}


def test_unknown_names_are_refused_with_the_known_ones() -> None:
    for bad in ("rgw3", "neurosym/RGW9-v0", ""):
        with pytest.raises(ConfigError, match=r"unknown environment .*rgw1, rgw2, rgw-random"):
            make(bad)
    with pytest.raises(ConfigError, match="positive integer"):
        make_batched("rgw2", 0)


def test_unknown_options_are_refused_with_the_known_ones() -> None:
    """One line naming the options the env takes, not gymnasium's TypeError from its factory."""
    with pytest.raises(
        ConfigError, match=r"^unknown option 'bogus' for rgw2; expected one of map, classic"
    ):
        make("rgw2", bogus=1)
    with pytest.raises(ConfigError, match=r"^unknown option 'solution' for bw1; .*solution_length"):
        make_batched("bw1", 2, solution=2)
    with pytest.raises(ConfigError, match=r"^unknown rgw-random parameter 'bogus'"):
        make_batched("rgw-random", 2, bogus=1)
    make("rgw2", classic=True).close()  # known options still pass


@pytest.mark.parametrize("name", ["rgw2", "rgw-random", "bw1"])
def test_the_batched_env_takes_its_own_options(name: str) -> None:
    """copy=False is the batched env's option (no copy of the observation per step)."""
    venv = make_batched(name, 2, seed=0, copy=False)
    obs, _ = venv.reset(seed=0)
    assert obs.shape[0] == 2
    venv.close()
    with pytest.raises(ConfigError, match=r"^unknown .*'copy'"):
        make(name, copy=False)


@pytest.mark.parametrize("name", NAMES)
def test_gymnasium_check_env(name: str) -> None:
    for render_mode in ("rgb_array", "ansi"):
        env = make(name, render_mode=render_mode)
        check_env(env.unwrapped)
        env.close()


@pytest.mark.parametrize("name", NAMES)
def test_single_env_contract(name: str) -> None:
    env = make(name)
    obs, info = env.reset(seed=3)
    space = env.observation_space
    assert obs.dtype == np.uint8 and obs.shape == space.shape and obs in space
    C, H, W = obs.shape
    assert env.unwrapped.obs_scale == (1.0 if name.startswith("rgw") else 1 / 255)
    level = {"optimal_return", "guarded", "needs_teleport", "hazard_on_route"}
    assert set(info) == {"agent", "holding", "objects", "events", "outcome"} | (
        level if name.startswith("rgw") else set()
    )
    assert info["events"] == () and info["outcome"] is None
    grid = env.unwrapped.entity_grid()
    names = env.unwrapped.entity_names
    assert grid.shape == (H, W) and names[grid[info["agent"]]] == "agent"
    assert "agent" in names and "empty" in names and "wall" in names
    ids = [o[0] for o in info["objects"]]
    assert len(ids) == len(set(ids))
    for t in range(30):
        obs, r, term, trunc, info = env.step(t % 4)
        assert obs in space and isinstance(r, float), f"[{t}]"
        assert all(isinstance(e, str) for e in info["events"]), f"[{t}]"
        if term or trunc:
            assert info["outcome"] in (
                "terminal",
                "pit",
                "enemy",
                "timeout",
                "gem",
                "distractor",
            ), f"[{t}]"
            break


@pytest.mark.parametrize("name", NAMES)
def test_batched_env_contract(name: str) -> None:
    vec = make_batched(name, 6, seed=1)
    single = make(name)
    obs, info = vec.reset()
    assert obs.shape == (6, *single.observation_space.shape) and obs.dtype == np.uint8
    assert vec.unwrapped.entity_grid().shape == (6, *obs.shape[2:])
    level = {"optimal_return", "guarded", "needs_teleport", "hazard_on_route"}
    for i in range(6):
        assert set(vec.unwrapped.decode_info(info, i)) == {
            "agent",
            "holding",
            "objects",
            "events",
            "outcome",
        } | (level if name.startswith("rgw") else set())
    for _ in range(10):
        obs, r, term, trunc, info = vec.step(np.arange(6) % 4)
    assert r.shape == term.shape == trunc.shape == (6,)
    # The same seed gives the same first observation as the single env with seed + i.
    first, _ = make_batched(name, 3, seed=9).reset()
    for i in range(3):
        assert (first[i] == make(name).reset(seed=9 + i)[0]).all(), f"{name} sub-env {i}"


@pytest.mark.parametrize("name", NAMES)
def test_same_seed_same_episode(name: str) -> None:
    a, b = make(name), make(name)
    oa, ia = a.reset(seed=42)
    ob, ib = b.reset(seed=42)
    rng = np.random.default_rng(0)
    for t in range(60):
        assert (oa == ob).all() and ia == ib, f"[{t}] {name}"
        act = int(rng.integers(4))
        oa, ra, ta, ua, ia = a.step(act)
        ob, rb, tb, ub, ib = b.step(act)
        assert (ra, ta, ua) == (rb, tb, ub), f"[{t}] {name}"
        if ta or ua:
            oa, ia = a.reset()
            ob, ib = b.reset()


@pytest.mark.parametrize("name", NAMES)
def test_render_modes(name: str) -> None:
    env = make(name, render_mode="rgb_array")
    obs, _ = env.reset(seed=0)
    frame = env.render()
    H, W = obs.shape[1:]
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3
    assert frame.shape[0] % H == 0 and frame.shape[1] % W == 0 and frame.shape[0] // H >= 8
    text_env = make(name, render_mode="ansi")
    text_env.reset(seed=0)
    text = text_env.render()
    assert isinstance(text, str) and len(text.splitlines()) >= H


def test_rgw_tiles_are_distinct() -> None:
    from neurosym.envs.render import rgw_tiles

    tiles = rgw_tiles()
    flat = tiles.reshape(len(tiles), -1)
    assert len({row.tobytes() for row in flat}) == len(tiles)


def test_gymnasium_make_with_the_module_prefix() -> None:
    code = "import gymnasium as g; e = g.make('neurosym.envs:neurosym/RGW1-v0'); print(e.reset(seed=0)[0].shape)"
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True
    )
    assert out.stdout.strip() == "(9, 10, 10)"


def run_cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "neurosym", "envs", *args], capture_output=True, text=True, cwd=ROOT
    )


def test_cli_lists_every_environment() -> None:
    out = run_cli()
    assert out.returncode == 0, out.stderr
    for name, env_id in ENVS.items():
        cells = next(
            [c.strip() for c in ln.split("│")[1:-1]]
            for ln in out.stdout.splitlines()
            if ln.startswith("│") and ln.split("│")[1].strip() == name
        )
        assert cells[1] == env_id and cells[3]
    rows = [json.loads(ln) for ln in run_cli("--json").stdout.splitlines()]
    own, minigrid = rows[: len(NAMES)], rows[len(NAMES) :]  # then the Minigrid family's ids
    assert [r["name"] for r in own] == NAMES
    assert all(r["id"] == ENVS[r["name"]] and r["description"] for r in own)
    assert minigrid and all(r["family"] == "minigrid" for r in minigrid)


def test_cli_show_and_errors() -> None:
    out = run_cli("--show", "rgw2")
    assert out.returncode == 0, out.stderr
    assert out.stdout.splitlines()[0] == "A....MSMMM" and "\x1b" not in out.stdout
    bad = run_cli("--show", "rgw9")
    assert bad.returncode == 1
    assert bad.stderr.strip().startswith("neurosym envs: error: unknown environment 'rgw9'")
