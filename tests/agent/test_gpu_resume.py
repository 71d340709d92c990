"""scripts/gpu_resume.sh: a run handed back mid-way and continued from what came back."""

from __future__ import annotations

import csv
import os
import subprocess
import sys
from pathlib import Path

import pytest
import torch

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "gpu_resume.sh"


def _script(*args: str, out: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "OUT": str(out), "PYTHON": sys.executable, "DEVICE": "cpu",
           "OMP_NUM_THREADS": "1"}  # fmt: skip
    return subprocess.run(["bash", str(SCRIPT), *args], cwd=ROOT, env=env, text=True,
                          capture_output=True, timeout=600)  # fmt: skip


def _frames(run: Path) -> int:
    return int(torch.load(run / "checkpoint.pt", weights_only=False)["frames"])


@pytest.mark.expensive
def test_a_run_continues_from_the_files_handed_back(tmp_path: Path) -> None:
    out, first, second = tmp_path / "out", tmp_path / "first", tmp_path / "second"
    out.mkdir()
    train = ("--env", "bw1", "--module", "predinet", "--algo", "ppo", "--envs", "4",
             "--n-steps", "8", "--eval-episodes", "1", "--checkpoint-interval", "1")  # fmt: skip
    proc = _script("train", str(first), "0.05", *train, out=out)
    assert proc.returncode == 0, proc.stderr
    parts = sorted(p.name for p in out.iterdir())
    assert parts[:1] == ["checkpoint.pt.part00"] and "metrics.csv" in parts, parts
    assert {"tensorboard.tar", "train.out"} <= set(parts)
    assert not [p for p in out.iterdir() if p.name.startswith(".")]  # no half-made hand-back

    proc = _script("collect", str(out), str(second), out=out)
    assert proc.returncode == 0, proc.stderr
    assert (second / "checkpoint.pt").read_bytes() == (first / "checkpoint.pt").read_bytes()
    assert (second / "tensorboard").is_dir()
    before = _frames(second)

    proc = _script("train", str(second), "0.05", out=out)  # no arguments: it resumes
    assert proc.returncode == 0, proc.stderr
    assert _frames(second) > before
    with open(second / "metrics.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert int(rows[-1]["frames"]) > before


def test_usage_is_one_line() -> None:
    proc = subprocess.run(["bash", str(SCRIPT)], capture_output=True, text=True)
    assert proc.returncode == 2 and proc.stderr.startswith("usage: ")


@pytest.mark.parametrize("flag", ["--help", "-h"])
def test_help_prints_the_usage(flag: str) -> None:
    proc = subprocess.run(["bash", str(SCRIPT), flag], capture_output=True, text=True)
    assert proc.returncode == 0 and proc.stderr == ""
    assert proc.stdout == (
        f"usage: {SCRIPT} train RUN MINUTES [TRAIN ARGS...] | collect FILES RUN | --help\n"
    )


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("train", "-x", "5"), "train: -x is not a name (names come first, without '-')"),
        (("train", "--help", "5"), "train: --help is not a name (names come first, without '-')"),
        (("train", "run"), "train needs 2 names, got 1"),
        (("train", "run", "soon"), "train: MINUTES must be a positive number, got soon"),
        (("collect", "-x", "run"), "collect: -x is not a name (names come first, without '-')"),
        (("collect", "files"), "collect needs 2 names, got 1"),
    ],
)
def test_an_option_or_a_missing_name_is_refused_in_one_line(
    tmp_path: Path, args: tuple[str, ...], message: str
) -> None:
    proc = _script(*args, out=tmp_path)
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr.splitlines() == [
        f"{SCRIPT}: {message}; usage: {SCRIPT} train RUN MINUTES [TRAIN ARGS...] | "
        "collect FILES RUN | --help"
    ]
    assert list(tmp_path.iterdir()) == []  # nothing made, nothing trained


def test_collect_refuses_a_missing_files_folder(tmp_path: Path) -> None:
    files, run = tmp_path / "handed-bak", tmp_path / "run"
    proc = _script("collect", str(files), str(run), out=tmp_path)
    assert proc.returncode == 1 and proc.stdout == ""
    assert proc.stderr.splitlines() == [
        f"{SCRIPT}: collect: FILES folder {files} does not exist (the folder the device tool "
        "handed back)"
    ]
    assert not run.exists()
