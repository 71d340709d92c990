"""``neurosym induce strategy`` on real files: output, the written file, error lines."""

from __future__ import annotations

from pathlib import Path

import pytest
from strategy_kbs import nearest_key_kb


@pytest.fixture(scope="module")
def kbs(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    folder = tmp_path_factory.mktemp("kbs")
    return nearest_key_kb(folder / "train.pl", 30, seed=3), nearest_key_kb(folder / "test.pl", 10, seed=4)


def test_cli_learns_prints_and_writes(neurosym_main, kbs: tuple[Path, Path], tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    train, test = kbs
    out = tmp_path / "strategy.pl"
    r = neurosym_main("induce", "strategy", "--kb", train, "--holdout", test, "--out", out)
    assert r.returncode == 0, r.stderr
    assert "fidelity 1.0000 on" in r.stdout and f"wrote {out}" in r.stdout
    text = out.read_text()
    assert text.startswith("%! features: world\n")
    assert f"Learned by `neurosym induce strategy` from {train}" in text


def test_cli_holdout_share_and_relations(neurosym_main, kbs: tuple[Path, Path], tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    train, _ = kbs
    out = tmp_path / "s.pl"
    r = neurosym_main(
        "induce", "strategy", "--kb", train, "--features", "relations",
        "--holdout-share", "0.5", "--out", out,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert "the last 15 of 30 episodes of the KB (share 0.5)" in r.stdout
    assert out.read_text().startswith("%! features: relations\n")


@pytest.mark.parametrize(
    ("args", "code", "message"),
    [
        (["strategy", "--kb", "missing.pl"], 1,
         "neurosym induce: error: --kb missing.pl does not exist (give a KB written by neurosym extract)"),
        (["plans"], 2, "neurosym induce: error: argument WHAT: invalid choice: 'plans' (choose from "
         "'world', 'strategy')"),
        (["strategy", "--holdout-share", "1.5"], 1,
         "neurosym induce: error: --holdout-share must be between 0 and 1 (exclusive), got 1.5"),
        (["strategy", "--features", "colour"], 2, "invalid choice: 'colour'"),
        (["--what", "strategy"], 2, "neurosym induce: error: --what is now a subcommand: neurosym "
         "induce world ... or neurosym induce strategy ..."),
    ],
)  # fmt: skip
def test_cli_errors_are_one_line(neurosym_main, kbs, tmp_path: Path, args, code, message) -> None:  # type: ignore[no-untyped-def]
    train, _ = kbs
    full = [*args[:1], "--kb", train, *args[1:]] if "--kb" not in args else args
    r = neurosym_main("induce", *full, "--out", tmp_path / "s.pl")
    assert r.returncode == code
    assert message in r.stderr
    if code == 1 or "--what" in args:
        assert len(r.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "s.pl").exists()


def test_induce_imports_neither_torch_nor_the_envs() -> None:
    import subprocess
    import sys

    code = (
        "import sys, neurosym.cli, neurosym.induce.cli_induce, neurosym.induce.strategy, "
        "neurosym.induce.strategy_writer, neurosym.induce.strategy_covering; "
        "print('torch' in sys.modules, 'neurosym.envs' in sys.modules)"
    )
    repo = Path(__file__).resolve().parents[2]
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=repo
    )
    assert out.stdout.split() == ["False", "False"]


def test_cli_refuses_a_folder_as_out_before_learning(neurosym_main, kbs, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    train, _ = kbs
    r = neurosym_main("induce", "strategy", "--kb", train, "--out", tmp_path)
    assert r.returncode == 1
    assert r.stderr.startswith("neurosym induce: error: ") and len(r.stderr.strip().splitlines()) == 1
    assert "learned from" not in r.stdout
