"""neurosym installed from its wheel, used outside the repository: the wheel installs where there
is no SWI-Prolog (janus-swi is the `prolog` extra), says in one line to run `neurosym setup-prolog`
until there is; it carries the rule files and the shipped agents, so `neurosym extract` prints rule
answers and `--rules rgw` works."""

from __future__ import annotations

import importlib.metadata
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


def _fresh_venv(root: Path, wheel: Path, janus: bool) -> Path:
    """A virtual environment under ``root`` that reuses this one's installed packages through
    links (no download), janus-swi among them only when ``janus``, with the wheel installed by
    pip with its dependencies checked (``--no-index``: all of them must be there already)."""
    mine = Path(sysconfig.get_paths()["purelib"])
    deps = root / "deps"
    deps.mkdir()
    for entry in mine.iterdir():
        name = entry.name.lower()
        if name.startswith(("neurosym", "__editable__", "janus_swi")) or name.endswith(".pth"):
            continue
        (deps / entry.name).symlink_to(entry)
    lines = [str(deps)]
    if janus:
        (root / "janus").mkdir()
        for entry in mine.glob("janus_swi*"):
            (root / "janus" / entry.name).symlink_to(entry)
        lines.append(str(root / "janus"))
    env_dir = root / "venv"
    venv.create(env_dir, with_pip=False)
    python = env_dir / "bin" / "python"
    site = Path(
        subprocess.run([python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                       check=True, capture_output=True, text=True).stdout.strip()
    )  # fmt: skip
    (site / "reuse-dependencies.pth").write_text("\n".join(lines) + "\n")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}  # no other neurosym's
    proc = subprocess.run(
        [sys.executable, "-m", "pip", "--python", str(python), "install", "-q", "--no-index",
         str(wheel)],
        capture_output=True, text=True, timeout=300, env=env,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    return env_dir


def _run(env_dir: Path, *args: str, cwd: Path, **env: str) -> subprocess.CompletedProcess[str]:
    """``ARGS`` (a program of the venv's bin/: ``neurosym``, ``python``, ``swipl``) outside the
    repository; PATH is the venv's bin/ alone (no swipl of the machine's), plus ``env``."""
    base = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "NEUROSYM_SWIPL")}
    return subprocess.run([env_dir / "bin" / args[0], *args[1:]], cwd=cwd,
                          env={**base, "PATH": str(env_dir / "bin"), **env},
                          capture_output=True, text=True, timeout=300)  # fmt: skip


def test_the_wheel_needs_no_prolog_to_install_and_says_in_one_line_what_to_run(
    wheel: Path, swipl: Path, tmp_path: Path
) -> None:
    from neurosym.setup_prolog import JANUS_REQUIREMENT

    requires = [line for line in zipfile.ZipFile(wheel).read(
        "neurosym-0.1.0.dist-info/METADATA").decode().splitlines() if line.startswith("Requires-Dist: janus")]  # fmt: skip
    assert requires == [f'Requires-Dist: {JANUS_REQUIREMENT}; extra == "prolog"']
    env_dir = _fresh_venv(tmp_path, wheel, janus=False)  # pip checked every dependency: no janus
    (tmp_path / "kb.pl").write_text("episode(0, 1, 1.0, terminal).\n")
    query = ("query", "--kb", "kb.pl", "episode(E, _, _, _)")
    proc = _run(env_dir, "neurosym", *query, cwd=tmp_path)
    assert (proc.returncode, proc.stdout) == (1, "")
    assert proc.stderr == (
        "neurosym query: error: no SWI-Prolog found: run `neurosym setup-prolog` (builds one "
        "into the venv) or set NEUROSYM_SWIPL to a swipl >= 9.1.12\n"
    )
    proc = _run(env_dir, "neurosym", *query, cwd=tmp_path, NEUROSYM_SWIPL=str(swipl))
    assert (proc.returncode, proc.stdout) == (1, "")
    assert proc.stderr == (
        "neurosym query: error: janus-swi is not installed (No module named 'janus_swi'): "
        f"run `neurosym setup-prolog`, which builds it against {swipl}\n"
    )
    proc = _run(env_dir, "neurosym", "setup-prolog", "--swipl", "no-such-swipl", cwd=tmp_path)
    assert (proc.returncode, proc.stdout) == (1, "")
    assert proc.stderr == (
        "neurosym setup-prolog: error: --swipl no-such-swipl is not a runnable swipl; point it "
        "at a SWI-Prolog >= 9.1.12 binary\n"
    )
    assert not (env_dir / "bin" / "swipl").exists()


