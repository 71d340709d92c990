"""terrain/grids tables and grid/3, terrain/4 facts; random actions in record()."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from neurosym.envs import make
from neurosym.errors import ConfigError
from neurosym.facts.tables import extract_facts
from neurosym.record.recorder import random_actions, record
from neurosym.record.recording import Recording


@pytest.mark.parametrize("env", ["rgw-random", "bw2"])
def test_terrain_is_the_reset_grid_less_objects_agent_and_empty(small_agent, env: str) -> None:
    rec = record(small_agent(env), env, episodes=3, seed=5, batch=2, env_kwargs={"max_steps": 5})
    for ep in rec.episodes.itertuples(index=False):
        single = make(env, max_steps=5)
        _, info = single.reset(seed=int(ep.seed))
        names = np.asarray(single.unwrapped.entity_names, dtype=object)[
            single.unwrapped.entity_grid()
        ]
        objects = {(r, c) for _, _, r, c in info["objects"]} | {tuple(info["agent"])}
        want = sorted(
            (str(names[r, c]), r, c)
            for r in range(names.shape[0])
            for c in range(names.shape[1])
            if names[r, c] not in ("empty", "agent") and (r, c) not in objects
        )
        got = rec.terrain[rec.terrain["episode"] == ep.episode]
        assert sorted(zip(got["type"], got["row"], got["col"], strict=True)) == want
        assert want, "every map has terrain (walls)"
        grid = rec.grids[rec.grids["episode"] == ep.episode]
        assert grid[["rows", "cols"]].values.tolist() == [list(names.shape)]


def test_a_recording_saved_without_terrain_or_grids_still_loads(small_agent, tmp_path: Path) -> None:
    rec = record(small_agent("rgw2"), "rgw2", episodes=2, seed=0, env_kwargs={"max_steps": 5})
    rec.save(tmp_path / "rec")
    (tmp_path / "rec" / "terrain.parquet").unlink()
    (tmp_path / "rec" / "grids.parquet").unlink()
    old = Recording.load(tmp_path / "rec")
    assert old.terrain.empty and old.grids.empty
    assert list(old.terrain.columns) == ["episode", "type", "row", "col"]
    assert old.steps.equals(rec.steps)


def test_grid_and_terrain_facts_load_in_prolog(small_agent, tmp_path: Path) -> None:
    from neurosym.prolog.knowledge_base import KnowledgeBase

    rec = record(small_agent("rgw2"), "rgw2", episodes=2, seed=0, env_kwargs={"max_steps": 5})
    path = extract_facts(rec).to_prolog(tmp_path / "kb.pl")
    text = path.read_text()
    assert ":- dynamic grid/3." in text and ":- dynamic terrain/4." in text
    with KnowledgeBase(path) as kb:
        assert kb.query("grid(0, R, C)") == [
            dict(zip("RC", rec.grids.iloc[0, 1:].tolist(), strict=True))
        ]
        walls = kb.query("terrain(0, wall, R, C)")
        assert len(walls) == int(((rec.terrain.episode == 0) & (rec.terrain.type == "wall")).sum())
        assert kb.query("kb_meta(actions, A)") == [{"A": "agent"}]


def test_random_actions_are_reproducible_uniform_and_batch_independent(small_agent) -> None:
    seeds = np.arange(1000)
    draws = np.stack([random_actions(seeds, t) for t in range(40)])
    counts = np.bincount(draws.ravel(), minlength=4) / draws.size
    assert np.all(np.abs(counts - 0.25) < 0.01)
    assert np.array_equal(random_actions(seeds[500:], 7), draws[7, 500:])
    agent = small_agent("rgw-random")
    kwargs = {"max_steps": 30}
    a = record(agent, "rgw-random", 5, seed=2, batch=5, actions="random", env_kwargs=kwargs)
    b = record(agent, "rgw-random", 5, seed=2, batch=2, actions="random", env_kwargs=kwargs)
    assert a.steps.equals(b.steps) and a.positions.equals(b.positions)
    # the model's values differ in the last bits between batch sizes, nothing else does
    assert a.relations.drop(columns="value").equals(b.relations.drop(columns="value"))
    assert np.allclose(a.relations["value"], b.relations["value"], atol=1e-5)
    assert a.meta["actions"] == "random"
    assert not a.relations.empty  # the network still ran on every state
    greedy = record(agent, "rgw-random", 5, seed=2, batch=5, env_kwargs=kwargs)
    assert not greedy.steps["action"].equals(a.steps["action"])


def test_unknown_action_source_is_refused(small_agent) -> None:
    with pytest.raises(ConfigError, match="actions must be one of agent, random"):
        record(small_agent("rgw2"), "rgw2", 1, actions="greedy")
