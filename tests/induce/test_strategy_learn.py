"""Learning a known strategy from generated KBs, and the learned file in real SWI-Prolog."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest
from strategy_kbs import nearest_key_kb

from neurosym.errors import ConfigError
from neurosym.induce.strategy import induce_strategy
from neurosym.induce.strategy_data import load_trace

ROUTE = Path(__file__).resolve().parents[2] / "rules" / "route.pl"
"""rules/route.pl, whose route_moves/4 a learned file's route features call"""


@pytest.fixture(scope="module")
def kbs(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    folder = tmp_path_factory.mktemp("kbs")
    return nearest_key_kb(folder / "train.pl", 40, seed=1), nearest_key_kb(folder / "test.pl", 20, seed=2)


def test_nearest_key_first_is_recovered_exactly(kbs: tuple[Path, Path]) -> None:
    train, test = kbs
    s = induce_strategy(train, "world", holdout=test)
    assert s.fidelity == 1.0 and s.train_fidelity == 1.0
    assert s.states == len(load_trace(test).step)
    assert "\n".join(s.text().split("\n")[:1]) == "%! features: world"
    assert len(s.model.clauses) == 1
    # one clause: the nearest key (by Manhattan distance or by route; keys and the gem block
    # routes, so the two agree here), and not the gem
    body = s.text().split("goal(E, T, O) :-\n")[1].split(".\n")[0].split(",\n")
    assert [lit.strip() for lit in body] in (
        [
            "goal_candidate(E, T, O)",
            nearest,
            kind,
        ]
        for nearest in ("nearest_of_kind(E, T, O)", "route_not_longer(E, T, O, key)")
        for kind in ("object_kind(O, key)", "\\+ object_kind(O, gem)")
    ), body


def test_relations_carry_the_strategy_when_a_head_attends_the_goal(kbs: tuple[Path, Path]) -> None:
    train, test = kbs
    s = induce_strategy(train, "relations", holdout=test)
    assert s.fidelity == 1.0
    assert "attended_by(E, T, 0, 1, O)" in s.text()
    assert "object_kind" not in s.text().split("% Background")[0]


def test_the_tree_learner_recovers_it_too(kbs: tuple[Path, Path]) -> None:
    train, test = kbs
    assert induce_strategy(train, "world", holdout=test, learner="tree").fidelity == 1.0


def _prolog_choices(swipl: Path, kb: Path, strategy: Path) -> dict[tuple[int, int], str | None]:
    goal = (
        "forall(distinct(E-T, at(E, T, _, _, _)), "
        "( goal(E, T, O) -> format('~w ~w ~w~n', [E, T, O]) ; format('~w ~w none~n', [E, T]) ))"
    )
    out = subprocess.run(
        [str(swipl), "-q", "-g", f"consult('{kb}'), consult('{ROUTE}'), consult('{strategy}')", "-g", goal, "-t", "halt"],
        capture_output=True, text=True, check=True, timeout=120,
    ).stdout  # fmt: skip
    rows = [line.split() for line in out.splitlines()]
    return {(int(e), int(t)): (None if o == "none" else o) for e, t, o in rows}


@pytest.mark.parametrize("features", ["world", "relations", "both"])
@pytest.mark.parametrize("learner", ["covering", "tree"])
def test_first_answer_in_swipl_is_the_python_choice(
    kbs: tuple[Path, Path], tmp_path: Path, swipl: Path, features: str, learner: str
) -> None:
    train, test = kbs
    s = induce_strategy(train, features, holdout=test, learner=learner)
    path = s.write(tmp_path / "strategy.pl")
    prolog = _prolog_choices(swipl, test, path)
    python = s.predict(load_trace(test))
    assert len(python) > 0
    for e, t, choice in zip(python["E"], python["T"], python["Choice"], strict=True):
        assert prolog[(e, t)] == choice, f"[{e},{t}]"


def test_bad_settings_are_one_line_errors(kbs: tuple[Path, Path], tmp_path: Path) -> None:
    train, _ = kbs
    with pytest.raises(ConfigError, match="unknown feature set 'colour'; use one of world, relations, both"):
        induce_strategy(train, "colour")
    with pytest.raises(ConfigError, match="between 0 and 1"):
        induce_strategy(train, "world", holdout_share=1.5)
    with pytest.raises(ConfigError, match="max_clauses must be 1 to 20, got 21"):
        induce_strategy(train, "world", max_clauses=21)
    with pytest.raises(ConfigError, match="unknown learner 'ilp'; use one of best, tree, covering"):
        induce_strategy(train, "world", learner="ilp")
    with pytest.raises(ConfigError, match="no knowledge base at"):
        induce_strategy(tmp_path / "missing.pl")
