"""The live state's facts equal what neurosym extract writes for the same recorded state.

The recorded actions are replayed through a PrologAgent's env; at every state
the facts it asserted (world and, for a strategy with ``features: both``,
the network's) are read back from its SWI-Prolog module and compared with
the fact tables of the recording.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from neurosym.agent.agent import load_agent
from neurosym.agent.evaluation import play_scored
from neurosym.envs.actions import ACTION_NAMES
from neurosym.facts.tables import extract_facts
from neurosym.play import PrologAgent
from neurosym.record.recorder import record

ROOT = Path(__file__).resolve().parents[2]
SEED = 40


def _strategy(tmp_path: Path, features: str) -> Path:
    path = tmp_path / "s.pl"
    path.write_text(f"%! features: {features}\ngoal(_, _, terminal).\n")
    return path


QUERIES = {
    "at": ("at(E, T, A, B, C)", ("A", "B", "C")),
    "holding": ("holding(E, T, A)", ("A",)),
    "step": ("step(E, T, A, B)", ("A", "B")),
    "event": ("event(E, T, A)", ("A",)),
    "holds": ("holds(E, T, r(A), B, C)", ("A", "B", "C")),
    "attends": ("attends(E, T, A, B, C, D, F, G)", ("A", "B", "C", "D", "F", "G")),
    "attention": ("attention(E, T, A, B, C, D)", ("A", "B", "C", "D")),
}
COLUMNS = {
    "at": ("id", "row", "col"),
    "holding": ("item",),
    "step": ("action", "reward"),
    "event": ("event",),
    "holds": ("j", "a", "b"),
    "attends": ("head", "arg", "entity", "row", "col", "weight"),
    "attention": ("head", "query", "key", "weight"),
}


def _rows(values: Any) -> list[tuple]:
    return sorted(tuple(round(v, 5) if isinstance(v, float) else v for v in row) for row in values)


def _live(agent: PrologAgent, e: int, t: int) -> dict[str, list[tuple]]:
    out = {}
    for name, (goal, cols) in QUERIES.items():
        rows = agent.kb.query(goal, E=e, T=t - 1 if name in ("step", "event") else t)
        out[name] = _rows(
            tuple(r[c] if isinstance(r[c], int | float) else str(r[c]) for c in cols) for r in rows
        )
    return out


def _kb_rows(tables: dict, name: str, e: int, t: int) -> list[tuple]:
    df = tables[name]
    df = df[(df["episode"] == e) & (df["t"] == t)]
    cols = [df[c].to_numpy() for c in COLUMNS[name]]
    return _rows(
        tuple(v.item() if hasattr(v, "item") else str(v) for v in row)
        for row in zip(*cols, strict=True)
    )


@pytest.mark.parametrize(
    ("checkpoint", "env"),
    [
        ("rgw-random-predinet-cellkeys", "rgw-random"),
        pytest.param(
            "bw1-mhdpa", "bw1", marks=pytest.mark.expensive
        ),  # 16 s: attention of every cell
    ],
)
def test_live_facts_equal_the_extracted_ones(tmp_path: Path, checkpoint: str, env: str) -> None:
    network = load_agent(ROOT / "checkpoints" / f"{checkpoint}.pt")
    rec = record(network, env, episodes=2, seed=SEED)
    facts = extract_facts(rec)
    tables = facts.tables
    actions = {
        (int(e), int(t)): ACTION_NAMES.index(a)
        for e, t, a in zip(rec.steps["episode"], rec.steps["t"], rec.steps["action"], strict=True)
    }
    thresholds = {int(j): float(v) for j, v in facts.thresholds().items()}
    seen: list[tuple[int, int]] = []
    mismatches: list[str] = []
    with PrologAgent(_strategy(tmp_path, "both"), network, thresholds=thresholds) as agent:

        def replay(obs: np.ndarray, venv: Any) -> np.ndarray:
            agent.act(obs, venv)  # asserts the state's facts; its own choice is not played
            out = np.zeros(len(obs), dtype=np.int64)
            for i in np.flatnonzero(venv.running):
                e, t = int(venv.episode[i]), int(venv.t[i])
                seen.append((e, t))
                live = _live(agent, e, t)
                for name in QUERIES:
                    expected = _kb_rows(tables, name, e, t - 1 if name in ("step", "event") else t)
                    if name in ("step", "event") and t == 0:
                        expected = []
                    if live[name] != expected:
                        mismatches.append(f"{name} at ({e}, {t}): {live[name]} != {expected}")
                out[i] = actions[(e, t)]
            return out

        kwargs = rec.meta["env_kwargs"]  # the checkpoint's env options (rgw-random: num_mountains)
        play_scored(
            replay, lambda n: agent.make_venv(env, n, SEED, **kwargs), 2, SEED, levels=False
        )
        objects = sorted((r["I"], str(r["Ty"])) for r in agent.kb.query("object(I, Ty)"))
    assert not mismatches, "\n".join(mismatches[:3])
    assert len(seen) == len(actions)  # every state the agent acted in
    assert objects == sorted(zip(tables["object"]["id"], tables["object"]["type"], strict=True))


def test_terrain_and_grid_equal_the_extracted_ones(tmp_path: Path) -> None:
    network = load_agent(ROOT / "checkpoints" / "rgw-random-predinet-cellkeys.pt")
    rec = record(network, "rgw-random", episodes=1, seed=SEED)
    tables = extract_facts(rec).tables
    with PrologAgent(_strategy(tmp_path, "world")) as agent:
        venv = agent.make_venv("rgw-random", 1, SEED, **rec.meta["env_kwargs"])
        venv.reset(seed=[SEED])
        terrain = sorted(
            (str(r["Ty"]), r["R"], r["C"]) for r in agent.kb.query("terrain(0, Ty, R, C)")
        )
        grid = agent.kb.query("grid(0, R, C)")
        venv.close()
    kb_terrain = tables["terrain"]
    assert terrain == sorted(
        zip(kb_terrain["type"], kb_terrain["row"], kb_terrain["col"], strict=True)
    )
    assert len(terrain) > 10
    assert [(g["R"], g["C"]) for g in grid] == [
        (int(r), int(c))
        for r, c in zip(tables["grid"]["rows"], tables["grid"]["cols"], strict=True)
    ]
