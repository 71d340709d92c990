"""record(): the trace against a fresh single env, the model outputs against the model, the shapes."""

from __future__ import annotations

from functools import cache

import numpy as np
import pandas as pd
import pytest
import torch
from builders import SMALL_MAX_STEPS as MAX_STEPS
from builders import small_agent

from neurosym.envs import ACTION_NAMES, make
from neurosym.errors import CheckpointError, ConfigError
from neurosym.record.recorder import record
from neurosym.record.recording import Recording


@cache
def recorded(
    env: str, module: str = "predinet", greedy: bool = False, batch: int = 4, episodes: int = 6
) -> Recording:
    return record(
        small_agent(env, module), env, episodes=episodes, seed=11, greedy=greedy, batch=batch
    )


def state_positions(info: dict) -> list[tuple[str, str, int, int]]:
    objs = [tuple(o) for o in info["objects"]]
    if not objs or objs[0][0] != "agent":
        objs.insert(0, ("agent", "agent", *info["agent"]))
    return [(str(i), str(t), int(r), int(c)) for i, t, r, c in objs]


def table_rows(df: pd.DataFrame, episode: int, t: int, cols: list[str]) -> list[tuple]:
    sel = df[(df["episode"] == episode) & (df["t"] == t)]
    return [tuple(r) for r in sel[cols].itertuples(index=False)]


@pytest.mark.parametrize("env", ["rgw2", "bw2"])
def test_trace_replays_in_a_fresh_single_env(env: str) -> None:
    """Replaying the recorded actions from reset(seed) gives the recorded positions, events, rewards."""
    rec = recorded(env)
    action_index = {name: i for i, name in enumerate(ACTION_NAMES)}
    assert len(rec.episodes) == 6
    for ep in rec.episodes.itertuples(index=False):
        e = int(ep.episode)
        single = make(env, max_steps=MAX_STEPS)
        obs, info = single.reset(seed=int(ep.seed))
        assert table_rows(rec.positions, e, 0, ["object", "type", "row", "col"]) == state_positions(
            info
        ), f"[{e}/0]"
        steps = rec.steps[rec.steps["episode"] == e].sort_values("t")
        assert steps["t"].tolist() == list(range(int(ep.steps)))
        total = 0.0
        for t, action, reward in steps[["t", "action", "reward"]].itertuples(index=False):
            obs, r, terminated, truncated, info = single.step(action_index[action])
            total += r
            assert r == reward, f"[{e}/{t}] reward"
            assert [ev for (ev,) in table_rows(rec.events, e, t, ["event"])] == list(
                info["events"]
            ), f"[{e}/{t}]"
            assert table_rows(
                rec.positions, e, t + 1, ["object", "type", "row", "col"]
            ) == state_positions(info), f"[{e}/{t + 1}] positions"
            assert [i for (i,) in table_rows(rec.holding, e, t + 1, ["item"])] == list(
                info["holding"]
            ), f"[{e}/{t + 1}]"
            assert (terminated or truncated) == (t == ep.steps - 1), f"[{e}/{t}] episode end"
        assert info["outcome"] == ep.outcome
        assert total == pytest.approx(ep._2)  # the return column


def test_model_outputs_match_the_model_on_replayed_states() -> None:
    """attends/relations/r_vectors are the model's own introspection of the replayed observations."""
    env = "rgw2"
    rec = recorded(env)
    agent = small_agent(env)
    names = make(env).unwrapped.entity_names
    action_index = {name: i for i, name in enumerate(ACTION_NAMES)}
    e = int(rec.episodes["episode"].iloc[1])
    single = make(env, max_steps=MAX_STEPS)
    obs, _ = single.reset(seed=int(rec.episodes["seed"].iloc[1]))
    W = single.unwrapped.entity_grid().shape[1]
    actions = rec.steps[rec.steps["episode"] == e].sort_values("t")["action"].tolist()
    for t, action in enumerate(actions):
        grid = single.unwrapped.entity_grid().reshape(-1)
        _, intro = agent.act(obs[None], greedy=True, introspect=True)
        for h in range(agent.config.heads):
            for arg, att in ((1, intro.attention1), (2, intro.attention2)):
                k = int(np.argmax(att[0, h]))
                row = rec.attends[
                    (rec.attends.episode == e)
                    & (rec.attends.t == t)
                    & (rec.attends["head"] == h)
                    & (rec.attends.arg == arg)
                ]
                assert len(row) == 1
                got = row.iloc[0]
                assert (got.entity, got.row, got.col) == (names[grid[k]], k // W, k % W), (
                    f"[{t}] head {h} arg {arg}"
                )
                assert got.weight == pytest.approx(float(att[0, h, k]), rel=1e-5)
            rel = rec.relations[
                (rec.relations.episode == e) & (rec.relations.t == t) & (rec.relations["head"] == h)
            ]
            np.testing.assert_allclose(
                rel.sort_values("j")["value"].to_numpy(),
                intro.relations[0, h],
                rtol=1e-5,
                atol=1e-7,
            )
            rv = rec.r_vectors[
                (rec.r_vectors.episode == e) & (rec.r_vectors.t == t) & (rec.r_vectors["head"] == h)
            ]
            np.testing.assert_allclose(
                rv.sort_values("j")["value"].to_numpy(),
                intro.r_vectors()[0, h],
                rtol=1e-5,
                atol=1e-7,
            )
        obs, *_ = single.step(action_index[action])


