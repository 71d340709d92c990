"""The shipped files: rule files and agents found by bare name, the agents' cards, `neurosym agents`."""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

import pytest
import torch

from neurosym.agent.agent import load_agent
from neurosym.errors import CheckpointError, ConfigError

REPO = Path(__file__).resolve().parents[2]
CHECKPOINTS = REPO / "checkpoints"


def test_rule_files_and_agents_by_bare_name(tmp_path: Path, monkeypatch) -> None:
    from neurosym.shipped import checkpoint_file, rule_file, rules_dir, shipped_rule_names

    assert rules_dir() == REPO / "rules"
    assert shipped_rule_names() == ["boxworld", "causal", "meaning", "minigrid", "relations", "rgw", "route"]
    monkeypatch.chdir(tmp_path)
    assert rule_file("rgw") == REPO / "rules" / "rgw.pl"
    assert rule_file("boxworld.pl") == REPO / "rules" / "boxworld.pl"
    assert rule_file("mine.pl") == Path("mine.pl")  # not there: the loader says so
    with pytest.raises(
        ConfigError, match=r"no rule file 'rgx'.*\(boxworld, causal, meaning, minigrid, relations, rgw, route\)"
    ):
        rule_file("rgx")
    (tmp_path / "rgw").write_text("my_rule.\n")  # a file of the user's wins over the shipped name
    assert rule_file("rgw") == Path("rgw")
    assert checkpoint_file("rgw2-predinet") == CHECKPOINTS / "rgw2-predinet.pt"
    assert checkpoint_file("rgw2-predinet.pt") == CHECKPOINTS / "rgw2-predinet.pt"
    assert checkpoint_file("rgw9-predinet") == Path("rgw9-predinet")
    agent = load_agent("rgw-random-mhdpa")
    assert agent.path == str(CHECKPOINTS / "rgw-random-mhdpa.pt") and agent.config.module == "mhdpa"
    with pytest.raises(CheckpointError, match="checkpoint not found: rgw9-predinet"):
        load_agent("rgw9-predinet")


def test_a_knowledge_base_loads_a_shipped_rule_file_by_name(tmp_path: Path) -> None:
    from neurosym.prolog.knowledge_base import KnowledgeBase

    kb = tmp_path / "kb.pl"
    kb.write_text("episode(0, 3, 11.0, terminal).\nevent(0, 1, picked(sword)).\n"
                  "event(0, 2, defeated(enemy)).\n")  # fmt: skip
    with KnowledgeBase(kb, rules=["rgw", "relations"]) as base:
        assert [row["E"] for row in base.query("sword_before_enemy(E)")] == [0]


def test_query_takes_a_shipped_rule_file_by_name(run_neurosym, tmp_path: Path) -> None:
    kb = tmp_path / "kb.pl"
    kb.write_text("episode(0, 3, 11.0, terminal).\nevent(0, 1, picked(sword)).\n"
                  "event(0, 2, defeated(enemy)).\n")  # fmt: skip
    proc = run_neurosym("query", "--kb", kb, "--rules", "rgw", "--csv",
                        "sword_before_enemy(E)")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == "E\n0\n"
    proc = run_neurosym("query", "--kb", kb, "--rules", "rgx", "true")
    assert proc.returncode == 1
    assert proc.stderr.startswith("neurosym query: error: no rule file 'rgx': give a .pl file")


def test_write_card_keeps_the_weights_and_the_agent_replays(tmp_path: Path, play_one_episode) -> None:
    """A card written into a copy of a shipped agent: every other entry and every weight as they
    were, and the agent still plays rgw2 by the optimal route."""
    from neurosym.cards import write_card

    path = tmp_path / "agent.pt"
    shutil.copy(CHECKPOINTS / "rgw2-predinet.pt", path)
    before = torch.load(path, weights_only=True)
    card = {"role": "a test", "eval_command": "neurosym eval ...",
            "held_out": {"env": "rgw-random", "sampled": {"success_rate": 0.5},
                         "greedy": {"success_rate": 0.25}}}  # fmt: skip
    write_card(path, card)
    after = torch.load(path, weights_only=True)
    assert after.pop("card") == card
    before.pop("card", None)
    assert before.keys() == after.keys()
    for key in before["state_dict"]:
        assert torch.equal(before["state_dict"][key], after["state_dict"][key]), key
        assert before["state_dict"][key].dtype == after["state_dict"][key].dtype
    assert {k: v for k, v in before.items() if k != "state_dict"} == {
        k: v for k, v in after.items() if k != "state_dict"
    }
    assert load_agent(path).meta["card"] == card
    route = ["picked(sword)", "teleported", "defeated(enemy)", "reached(terminal)"]
    total, events, _ = play_one_episode(path, route)
    assert events == route and total == pytest.approx(10.7)
    with pytest.raises(CheckpointError, match="held_out.greedy.success_rate must be in"):
        write_card(
            path, {**card, "held_out": {**card["held_out"], "greedy": {"success_rate": 2.0}}}
        )
    with pytest.raises(CheckpointError, match="lacks role"):
        write_card(path, {"eval_command": "", "held_out": {}})
    assert load_agent(path).meta["card"] == card  # a refused card changes nothing


