"""Faithfulness: the untrained control, the held-out split, and the table printed beside the KB's facts."""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import torch

from neurosym.agent.agent import Agent
from neurosym.agent.networks.model import ActorCritic
from neurosym.envs import make
from neurosym.facts.tables import extract_facts
from neurosym.record.faithfulness import (
    CONTROL_SEED,
    ControlledAgent,
    acted_states,
    measure,
    record_control,
    split,
    trace_from_facts,
    untrained_agent,
)
from neurosym.record.recorder import record


@pytest.fixture(scope="module")
def trained(small_agent) -> Agent:  # noqa: ANN001
    """The small rgw2 agent with weights of another seed than the control's (a stand-in for training)."""
    agent = small_agent("rgw2")
    with torch.random.fork_rng():
        torch.manual_seed(CONTROL_SEED + 1)
        model = ActorCritic(agent.config).eval()
    return replace(agent, model=model)


OPTIONS = {"env": "rgw2", "episodes": 3, "seed": 4, "greedy": True}


def test_the_control_is_a_fresh_network_on_the_agents_very_states(trained: Agent) -> None:
    agent = trained
    control = untrained_agent(agent)
    with torch.random.fork_rng():
        torch.manual_seed(CONTROL_SEED)
        fresh = ActorCritic(agent.config).state_dict()
    mine, theirs = agent.model.state_dict(), control.model.state_dict()
    for name, value in control.model.state_dict().items():
        assert torch.equal(value, fresh[name]), name  # freshly initialised, seeded
    assert any(not torch.equal(mine[k], theirs[k]) for k in mine)  # not the agent's weights
    assert control.config == agent.config

    rec = record(agent, **OPTIONS)
    shown = record_control(agent, rec, **OPTIONS)
    agent_at = extract_facts(rec)["at"]
    control_at = extract_facts(shown)["at"]
    pd.testing.assert_frame_equal(agent_at, control_at)  # the same at/5 facts: the same states
    pd.testing.assert_frame_equal(rec.steps, shown.steps)  # the agent chose every action
    assert not rec.attends.equals(shown.attends)  # another network was introspected


def test_the_controlled_agent_acts_as_one_and_shows_the_other(trained: Agent) -> None:
    agent = trained
    control = untrained_agent(agent)
    both = ControlledAgent(agent, control)
    obs = np.stack([make("rgw2").reset(seed=s)[0] for s in range(8)])
    actions, intro = both.act(
        obs, greedy=False, introspect=True, generator=torch.Generator().manual_seed(3)
    )
    mine, _ = agent.act(obs, greedy=False, generator=torch.Generator().manual_seed(3))
    _, theirs = control.act(obs, introspect=True)
    _, own = agent.act(obs, introspect=True)
    assert actions.tolist() == mine.tolist()  # the same sampling draws: only the actor draws
    for got, want in zip(intro, theirs, strict=True):
        assert np.array_equal(got, want)
    assert not np.array_equal(intro.attention1, own.attention1)


@pytest.fixture(scope="module")
def scripted_facts(scripted_recording) -> tuple[object, object]:  # noqa: ANN001
    """The scripted routes' facts (contacts on every route but the timeout), twice: the
    second stands in for the control's, so its figures must be the relation figures."""
    rec = scripted_recording()
    assert len(rec.episodes) == 5
    return extract_facts(rec), extract_facts(rec)


def test_figures_count_held_out_episodes_only(scripted_facts) -> None:  # noqa: ANN001
    facts, control = scripted_facts
    got = measure(facts, control)
    episodes = list(range(5))  # the five scripted routes
    fit, test = split(episodes)
    assert (fit, test) == (episodes[:3], episodes[3:])  # ceil(0.3 * 5) = 2 held out
    trace = trace_from_facts(facts)
    acted = acted_states(trace)
    held_acted = int(acted["E"].isin(test).sum())
    from neurosym.induce.strategy_data import labels

    held_labelled = int(labels(trace)["E"].isin(test).sum())
    table = got.table
    assert set(table["episodes"]) == {2}
    for target, states in (("action", held_acted), ("next_object", held_labelled)):
        rows = table[table["target"] == target]
        assert rows["features"].tolist() == ["relations", "world", "untrained_relations", "chance"]
        assert set(rows["states"]) == {states}, target
    assert 0 < held_labelled < held_acted < len(acted)
    assert all(0.0 <= s <= 1.0 for s in table["score"])
    # the control's figures are the relation figures when its facts are the agent's own
    for target in ("action", "next_object"):
        assert got.score(target, "untrained_relations") == got.score(target, "relations")