def test_table_shapes_follow_the_time_convention() -> None:
    rec = recorded("rgw2")
    H, J = 2, 3
    acted = int(rec.episodes["steps"].sum())
    assert len(rec.steps) == acted
    assert len(rec.attends) == acted * H * 2
    assert len(rec.relations) == acted * H * J
    assert len(rec.r_vectors) == acted * H * (J + 4)
    last_t = rec.positions.groupby("episode")["t"].max()
    assert (last_t == rec.episodes.set_index("episode")["steps"]).all()  # states 0..S
    assert (
        rec.attends.groupby("episode")["t"]
        .max()
        .add(1)
        .equals(rec.episodes.set_index("episode")["steps"])
    )
    # the first J components of R^h are D^h
    rv = rec.r_vectors[rec.r_vectors.j < J].reset_index(drop=True)
    assert np.array_equal(rv["value"].to_numpy(), rec.relations["value"].to_numpy())
    assert rec.meta["env"] == "rgw2" and rec.meta["heads"] == H and rec.meta["relations"] == J
    assert rec.meta["checkpoint"] == "random.pt" and rec.meta["seed"] == 11


def test_greedy_recording_does_not_depend_on_the_batch() -> None:
    a = recorded("bw2", greedy=True, batch=2, episodes=5)
    b = recorded("bw2", greedy=True, batch=5, episodes=5)
    for name, table in a.tables.items():
        pd.testing.assert_frame_equal(table, b.tables[name], obj=name)
    assert a.episodes["seed"].tolist() == [11, 12, 13, 14, 15]


def test_mhdpa_attention_table() -> None:
    rec = recorded("rgw2", module="mhdpa")
    assert rec.relations.empty and rec.attends.empty
    att = rec.attention
    assert not att.empty
    assert not att["query"].isin(["empty", "wall"]).any()
    assert att["weight"].between(0, 1).all()
    # one strongest key per (state, head, query cell)
    assert not att.duplicated(["episode", "t", "head", "query_row", "query_col"]).any()
    per_state = att.groupby(["episode", "t", "head"]).size()
    assert per_state.nunique() <= 2  # the agent's cell changes what it covers, little else
    assert rec.meta["module"] == "mhdpa" and rec.meta["relations"] == 0


def test_torch_threads_are_restored() -> None:
    before = torch.get_num_threads()
    record(small_agent("rgw2"), "rgw2", episodes=1, threads=1)
    assert torch.get_num_threads() == before


def test_env_of_another_family_or_shape_is_refused() -> None:
    with pytest.raises(CheckpointError, match=r"bw1 is a boxworld environment"):
        record(small_agent("rgw2"), "bw1", episodes=1)
    with pytest.raises(
        CheckpointError, match=r"observations \(9, 10, 10\); rgw2 .* gives \(9, 2, 3\)"
    ):
        record(small_agent("rgw2"), "rgw2", episodes=1, env_kwargs={"map": "AET\nS..\n"})


def test_an_agent_records_on_other_envs_of_its_family() -> None:
    rec = record(small_agent("rgw2"), "rgw-random", episodes=2, seed=4)
    assert rec.meta["env"] == "rgw-random" and len(rec.episodes) == 2
    rec = record(small_agent("rgw2"), "rgw1", episodes=1)
    assert rec.meta["env"] == "rgw1" and rec.meta["env_kwargs"] == {}


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"episodes": 0}, "episodes must be a positive integer"),
        ({"seed": -1}, r"seed must be an integer from 0 to \d+ .*got -1"),
        (
            {"seed": 2**63 - 1, "episodes": 2},
            r"seed must be an integer from 0 to 9223372036854775806 "
            r"with 2 episodes \(episode k plays seed SEED \+ k",
        ),
        ({"batch": 0}, "batch must be a positive integer"),
        ({"threads": 0}, "threads must be a positive integer or None"),
    ],
)
def test_bad_arguments(kwargs: dict, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        record(small_agent("rgw2"), "rgw2", **kwargs)
