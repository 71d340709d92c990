"""``neurosym probe``, ``neurosym intervene`` and ``neurosym plot probes`` run for real on shipped agents."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pandas as pd
import pytest

REPO = Path(__file__).resolve().parents[2]
RULES = REPO / "rules"


def loads(swipl: Path, *files: Path) -> None:
    """Real SWI-Prolog loads the files without a word."""
    proc = subprocess.run(
        [swipl, "-q", "-g", "halt", *files], capture_output=True, text=True, timeout=120
    )
    assert (proc.returncode, proc.stdout, proc.stderr) == (0, "", ""), proc.stderr


def test_probe_writes_a_kb_the_table_and_json(run_neurosym, tmp_path: Path, swipl: Path) -> None:
    out = tmp_path / "probe"
    proc = run_neurosym(
        "probe", "--checkpoint", REPO / "checkpoints" / "rgw1-predinet.pt",
        "--episodes", 6, "--seed", 3, "--out", out, "--json",
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    rows = [json.loads(line) for line in proc.stdout.splitlines()]
    assert rows, "no probes"
    for key in ("head", "relation", "predicate", "accuracy", "control", "selectivity"):
        assert key in rows[0]
    table = pd.read_parquet(out / "probes.parquet")
    assert len(table) == len(rows)
    assert set(table["relation"]) == {*map(str, range(8)), "all"}
    skipped = pd.read_parquet(out / "probes_skipped.parquet")
    assert not set(skipped["predicate"]) & set(table["predicate"])
    text = (out / "kb.pl").read_text()
    assert text.count("\nprobe(") == len(table)
    assert "probe_skipped(" in text
    loads(swipl, out / "kb.pl", RULES / "meaning.pl")

    picture = tmp_path / "probes.png"
    drawn = run_neurosym("plot", "probes", "--probe", out, "--out", picture)
    assert drawn.returncode == 0, drawn.stderr
    assert picture.read_bytes()[:4] == b"\x89PNG"


def test_intervene_writes_experiments_effects_and_the_causal_answer(
    run_neurosym, tmp_path: Path, swipl: Path
) -> None:
    from neurosym.prolog.knowledge_base import KnowledgeBase

    out = tmp_path / "intervene"
    proc = run_neurosym(
        "intervene", "--checkpoint", REPO / "checkpoints" / "rgw2-predinet.pt",
        "--episodes", 3, "--out", out,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "sword_enemy_cause: " in proc.stdout
    kb_path = out / "kb.pl"
    loads(swipl, kb_path, RULES / "causal.pl")
    with KnowledgeBase(kb_path, rules=[RULES / "causal.pl"]) as kb:
        found = kb.query("experiment(X, K, _), format(atom(T), '~q', [K])")
        ids, kinds = [r["X"] for r in found], [str(r["T"]) for r in found]
        assert kinds[0] == "baseline"
        for kind in ("remove(sword)", "remove(enemy)", "swap(sword,enemy)"):
            assert kind in kinds
        assert sum(k.startswith("move(enemy,") for k in kinds) == 1
        assert sum(k.startswith("move(sword,") for k in kinds) == 1
        assert "ablate(head(0))" in kinds and "ablate(heads)" in kinds
        pairs = kb.query("experiment_episode(X, E)")
        episodes = [r["E"] for r in pairs]
        assert len(episodes) == len(set(episodes)) == 3 * len(kinds)
        assert kb.count("episode(_, _, _, _)") == len(episodes)
        assert {r["E"] for r in pairs if r["X"] == "baseline"} == {0, 1, 2}
        assert kb.count("effect(remove_sword, kl, _)") == 1
        assert kb.count("effect(ablate_head_1, relation_shift(1, _), _)") == 8
        answer = kb.query("sword_enemy_cause(A)")
        assert len(answer) == 1
    effects = pd.read_parquet(out / "effects.parquet")
    assert set(effects["experiment"]) == set(ids) - {"baseline"}
    # ablating a head changes only that head's vector at the baseline's states
    shift = effects[effects["measure"].str.startswith("relation_shift(")]
    ab0 = shift[shift["experiment"] == "ablate_head_0"]
    others = ab0[~ab0["measure"].str.startswith("relation_shift(0,")]
    assert (others["value"] == 0).all() and (ab0["value"] > 0).any()


def test_intervene_ablates_mhdpa_heads(run_neurosym, tmp_path: Path, swipl: Path) -> None:
    out = tmp_path / "mhdpa"
    proc = run_neurosym(
        "intervene", "--checkpoint", REPO / "checkpoints" / "rgw1-mhdpa.pt",
        "--episodes", 2, "--no-levels", "--out", out, "--json",
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    rows = [json.loads(line) for line in proc.stdout.splitlines()]
    shifts = {
        (r["experiment"], r["measure"]): r["value"] for r in rows if "head_shift" in r["measure"]
    }
    assert shifts[("ablate_head_2", "head_shift(2)")] > 0
    assert shifts[("ablate_head_2", "head_shift(0)")] == 0
    loads(swipl, out / "kb.pl", RULES / "causal.pl")


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["probe", "--episodes", "1"], "--episodes must be at least 2"),
        (["intervene", "--episodes", "0"], "--episodes must be at least 1"),
        (["intervene", "--env-option", "bogus=1"], "unknown option 'bogus' for rgw2; expected"),
        (["probe", "--env-option", "max_steps"], "--env-option wants KEY=VALUE"),
        (
            ["intervene", "--env", "rgw-random", "--env-option", "edit=remove_sword"],
            "--env-option edit=remove_sword: intervene makes the level edits itself",
        ),  # fmt: skip
        (["probe", "--env-option", "classic=maybe"], "classic takes true or false"),
    ],
)
def test_bad_input_is_one_line(run_neurosym, tmp_path: Path, args: list[str], message: str) -> None:
    out = tmp_path / "x"
    proc = run_neurosym(*args[:1], "--checkpoint", REPO / "checkpoints" / "rgw2-predinet.pt",
                        *args[1:], "--out", out)  # fmt: skip
    assert proc.returncode == 1
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], proc.stderr
    assert not out.exists()


def test_env_options_reach_the_played_env() -> None:
    """intervene and probe play --env (default: the agent's own) with --env-option on top, checked."""
    from neurosym.agent.agent import load_agent
    from neurosym.cli import agent_env
    from neurosym.errors import ConfigError
    from neurosym.record.recorder import record

    agent = load_agent(REPO / "checkpoints" / "rgw2-predinet.pt")
    assert agent_env(agent, None, []) == ("rgw2", agent.env_kwargs)
    name, capped = agent_env(agent, None, ["max_steps=3"])
    assert capped == {**agent.env_kwargs, "max_steps": 3}
    assert agent.env_kwargs.get("max_steps") != 3  # the loaded agent is left as it was
    rec = record(agent, name, episodes=2, seed=0, greedy=True, env_kwargs=capped)
    assert rec.meta["env_kwargs"]["max_steps"] == 3
    assert int(rec.episodes["steps"].max()) <= 3  # its episodes end at 3 steps
    with pytest.raises(ConfigError, match="num_mountains"):
        agent_env(agent, None, ["num_mountains=12"])  # rgw2 takes no level parameters
    cellkeys = load_agent(REPO / "checkpoints" / "rgw-random-predinet-cellkeys.pt")
    # another env of the family: its options, not the agent's own (num_mountains=12) nor lost
    assert agent_env(cellkeys, "rgw2", ["max_steps=3"]) == ("rgw2", {"max_steps": 3})
    with pytest.raises(ConfigError, match="unknown option 'num_mountains' for rgw2"):
        agent_env(cellkeys, "rgw2", ["num_mountains=12"])


@pytest.mark.parametrize(
    ("checkpoint", "env"),
    [("rgw-random-predinet-cellkeys.pt", "rgw2"), ("rgw2-predinet.pt", "rgw1")],
)
def test_intervene_changes_the_level_of_the_env_asked_for(checkpoint: str, env: str) -> None:
    """On another env than the agent's, every level change is played (the sword removed is
    never picked up), not the unchanged level under the change's name."""
    from neurosym.agent.agent import load_agent
    from neurosym.meaning.intervene import intervene

    agent = load_agent(REPO / "checkpoints" / checkpoint)
    report = intervene(agent, env, episodes=3, ablations=False)
    m = report.measures.pivot(index="experiment", columns="measure", values="value")
    assert report.meta["env"] == env
    assert m.loc["baseline", "sword_picked"] == 1.0
    assert m.loc["remove_sword", "sword_picked"] == 0.0
    assert m.loc["remove_enemy", "enemy_met"] == 0.0
    for rec in report.recordings.values():
        assert rec.meta["env"] == env


def test_probe_plays_env_options_on_another_env(run_neurosym, tmp_path: Path) -> None:
    """probe --env rgw2 --env-option max_steps=3 of an rgw-random agent: 3-step episodes on
    rgw2; paths print as text."""
    out = tmp_path / "p\x1b[31m"
    proc = run_neurosym(
        "probe", "--checkpoint", REPO / "checkpoints" / "rgw-random-predinet-cellkeys.pt",
        "--env", "rgw2", "--env-option", "max_steps=3", "--episodes", 4, "--no-untrained",
        "--out", out,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    first = proc.stdout.splitlines()[0]
    assert first.startswith("rgw2 predinet: 4 episodes") and "12 states" in first, first
    assert "\x1b" not in proc.stdout and "p\\e[31m" in proc.stdout