def test_the_wheel_carries_the_rule_files_and_the_agents(wheel: Path) -> None:
    names = set(zipfile.ZipFile(wheel).namelist())
    rules = {n for n in names if n.endswith(".pl") and n.startswith("neurosym/rules/")}
    shipped = [*(REPO / "rules").glob("*.pl"), *(REPO / "rules").glob("lib/*.pl")]
    assert "lib/kb_common.pl" in {p.relative_to(REPO / "rules").as_posix() for p in shipped}
    assert rules == {f"neurosym/rules/{p.relative_to(REPO / 'rules').as_posix()}" for p in shipped}
    modules = {n for n in names if n.endswith(".pl") and not n.startswith("neurosym/rules/")}
    assert modules == {  # the package's Prolog modules and play's shipped strategies (their
        # .plt files stay behind, see below)
        f"neurosym/{p.relative_to(REPO / 'neurosym')}"
        for p in [*(REPO / "neurosym").glob("*/pl/*.pl"), *(REPO / "neurosym").glob("play/strategies/*.pl")]
    }
    agents = {n for n in names if n.endswith(".pt")}
    assert agents == {f"neurosym/checkpoints/{p.name}" for p in (REPO / "checkpoints").glob("*.pt")}
    assert "neurosym/envs/maps/rgw2.txt" in names
    assert "neurosym/setup_swipl.sh" in names  # `neurosym setup-prolog` builds SWI-Prolog with it
    assert not {n for n in names if n.endswith((".plt", ".md"))}  # tests and docs stay behind


def test_installed_neurosym_extracts_and_queries_outside_the_repository(
    wheel: Path, swipl: Path, tmp_path: Path
) -> None:
    """`neurosym setup-prolog` links this Prolog into the venv (janus-swi already loads it:
    nothing to build); from then on neurosym finds it there, without NEUROSYM_SWIPL."""
    env_dir = _fresh_venv(tmp_path, wheel, janus=True)
    work = tmp_path / "elsewhere"
    work.mkdir()
    proc = _run(env_dir, "neurosym", "setup-prolog", cwd=work, NEUROSYM_SWIPL=str(swipl))
    assert proc.returncode == 0, proc.stderr
    link = env_dir / "bin" / "swipl"
    assert os.readlink(link) == str(swipl)
    assert proc.stdout.splitlines()[1:] == [
        f"swipl: {link} -> {swipl} (on PATH once the environment is activated)",
        f"janus-swi {importlib.metadata.version('janus-swi')}: loads this SWI-Prolog "
        "(nothing to build)",
    ]
    site = _run(
        env_dir, "python", "-c", "import neurosym; print(neurosym.__file__)", cwd=work
    ).stdout
    assert site.startswith(str(env_dir)), site  # the wheel's copy, not the repository's
    site = Path(site).parents[1]
    proc = _run(env_dir, "neurosym", "agents", "--json", cwd=work)
    assert proc.returncode == 0, proc.stderr
    files = {a["name"]: a["file"] for a in json.loads(proc.stdout)}
    assert files["rgw-random-predinet-cellkeys"].startswith(str(site / "neurosym" / "checkpoints"))
    proc = _run(env_dir, "neurosym", "extract", "--checkpoint", "rgw-random-predinet-cellkeys", "--env", "rgw2",
                "--episodes", "2", "--out", "kb", cwd=work)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "rules/rgw.pl" in proc.stdout and "rule files are missing" not in proc.stdout
    assert "sword before enemy" in proc.stdout and "2 of 2 episodes" in proc.stdout
    assert "co-occurring only: agent" in proc.stdout  # the sword-enemy link, in words
    proc = _run(env_dir, "neurosym", "query", "--kb", "kb/kb.pl", "--rules", "rgw", "--csv",
                "sword_before_enemy(E)", cwd=work)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == "E\n0\n1\n"
    proc = _run(env_dir, "swipl", "-g", "consult('kb/kb.pl'), aggregate_all(count, episode(_, _, _, _), N), write(N)",
                "-t", "halt", cwd=work)  # fmt: skip
    assert (proc.returncode, proc.stdout) == (0, "2"), proc.stderr  # `swipl` of the venv's bin/
