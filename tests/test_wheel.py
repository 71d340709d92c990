"""neurosym installed from its wheel, used outside the repository: the wheel carries the rule files
and the shipped agents, so `neurosym extract` prints rule answers and `--rules rgw` works."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import sysconfig
import venv
import zipfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
SKIP = {".git", ".venv", "build", "dist", "kb_out", "runs", "out", "__pycache__", ".pytest_cache",
        ".ruff_cache", ".hypothesis", ".gl", ".whl"}  # fmt: skip


def _ignore(folder: str, names: list[str]) -> set[str]:
    return {n for n in names if n in SKIP or n.endswith(".egg-info")}


@pytest.fixture(scope="module")
def wheel(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The wheel `pip wheel` builds from a copy of the repository (the build writes no file here)."""
    tmp = tmp_path_factory.mktemp("wheel")
    src = tmp / "src"
    shutil.copytree(REPO, src, ignore=_ignore)
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "--no-build-isolation",
         str(src), "-w", str(tmp / "dist")],
        check=True, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    (built,) = (tmp / "dist").glob("neurosym-*.whl")
    return built


def test_the_wheel_carries_the_rule_files_and_the_agents(wheel: Path) -> None:
    names = set(zipfile.ZipFile(wheel).namelist())
    rules = {n for n in names if n.endswith(".pl")}
    assert rules == {f"neurosym/rules/{p.name}" for p in (REPO / "rules").glob("*.pl")}
    agents = {n for n in names if n.endswith(".pt")}
    assert agents == {f"neurosym/checkpoints/{p.name}" for p in (REPO / "checkpoints").glob("*.pt")}
    assert "neurosym/envs/maps/rgw2.txt" in names
    assert not {n for n in names if n.endswith((".plt", ".md"))}  # tests and docs stay behind


def test_installed_neurosym_extracts_and_queries_outside_the_repository(
    wheel: Path, swipl: Path, tmp_path: Path
) -> None:
    """A fresh virtual environment that reuses this one's torch and janus (a .pth line: no
    download), the wheel installed into it, run from a folder outside the repository."""
    env_dir = tmp_path / "venv"
    venv.create(env_dir, with_pip=False)
    python = env_dir / "bin" / "python"
    site = Path(
        subprocess.run([python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                       check=True, capture_output=True, text=True).stdout.strip()
    )  # fmt: skip
    (site / "reuse-dependencies.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    subprocess.run(
        [sys.executable, "-m", "pip", "--python", str(python), "install", "-q", "--no-deps",
         "--no-index", str(wheel)],
        check=True, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    work = tmp_path / "elsewhere"
    work.mkdir()
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["NEUROSYM_SWIPL"] = str(swipl)

    def neurosym(*args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run([env_dir / "bin" / "neurosym", *args], cwd=work, env=env,
                              capture_output=True, text=True, timeout=300)  # fmt: skip

    where = subprocess.run([python, "-c", "import neurosym; print(neurosym.__file__)"], cwd=work,
                           env=env, capture_output=True, text=True, check=True).stdout  # fmt: skip
    assert where.startswith(str(site)), where  # the wheel's copy, not the repository's
    proc = neurosym("agents", "--json")
    assert proc.returncode == 0, proc.stderr
    files = {a["name"]: a["file"] for a in json.loads(proc.stdout)}
    assert files["rgw-random-predinet-cellkeys"].startswith(str(site / "neurosym" / "checkpoints"))
    proc = neurosym("extract", "--checkpoint", "rgw-random-predinet-cellkeys", "--env", "rgw2",
                    "--episodes", "2", "--out", "kb")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "rules/rgw.pl" in proc.stdout and "rule files are missing" not in proc.stdout
    assert "sword before enemy" in proc.stdout and "2 of 2 episodes" in proc.stdout
    assert "indirect([agent])" in proc.stdout
    proc = neurosym("query", "--kb", "kb/kb.pl", "--rules", "rgw", "--format", "csv",
                    "sword_before_enemy(E)")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == "E\n0\n1\n"
