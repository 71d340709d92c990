"""Faults, for real: ``kill -9`` of train and extract, and a disk that fills up part-way.

Each test runs the real command in a subprocess (its own session, so the
workers it forks are found and checked too) on a budget of seconds.
"""

from __future__ import annotations

import csv
import hashlib
import os
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from neurosym.agent.checkpoint import read_checkpoint

REPO = Path(__file__).resolve().parents[1]
CHECKPOINT = REPO / "checkpoints" / "rgw2-predinet.pt"
INTERVAL = 2.0  # --checkpoint-interval of the killed training run


def _env() -> dict[str, str]:
    path = os.pathsep.join(p for p in (str(REPO), os.environ.get("PYTHONPATH")) if p)
    return {**os.environ, "PYTHONPATH": path, "PYTHONHASHSEED": "0"}


def _start(*args: object, preexec=None) -> subprocess.Popen[str]:
    return subprocess.Popen(
        [sys.executable, "-m", "neurosym", *map(str, args)],
        cwd=REPO, env=_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        start_new_session=True, preexec_fn=preexec,
    )  # fmt: skip


def _wait_for(condition, timeout: float, what: str) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.02)


def _group_gone(pgid: int) -> bool:
    try:
        os.killpg(pgid, 0)
    except ProcessLookupError:
        return True
    return False


def _kill_9(proc: subprocess.Popen[str]) -> None:
    """SIGKILL the command's main process only, as the OOM killer or a lost node would."""
    os.kill(proc.pid, signal.SIGKILL)
    proc.communicate(timeout=30)


def _snapshot(folder: Path) -> dict[str, str]:
    """Path -> SHA-256 of every file, read as a reader would (through the products' links)."""
    found = {}
    for root, _, files in os.walk(folder, followlinks=True):
        for name in files:
            p = Path(root) / name
            if p.is_file():
                found[str(p.relative_to(folder))] = hashlib.sha256(p.read_bytes()).hexdigest()
    return dict(sorted(found.items()))


@pytest.mark.expensive
def test_kill_9_of_train_loses_at_most_one_checkpoint_interval_and_resume_continues(
    run_neurosym, tmp_path: Path
) -> None:
    out = tmp_path / "run"
    ckpt = out / "checkpoint.pt"
    proc = _start(
        "train", "--env", "rgw2", "--module", "predinet", "--out", out, "--workers", "1",
        "--envs", "4", "--minutes", "5", "--checkpoint-interval", INTERVAL,
        "--eval-interval", "1", "--eval-episodes", "2", "--quiet",
    )  # fmt: skip
    try:
        _wait_for(ckpt.exists, 180, "the first checkpoint")
        seen: set[int] = set()

        def rewritten_twice() -> bool:
            seen.add(ckpt.stat().st_mtime_ns)
            return len(seen) >= 3

        _wait_for(rewritten_twice, 60, "two more checkpoints")
        time.sleep(INTERVAL * 0.7)  # somewhere between two checkpoints
        killed_at = time.time()
        _kill_9(proc)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    # the workers notice that their parent is gone and stop by themselves
    _wait_for(lambda: _group_gone(proc.pid), 60, "the orphaned workers to exit")

    assert killed_at - ckpt.stat().st_mtime <= INTERVAL + 3.0  # at most one interval lost (+ slack)
    payload = read_checkpoint(ckpt, env="rgw2")
    frames = int(payload["frames"])
    assert frames > 0 and payload["metrics"]["stop_reason"] == "running"

    resumed = run_neurosym(
        "train", "--out", out, "--resume", "--frames", frames + 2000, "--quiet",
        "--eval-interval", "1", "--eval-episodes", "2", timeout=180,
    )  # fmt: skip
    assert resumed.returncode == 0, resumed.stderr
    after = read_checkpoint(ckpt, env="rgw2")
    assert int(after["frames"]) >= frames + 2000
    with (out / "metrics.csv").open(newline="") as fh:
        rows = [int(r["frames"]) for r in csv.DictReader(fh)]
    assert rows == sorted(rows)  # rows of the lost stretch (past the checkpoint) are gone
    assert any(r <= frames for r in rows) and rows[-1] == int(after["frames"])
    assert not [p.name for p in out.iterdir() if p.name.endswith(".tmp")]