def test_the_trace_in_memory_is_the_written_kbs(scripted_facts, tmp_path: Path) -> None:  # noqa: ANN001
    from neurosym.induce.strategy_data import load_trace

    facts, _ = scripted_facts
    facts.to_prolog(tmp_path / "kb.pl")
    read = load_trace(tmp_path / "kb.pl")
    mine = trace_from_facts(facts)
    for name in ("object", "at", "step", "event", "holding", "attends", "holds", "terrain", "grid"):
        a = getattr(mine, name).reset_index(drop=True)
        b = getattr(read, name).reset_index(drop=True)
        key = list(a.columns)
        a = a.sort_values(key, kind="stable").reset_index(drop=True)
        b = b[key].sort_values(key, kind="stable").reset_index(drop=True)
        pd.testing.assert_frame_equal(a, b, check_dtype=False, obj=name)
    for key in ("env", "module", "heads", "relations"):
        assert mine.meta[key] == read.meta[key], key


def _printed(stdout: str) -> dict[tuple[str, str], str]:
    """The printed faithfulness table: (target, column) -> cell."""
    lines = stdout.splitlines()
    start = next(
        i
        for i, line in enumerate(lines)
        if line.strip().startswith("target") and "untrained" in line
    )
    head = [c.strip() for c in re.split(r"[┃|]", lines[start])]
    cells = {}
    for line in lines[start + 2 :]:
        if "│" not in line:
            break
        row = [c.strip() for c in line.split("│")]
        for col, value in zip(head[1:], row[1:], strict=True):
            cells[(row[0], col)] = value
    return cells


def test_the_printed_table_is_the_kbs_facts(run_neurosym, small_checkpoint, tmp_path: Path) -> None:  # noqa: ANN001
    from neurosym.prolog.knowledge_base import KnowledgeBase

    ckpt = small_checkpoint(tmp_path / "small.pt", "predinet", 15, relations=3)
    out = tmp_path / "kb"
    proc = run_neurosym("extract", "--checkpoint", ckpt, "--episodes", 4, "--out", out)
    assert proc.returncode == 0, proc.stderr
    assert "faithfulness (held out: 2 of 4 episodes)" in proc.stdout
    printed = _printed(proc.stdout)
    with KnowledgeBase(out / "kb.pl") as kb:
        facts = kb.query_df("faithfulness(T, F, S, N, E)")
    assert len(facts) > 0 and set(facts["E"]) == {2}
    columns = {
        "relations": "relations",
        "world": "world",
        "untrained_relations": "untrained",
        "chance": "chance",
    }
    for t, f, s, n, _ in facts.itertuples(index=False):
        target = str(t).replace("_", " ")
        assert printed[(target, columns[str(f)])] == f"{s:.2f}"
        assert printed[(target, "states")] == str(n)
    assert len(printed) == 5 * len(set(facts["T"]))  # four figures and the states per target

    # the report page's section: the KB's facts (a page rebuilt from the recording re-extracts
    # facts without them, so they are read from kb.pl)
    from neurosym.reports.web.build import load_extract
    from neurosym.reports.web.tables import faithfulness_rows

    got = load_extract(out)
    assert got.facts["faithfulness"].empty
    rows = faithfulness_rows(got.facts, got.kb_path)
    kb_rows = {
        (str(t), str(f)): (float(s), int(n)) for t, f, s, n, _ in facts.itertuples(index=False)
    }
    for row in rows:
        target = row["target"].replace(" ", "_")
        names = ("relations", "world", "untrained_relations", "chance")
        for name, score in zip(names, row["scores"], strict=True):
            assert score == kb_rows.get((target, name), (None,))[0]
        assert row["states"] == kb_rows[(target, "chance")][1] and row["episodes"] == 2
    assert len(rows) == len(set(facts["T"]))


def test_no_faithfulness_measures_nothing(trained: Agent) -> None:
    from neurosym.record.extraction import extract

    got = extract(trained, episodes=2, seed=4, faithfulness=False)
    assert got.faithfulness is None and got.facts["faithfulness"].empty


def test_one_episode_has_no_figures_and_says_why(trained: Agent) -> None:
    from neurosym.record.faithfulness import faithfulness

    agent = trained
    options = {**OPTIONS, "episodes": 1}
    rec = record(agent, **options)
    got = faithfulness(agent, rec, extract_facts(rec), **options)
    assert got.table.empty
    assert got.notes == (
        "1 episode: faithfulness needs at least 2 (one to learn from, one to score on)",
    )
