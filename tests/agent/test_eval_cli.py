"""`neurosym eval` on real checkpoint files, through the CLI in a subprocess (its refusals and
options in this process, through the same ``main``)."""

from __future__ import annotations

import functools
import json
import subprocess
from collections.abc import Callable
from pathlib import Path

import pytest
import torch

from neurosym.agent.agent import load_agent
from neurosym.agent.checkpoint import save_checkpoint
from neurosym.agent.config import ModelConfig
from neurosym.agent.evaluation import evaluate
from neurosym.agent.networks.model import ActorCritic

RGW1_MAP = Path(__file__).resolve().parents[2] / "neurosym" / "envs" / "maps" / "rgw1.txt"


@pytest.fixture
def neurosym(
    run_neurosym: Callable[..., subprocess.CompletedProcess[str]],
) -> Callable[..., subprocess.CompletedProcess[str]]:
    """The CLI in a subprocess (conftest's run_neurosym) with these tests' 120 s limit."""
    return functools.partial(run_neurosym, timeout=120)


@pytest.fixture(scope="module")
def untrained(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("ckpt") / "untrained.pt"
    config = ModelConfig.for_family("rgw", "predinet", (9, 10, 10))
    torch.manual_seed(0)
    save_checkpoint(path, model=ActorCritic(config), config=config, env_name="rgw2", frames=7)
    return path


def test_eval_json(neurosym, untrained: Path) -> None:
    proc = neurosym("eval", "--checkpoint", str(untrained), "--episodes", "6", "--json")
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.strip().splitlines()
    assert len(lines) == 1
    report = json.loads(lines[0])
    assert report["env"] == "rgw2" and report["module"] == "predinet" and report["episodes"] == 6
    assert report["greedy"] is True and report["trained_frames"] == 7
    assert sum(report["outcomes"].values()) == 6
    assert 0.0 <= report["success_rate"] <= 1.0 and report["mean_length"] > 0
    # greedy on a fixed map is deterministic: the library function gives the same numbers
    again = evaluate(load_agent(untrained), "rgw2", 6).as_dict()
    assert again["mean_return"] == report["mean_return"] and again["outcomes"] == report["outcomes"]


def test_eval_text_and_sample(neurosym, untrained: Path) -> None:
    proc = neurosym(
        "eval", "--checkpoint", str(untrained), "--episodes", "4", "--sample", "--seed", "3"
    )
    assert proc.returncode == 0, proc.stderr
    out = proc.stdout
    assert (
        "mean return" in out and "success" in out and "outcomes" in out and "sampled, seed 3" in out
    )
    a = evaluate(load_agent(untrained), "rgw2", 4, greedy=False, seed=3).as_dict()
    b = evaluate(load_agent(untrained), "rgw2", 4, greedy=False, seed=3).as_dict()
    assert a == b  # sampling is seeded


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--checkpoint", "missing.pt"), "checkpoint not found: missing.pt"),
        (("--episodes", "0"), "--episodes must be a positive integer"),
        (("--env", "bw2"), "bw2 is a boxworld environment: pick one of rgw1, rgw2, rgw-random"),
        (("--env", "rgw-random", "--map", "m.txt"), "--map goes with a fixed-map RGW env"),
        (("--env-option", "bogus=1"), "unknown option 'bogus' for rgw2; expected one of map,"),
        (("--env-option", "max_steps"), "--env-option wants KEY=VALUE with KEY a name"),
        (("--map", str(RGW1_MAP), "--env-option", "map=rgw2"), "give the map once: --map FILE"),
        (("--env", "rgw-random", "--env-option", "num_mountains=-1"), "num_mountains must be"),
    ],
)
def test_eval_errors_are_one_line(
    neurosym_main, untrained: Path, args: tuple[str, ...], message: str
) -> None:
    full = ("--checkpoint", str(untrained), *args) if args[0] != "--checkpoint" else args
    proc = neurosym_main("eval", *full)
    assert proc.returncode == 1
    assert message in proc.stderr and len(proc.stderr.strip().splitlines()) == 1, proc.stderr


def test_eval_env_options_change_the_levels(neurosym_main, untrained: Path) -> None:
    """--env-option plays rgw-random's levels with other parameters, recorded in the report."""
    reports = {}
    for mountains in (0, 12):
        proc = neurosym_main(
            "eval", "--checkpoint", str(untrained), "--env", "rgw-random", "--episodes", "20",
            "--seed", "3000000000", "--env-option", f"num_mountains={mountains}", "--json",
        )  # fmt: skip
        assert proc.returncode == 0, proc.stderr
        reports[mountains] = json.loads(proc.stdout)
        assert reports[mountains]["env_kwargs"] == {"num_mountains": mountains}
    # the same 20 seeds: without mountains no optimal route pays for one; with 12 some must
    assert reports[0]["mean_optimal_return"] > reports[12]["mean_optimal_return"]


def test_eval_refuses_a_text_file(neurosym, tmp_path: Path) -> None:
    path = tmp_path / "notes.pt"
    path.write_text("not a checkpoint\n")
    proc = neurosym("eval", "--checkpoint", str(path))
    assert proc.returncode == 1 and proc.stderr.startswith(
        f"neurosym eval: error: cannot read {path}"
    )
