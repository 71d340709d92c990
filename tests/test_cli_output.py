"""What the commands print: quiet on a closed pipe, data as text, progress only on a terminal."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import threading
from pathlib import Path

import pytest
from builders import REPO

from neurosym.cli import BROKEN_PIPE_EXIT

CHECKPOINTS = REPO / "checkpoints"


def _env() -> dict[str, str]:
    path = os.pathsep.join(p for p in (str(REPO), os.environ.get("PYTHONPATH")) if p)
    return {**os.environ, "PYTHONPATH": path, "PYTHONHASHSEED": "0", "OMP_NUM_THREADS": "1"}


def _into_closed_pipe(*args: object) -> subprocess.CompletedProcess[str]:
    """Run neurosym with stdout a pipe whose reader has gone already (``| head`` that quit)."""
    read_end, write_end = os.pipe()
    os.close(read_end)
    try:
        return subprocess.run(
            [sys.executable, "-m", "neurosym", *map(str, args)],
            stdout=write_end, stderr=subprocess.PIPE, text=True, cwd=REPO, env=_env(),
            timeout=300,
        )  # fmt: skip
    finally:
        os.close(write_end)


@pytest.mark.parametrize(
    "args",
    [
        ("envs",),  # a rich table
        ("envs", "--json"),  # print()
        ("eval", "--checkpoint", CHECKPOINTS / "rgw1-predinet.pt", "--episodes", "1"),
        ("query", "--kb", REPO / "rules" / "tests" / "rgw_facts.pl", "--csv", "true"),
    ],
    ids=["table", "json", "eval", "query"],
)
def test_a_closed_pipe_ends_the_command_quietly(args: tuple[object, ...]) -> None:
    proc = _into_closed_pipe(*args)
    assert (proc.returncode, proc.stderr) == (BROKEN_PIPE_EXIT, "")


def test_top_keys_is_refused_on_a_predinet(neurosym_main, tmp_path: Path) -> None:  # noqa: ANN001
    out = tmp_path / "kb"
    proc = neurosym_main("extract", "--checkpoint", CHECKPOINTS / "rgw2-predinet.pt",
                        "--top-keys", 3, "--episodes", 1, "--out", out)  # fmt: skip
    assert proc.returncode == 1 and len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    assert "--top-keys is for MHDPA checkpoints" in proc.stderr and "is a predinet" in proc.stderr
    assert not out.exists()


def test_eval_shows_a_checkpoint_name_as_text(neurosym_main, tmp_path: Path) -> None:  # noqa: ANN001
    hostile = tmp_path / "[red]x\x1b[31m.pt"
    shutil.copy(CHECKPOINTS / "rgw1-predinet.pt", hostile)
    proc = neurosym_main("eval", "--checkpoint", hostile, "--episodes", 1)
    assert proc.returncode == 0, proc.stderr
    assert "\x1b" not in proc.stdout
    assert "[red]x\\e[31m.pt (rgw1, predinet" in proc.stdout


def _on_a_terminal(*args: object, columns: int = 100) -> tuple[int, str]:
    """Run neurosym with stderr a terminal (a pty); (exit status, what it wrote there)."""
    import pty

    master, slave = pty.openpty()
    proc = subprocess.Popen(
        [sys.executable, "-m", "neurosym", *map(str, args)],
        stdout=subprocess.DEVNULL, stderr=slave, cwd=REPO,
        env={**_env(), "TERM": "xterm", "COLUMNS": str(columns)},
    )  # fmt: skip
    os.close(slave)
    chunks: list[bytes] = []

    def read() -> None:
        while True:
            try:
                data = os.read(master, 65536)
            except OSError:  # EIO: the child closed the terminal
                return
            if not data:
                return
            chunks.append(data)

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    code = proc.wait(timeout=300)
    reader.join(timeout=10)
    os.close(master)
    return code, b"".join(chunks).decode("utf-8", "replace")


def test_probe_and_intervene_show_progress_on_a_terminal(tmp_path: Path) -> None:
    code, text = _on_a_terminal(
        "intervene", "--checkpoint", CHECKPOINTS / "rgw2-predinet.pt", "--episodes", 2,
        "--no-levels", "--out", tmp_path / "i",
    )  # fmt: skip
    assert code == 0, text
    assert "effects at the baseline's states" in text  # the last stage, drawn when it stops
    code, text = _on_a_terminal(
        "probe", "--checkpoint", CHECKPOINTS / "rgw1-predinet.pt", "--episodes", 2,
        "--no-untrained", "--out", tmp_path / "p",
    )  # fmt: skip
    assert code == 0, text
    assert "fitting probes" in text


def test_no_progress_when_stderr_is_not_a_terminal(run_neurosym, tmp_path: Path) -> None:  # noqa: ANN001
    proc = run_neurosym("intervene", "--checkpoint", CHECKPOINTS / "rgw2-predinet.pt",
                        "--episodes", 2, "--no-levels", "--out", tmp_path / "i")  # fmt: skip
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr


def test_fields_are_shown_whole_or_left_out() -> None:
    import io

    from rich.console import Console

    from neurosym.progress import Fields

    console = Console(width=20, file=io.StringIO(), color_system=None)
    console.print(Fields("320 frames  254/s  0 ep  success 29 %"))
    assert console.file.getvalue() == "320 frames  254/s\n"


def test_the_training_bar_never_cuts_a_figure(tmp_path: Path) -> None:
    """In a narrow terminal the figures that do not fit are left out, never cut ("succes…")."""
    import re

    code, text = _on_a_terminal(
        "train", "--env", "rgw1", "--module", "predinet", "--frames", 300, "--workers", 1,
        "--out", tmp_path / "run", columns=60,
    )  # fmt: skip
    assert code == 0, text
    plain = re.sub(r"\x1b\[[0-9;?]*[A-Za-z]", "", text)
    assert "rgw1 predinet" in plain and re.search(r"\d+ frames  ", plain), plain
    assert "…" not in plain, plain


def test_an_error_is_one_line_whatever_the_path_holds(neurosym_main) -> None:  # noqa: ANN001
    proc = neurosym_main("eval", "--checkpoint", "/nowhere/x\x1b[31mred\nline2.pt")
    assert proc.returncode == 1
    assert (
        proc.stderr
        == "neurosym eval: error: checkpoint not found: /nowhere/x\\e[31mred\\nline2.pt\n"
    )