def test_every_shipped_agent_carries_its_card() -> None:
    """The cards in the files are the ones scripts/write_cards.py writes (its --check passes)."""
    sys.path.insert(0, str(REPO / "scripts"))
    try:
        import write_cards
    finally:
        sys.path.remove(str(REPO / "scripts"))
    shipped = sorted(p.stem for p in CHECKPOINTS.glob("*.pt"))
    assert sorted(write_cards.CARDS) == shipped
    for name in shipped:
        assert torch.load(CHECKPOINTS / f"{name}.pt", weights_only=True)[
            "card"
        ] == write_cards.card(name)
    assert write_cards.main(["--check"]) == 0


def test_learner_from_the_train_config_or_the_command() -> None:
    from neurosym.cards import learner

    assert learner({"train_config": {"algo": "imitate"}, "command": ""}) == "imitate"
    assert (
        learner({"train_config": None, "command": "neurosym train --env rgw2 --module predinet"})
        == "a3c"
    )
    cmd = "neurosym train --env rgw2 --algo ppo && neurosym compact a.pt --out a.pt"
    assert learner({"train_config": None, "command": cmd}) == "ppo"


def test_agents_lists_the_shipped_agents(run_neurosym) -> None:
    proc = run_neurosym("agents", "--json")
    assert proc.returncode == 0, proc.stderr
    agents = {a["name"]: a for a in json.loads(proc.stdout)}
    assert sorted(agents) == sorted(p.stem for p in CHECKPOINTS.glob("*.pt"))
    cellkeys = agents["rgw-random-predinet-cellkeys"]
    assert cellkeys["file"] == str(CHECKPOINTS / "rgw-random-predinet-cellkeys.pt")
    assert (cellkeys["env"], cellkeys["module"], cellkeys["learner"]) == (
        "rgw-random",
        "predinet",
        "imitate",
    )
    assert cellkeys["env_options"] == {"num_mountains": 12} and cellkeys["frames"] == 1_399_959
    assert cellkeys["card"]["held_out"]["sampled"]["success_rate"] == 0.987
    assert agents["rgw2-predinet"]["learner"] == "a3c"
    proc = run_neurosym("agents")
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[0] == "agents"
    assert lines[1].split() == ["agent", "env", "module", "learner", "frames", "held", "out", "for"]
    row = next(ln for ln in lines if ln.split()[:1] == ["rgw-random-predinet-cellkeys"])
    assert row.split()[:7] == ["rgw-random-predinet-cellkeys", "rgw-random", "predinet", "imitate",
                               "1.4", "M", "98.7/92.3"]  # fmt: skip
    assert lines[-2].startswith("held out: success in % on 300 levels")


def test_agents_in_a_folder_of_ones_own(neurosym_main, tmp_path: Path) -> None:
    shutil.copy(CHECKPOINTS / "rgw1-mhdpa.pt", tmp_path / "mine.pt")
    (tmp_path / "broken.pt").write_bytes(b"not a checkpoint")
    proc = neurosym_main("agents", "--dir", tmp_path, "--json")
    assert proc.returncode == 0, proc.stderr
    assert [a["name"] for a in json.loads(proc.stdout)] == ["mine"]
    assert proc.stderr.startswith("neurosym agents: skipped broken.pt: cannot read")
    proc = neurosym_main("agents", "--dir", tmp_path / "nowhere")
    assert proc.returncode == 1
    assert proc.stderr == f"neurosym agents: error: --dir {tmp_path / 'nowhere'}: no such folder\n"
    empty = tmp_path / "empty"
    empty.mkdir()
    proc = neurosym_main("agents", "--dir", empty)
    assert proc.stderr == f"neurosym agents: error: no agents (*.pt files) in {empty}\n"


def test_compact_takes_a_shipped_agent_by_name_and_drops_its_card(tmp_path: Path) -> None:
    """The card's figures were measured on the float32 weights, not on the compacted ones."""
    from neurosym.agent.checkpoint import compact_checkpoint

    out = tmp_path / "small.pt"
    compact_checkpoint("rgw2-mhdpa", out)
    assert "card" in load_agent("rgw2-mhdpa").meta
    small = load_agent(out)
    assert "card" not in small.meta and small.meta["weights_dtype"] == "float16"
    assert small.meta["command"].endswith(
        f"neurosym compact {CHECKPOINTS / 'rgw2-mhdpa.pt'} --out {out} --dtype float16"
    )
