"""`neurosym induce world` and `neurosym extract --actions random`, run as commands."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest


@pytest.fixture(scope="module")
def kbs(tmp_path_factory: pytest.TempPathFactory, write_world_kb) -> tuple[Path, Path]:
    folder = tmp_path_factory.mktemp("kbs")
    return write_world_kb(folder / "train.pl", "rgw-random", 0), write_world_kb(
        folder / "held.pl", "rgw-random", 50_000
    )


def test_induce_prints_each_event_and_writes_the_rules(neurosym_main, kbs, tmp_path: Path) -> None:
    train, held = kbs
    out = tmp_path / "world.pl"
    done = neurosym_main("induce", "world", "--kb", train, "--out", out, "--holdout", held)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0].startswith(f"learned from {train} (env rgw-random, 60 episodes, ")
    assert lines[0].endswith(f"; held out: {held} (60 episodes)")
    i = lines.index(
        next(
            x
            for x in lines
            if x.startswith("picked(sword): 1 clause(s); train precision 1.000 recall 1.000")
        )
    )
    assert lines[i].endswith("; solved perfectly")
    assert lines[i + 1] == "  predicts(E, T, picked(sword)) :- ahead(E, T, sword)."
    assert "killed_by(enemy): undetermined (no positive example in the KB)" in lines
    assert lines[-1] == f"wrote {out}"
    assert "solved perfectly on the held-out KB" in lines[-2]
    assert out.read_text().startswith("/** <module> World rules learned")


def test_without_holdout_only_train_scores(neurosym_main, kbs, tmp_path: Path) -> None:
    done = neurosym_main("induce", "world", "--kb", kbs[0], "--out", tmp_path / "w.pl")
    assert done.returncode == 0, done.stderr
    assert "held-out" not in done.stdout and "held out" not in done.stdout


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (
            ["world", "--kb", "missing.pl"],
            "neurosym induce: error: --kb missing.pl does not exist",
        ),
        (
            ["world", "--kb", "EMPTY"],
            "has no step/4 facts: nothing to learn world rules from",
        ),
    ],
)
def test_bad_input_is_one_line(
    neurosym_main, kbs, tmp_path: Path, args: list[str], message: str
) -> None:
    from neurosym.facts.tables import extract_facts
    from neurosym.record.recording import Recording

    empty = extract_facts(Recording()).to_prolog(tmp_path / "empty.pl")
    args = [{"KB": str(kbs[0]), "EMPTY": str(empty)}.get(a, a) for a in args]
    out = tmp_path / "w.pl"
    done = neurosym_main("induce", *args, "--out", out)
    assert done.returncode == 1
    assert len(done.stderr.splitlines()) == 1 and message in done.stderr
    assert not out.exists()


def test_induce_imports_no_torch(tmp_path: Path) -> None:
    code = (
        "import sys; from neurosym.cli import main\n"
        "import neurosym.induce.cli_induce, neurosym.induce.world\n"
        "assert 'torch' not in sys.modules, 'torch imported'"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=Path(__file__).parents[2]
    )
    assert done.returncode == 0, done.stderr


def test_extract_random_actions_records_it(small_checkpoint, neurosym_main, tmp_path: Path) -> None:
    ckpt = small_checkpoint(tmp_path / "small.pt", "predinet", 12, relations=3)
    outs = []
    for batch in ("3", "1"):
        out = tmp_path / f"kb{batch}"
        done = neurosym_main(
            "extract", "--checkpoint", ckpt, "--actions", "random", "--episodes", "3",
            "--batch", batch, "--out", out, "--quiet",
        )  # fmt: skip
        assert done.returncode == 0, done.stderr
        outs.append((out / "kb.pl").read_text())
    assert "kb_meta(actions,random)." in outs[0]
    steps = [sorted(x for x in text.splitlines() if x.startswith("step(")) for text in outs]
    assert steps[0] == steps[1] and len(steps[0]) == 36  # 3 episodes of 12 steps, same at any batch
    agent = neurosym_main(
        "extract", "--checkpoint", ckpt, "--episodes", "3", "--out", tmp_path / "a", "--quiet"
    )
    assert agent.returncode == 0
    assert "kb_meta(actions,agent)." in (tmp_path / "a" / "kb.pl").read_text()