@pytest.fixture
def previous_output(run_neurosym, tmp_path: Path) -> tuple[Path, dict[str, str]]:
    out = tmp_path / "kb_out"
    proc = run_neurosym(
        "extract", "--checkpoint", CHECKPOINT, "--episodes", 2, "--out", out, "--quiet",
        "--format", "pl,parquet",
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    (out / "notes.txt").write_text("mine\n")
    return out, _snapshot(out)


@pytest.mark.expensive
def test_kill_9_of_extract_leaves_the_previous_output_intact(
    run_neurosym, previous_output: tuple[Path, dict[str, str]]
) -> None:
    out, before = previous_output
    assert {"kb.pl", "recording/meta.json", "facts/meta.json", "notes.txt"} <= set(before)
    proc = _start(
        "extract", "--checkpoint", CHECKPOINT, "--episodes", 10, "--seed", 7, "--out", out,
        "--quiet", "--format", "pl,parquet",
    )  # fmt: skip
    try:
        runs = lambda: [p for p in (out / ".neurosym").iterdir() if p.name.startswith("run-")]  # noqa: E731
        _wait_for(lambda: len(runs()) > 1, 120, "extract to start writing")
        _kill_9(proc)  # while the new outputs are being written
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    visible = {k: v for k, v in _snapshot(out).items() if not k.startswith(".")}
    assert visible == {k: v for k, v in before.items() if not k.startswith(".")}

    # the next run finishes, replaces the products, and removes what the killed run left
    proc2 = run_neurosym(
        "extract", "--checkpoint", CHECKPOINT, "--episodes", 3, "--out", out, "--quiet",
        "--format", "pl,parquet",
    )  # fmt: skip
    assert proc2.returncode == 0, proc2.stderr
    names = sorted(p.name for p in out.iterdir())
    assert names == [".neurosym", "facts", "kb.pl", "notes.txt", "recording"]
    assert (out / "notes.txt").read_text() == "mine\n"
    assert _snapshot(out)["kb.pl"] != before["kb.pl"]


def _file_size_limit(limit: int):
    def preexec() -> None:
        os.setsid()
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # the write raises EFBIG instead
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    return preexec


@pytest.mark.expensive
def test_a_full_disk_during_extract_gives_one_line_and_no_half_written_file(
    previous_output: tuple[Path, dict[str, str]],
) -> None:
    out, before = previous_output
    limit = 128 * 1024  # the KB of 10 episodes takes about 0.5 MB
    proc = subprocess.run(
        [sys.executable, "-m", "neurosym", "extract", "--checkpoint", str(CHECKPOINT),
         "--episodes", "10", "--out", str(out), "--quiet"],
        cwd=REPO, env=_env(), capture_output=True, text=True, timeout=300,
        preexec_fn=_file_size_limit(limit),
    )  # fmt: skip
    assert proc.returncode == 1, proc.stderr
    assert proc.stderr.count("\n") == 1, proc.stderr
    assert proc.stderr.startswith("neurosym extract: error: cannot write ")
    assert "File too large" in proc.stderr
    assert _snapshot(out) == before  # nothing replaced, no staging folder or temporary file left


READ_ONLY = """
import builtins, errno, io, os, runpy, sys

ro = os.path.abspath(sys.argv[1])  # everything under it behaves as on a read-only file system


def _under(path) -> bool:
    if isinstance(path, int):
        return False
    path = os.path.abspath(os.fsdecode(path))
    return path == ro or path.startswith(ro + os.sep)


def _refuse(fn, *positions, writes=None):
    def guarded(*args, **kwargs):
        if (writes is None or writes(*args, **kwargs)) and any(
            len(args) > i and _under(args[i]) for i in positions
        ):
            raise OSError(errno.EROFS, os.strerror(errno.EROFS), args[positions[-1]])
        return fn(*args, **kwargs)
    return guarded


write_flags = os.O_WRONLY | os.O_RDWR | os.O_CREAT | os.O_TRUNC | os.O_APPEND
os.open = _refuse(os.open, 0, writes=lambda path, flags, *a, **k: flags & write_flags)
for name in ("mkdir", "rmdir", "unlink", "remove", "chmod"):
    setattr(os, name, _refuse(getattr(os, name), 0))
for name in ("replace", "rename", "link", "symlink"):
    setattr(os, name, _refuse(getattr(os, name), 0, 1))
mode_writes = lambda file, mode="r", *a, **k: any(c in mode for c in "wax+")
builtins.open = io.open = _refuse(io.open, 0, writes=mode_writes)
sys.argv = ["neurosym", *sys.argv[2:]]
runpy.run_module("neurosym", run_name="__main__")
"""


@pytest.mark.parametrize("command", ["extract", "probe"])
def test_a_read_only_output_folder_is_one_line_and_left_as_it_was(
    run_neurosym, tmp_path: Path, command: str
) -> None:
    old = tmp_path / "old"
    made = run_neurosym(command, "--checkpoint", CHECKPOINT, "--episodes", 2, "--out", old)
    assert made.returncode == 0, made.stderr
    before = _snapshot(old)
    for out in (old, tmp_path / "new"):
        proc = subprocess.run(
            [sys.executable, "-c", READ_ONLY, tmp_path, command, "--checkpoint", CHECKPOINT,
             "--episodes", "2", "--out", out],
            cwd=REPO, env=_env(), capture_output=True, text=True, timeout=300,
        )  # fmt: skip
        assert (proc.returncode, proc.stdout) == (1, ""), proc.stderr
        assert proc.stderr == (
            f"neurosym {command}: error: cannot write into {out}: Read-only file system\n"
        )
    assert _snapshot(old) == before
    assert not (tmp_path / "new").exists()
