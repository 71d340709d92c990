"""Shared pytest fixtures: where SWI-Prolog is, and running the real ``neurosym`` command."""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

REPO = Path(__file__).resolve().parents[1]


def pytest_configure(config: pytest.Config) -> None:
    """Sign .qlf files with a key of the test session, never the user's own (subprocesses inherit it).

    Torch computes on one thread in the session and in the subprocesses it starts: the tests'
    batches are small, and on a machine whose few cores other jobs share, two intra-op
    threads spin against each other (a Box-World PrediNet's batch of 64 took 0.6-0.8 s on two
    threads against 0.09 s on one, at a load of 5 on 2 cores). The CLI's own commands and the
    learners' processes set their threads themselves; this covers the calls made in-process."""
    import tempfile

    if "NEUROSYM_KEY_FILE" not in os.environ:
        key_dir = tempfile.mkdtemp(prefix="neurosym-test-key-")
        os.environ["NEUROSYM_KEY_FILE"] = os.path.join(key_dir, "qlf.key")
        # Made here, before pytest-xdist's workers start: they share it, and none of
        # them may read it half-written.
        from neurosym.prolog import signature

        signature._key(create=True)
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    import torch

    torch.set_num_threads(int(os.environ["OMP_NUM_THREADS"]))


@pytest.fixture(scope="session")
def swipl() -> Path:
    """The swipl binary neurosym uses (tests fail, not skip, when there is none)."""
    from neurosym.prolog.locate import swipl_executable

    return swipl_executable()


@pytest.fixture(scope="session")
def fake_swipl() -> Callable[[Path, int], Path]:
    """Makes a `swipl` in a folder that answers --dump-runtime-variables with a version (what
    neurosym probes), for the tests of locating SWI-Prolog."""

    def make(directory: Path, version: int) -> Path:
        directory.mkdir(parents=True, exist_ok=True)
        exe = directory / "swipl"
        exe.write_text(
            f"#!/bin/sh\necho 'PLBASE=\"{directory}/home\";'\necho 'PLVERSION=\"{version}\";'\n"
        )
        exe.chmod(0o755)
        return exe

    return make


@pytest.fixture(scope="session")
def run_neurosym() -> Callable[..., subprocess.CompletedProcess[str]]:
    """Run ``python -m neurosym ARGS...`` in a subprocess, from the repository root."""

    def run(*args: object, timeout: float = 300) -> subprocess.CompletedProcess[str]:
        path = os.pathsep.join(p for p in (str(REPO), os.environ.get("PYTHONPATH")) if p)
        env = {**os.environ, "PYTHONPATH": path, "PYTHONHASHSEED": "0"}
        return subprocess.run(
            [sys.executable, "-m", "neurosym", *map(str, args)],
            capture_output=True, text=True, cwd=REPO, env=env, timeout=timeout,
        )  # fmt: skip

    return run


@pytest.fixture
def neurosym_main(
    capsys: pytest.CaptureFixture[str],
) -> Callable[..., subprocess.CompletedProcess[str]]:
    """Run ``neurosym ARGS...`` in this process (``neurosym.cli.main``), as ``run_neurosym``
    reports it: exit code (argparse's SystemExit included), stdout, stderr. For CLI runs whose
    exit code, one-line error or printed report is what is checked, not the process itself
    (signals, a terminal, warnings written at start-up): a Python start costs 2-3 s a case."""

    def run(*args: object) -> subprocess.CompletedProcess[str]:
        from neurosym.cli import main

        argv = [str(a) for a in args]
        capsys.readouterr()
        try:
            code = main(argv)
        except SystemExit as exc:
            if isinstance(exc.code, str):  # what Python prints for sys.exit(text)
                print(exc.code, file=sys.stderr)
            code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
        out, err = capsys.readouterr()
        return subprocess.CompletedProcess(["neurosym", *argv], code, out, err)

    return run


@pytest.fixture
def train_refused(
    neurosym_main: Callable[..., subprocess.CompletedProcess[str]], monkeypatch: pytest.MonkeyPatch
) -> Callable[..., subprocess.CompletedProcess[str]]:
    """``neurosym_main`` for `neurosym train` input that must be refused before the run starts:
    a run that gets as far as making its directory fails the test at once instead of
    training inside pytest."""
    from neurosym.agent.run import trainer

    def no_run(out: Path) -> None:
        raise AssertionError(f"the input was taken: the run started in {out}")

    monkeypatch.setattr(trainer, "make_run_directory", no_run)
    return neurosym_main


# Fixtures that start a subprocess (the CLI, training) or a browser: tests using them are left
# out of `make test-fast` with the ones marked expensive.
SUBPROCESS_FIXTURES = {"run_neurosym", "neurosym", "browser"}
# modules whose tests start their own subprocesses (a terminal, a fresh venv, a umask, a limit)
SUBPROCESS_MODULES = {"test_cli_output.py", "test_wheel.py", "test_atomic.py", "test_viz_cli.py",
                      "test_allocator.py", "test_gpu_resume.py"}  # fmt: skip


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        if item.path.name in SUBPROCESS_MODULES or SUBPROCESS_FIXTURES & set(
            getattr(item, "fixturenames", ())
        ):
            item.add_marker(pytest.mark.subprocess)


# Builders the tests share (tests/builders.py), as fixtures: a test asks for one by name and
# calls it, e.g. ``def test_x(scripted_recording): rec = scripted_recording()``.


@pytest.fixture(scope="session")
def small_agent() -> Callable[..., Any]:
    """``small_agent(env, module="predinet")``: a small untrained agent (torch seed 0)."""
    from builders import small_agent

    return small_agent


@pytest.fixture(scope="session")
def scripted_recording() -> Callable[..., Any]:
    """``scripted_recording(module="predinet")``: rgw2 episodes along fixed plans (builders.PLANS)."""
    from builders import scripted_recording

    return scripted_recording


@pytest.fixture(scope="session")
def explorer_recording() -> Callable[..., Any]:
    """``explorer_recording(env="bw2", episodes=8)``: Box-World episodes of a scripted explorer."""
    from builders import explorer_recording

    return explorer_recording


@pytest.fixture(scope="session")
def small_checkpoint() -> Callable[..., Any]:
    """``small_checkpoint(path, module, max_steps, **sizes)``: a small untrained rgw2 checkpoint."""
    from builders import small_checkpoint

    return small_checkpoint


@pytest.fixture(scope="session")
def play_one_episode() -> Callable[..., Any]:
    """``play_one_episode(path, route, env_name=None)``: one greedy episode of a checkpoint,
    (return, the route's events met in order, steps)."""
    from builders import play_one_episode

    return play_one_episode

