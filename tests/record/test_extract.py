"""``neurosym extract`` run for real in a subprocess: outputs, the printed answers, and refusals."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pandas as pd
import pytest
from builders import small_checkpoint

from neurosym.record.recording import Recording


@pytest.fixture(scope="module")
def checkpoint(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A small untrained rgw2 PrediNet checkpoint whose episodes stop after 15 steps."""
    path = tmp_path_factory.mktemp("ckpt") / "rgw2-small.pt"
    return small_checkpoint(path, "predinet", 15, relations=3)


def one_line_error(proc: subprocess.CompletedProcess[str], *parts: str) -> None:
    assert proc.returncode == 1, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("neurosym extract: error: ")
    for part in parts:
        assert part in lines[0]


def test_extract_writes_the_kb_and_prints_the_answers(
    run_neurosym, checkpoint: Path, tmp_path: Path, swipl: Path
) -> None:
    out = tmp_path / "kb"
    out.mkdir()
    (out / "notes.txt").write_text("mine")  # not neurosym's: must survive
    args = ["extract", "--checkpoint", checkpoint, "--env", "rgw2", "--episodes", 3, "--seed", 5,
            "--sample", "--threshold", "z:1", "--out", out, "--format", "pl,parquet", "--qlf",
            "--verbose"]  # fmt: skip
    proc = run_neurosym(*args)
    assert proc.returncode == 0, proc.stderr
    text = proc.stdout
    for part in ("rgw2: 3 episodes (sampled, seed 5)", "facts: ", "thresholds (z:1)", "sword before enemy",
                 "sword-enemy link in the network", f"wrote {out / 'kb.pl'}"):  # fmt: skip
        assert part in text, part
    # Prolog lists such as [sword,enemy] survive rich markup
    assert re.search(r"visit orders \(most common\)\s+│ \[", text)
    assert sorted(p.name for p in out.iterdir()) == [
        ".neurosym",  # the published run, its links and the writers' lock
        "facts",
        "kb.pl",
        "kb.qlf",
        "kb.qlf.sig",  # neurosym's signature: this .qlf loads without --trust
        "notes.txt",
        "recording",
    ]
    assert (out / "notes.txt").read_text() == "mine"
    rec = Recording.load(out / "recording")
    assert rec.episodes["seed"].tolist() == [5, 6, 7]
    assert rec.meta["checkpoint"] == str(checkpoint)
    holds = pd.read_parquet(out / "facts" / "holds.parquet")
    kb_text = (out / "kb.pl").read_text()
    assert kb_text.count("\nholds(") == len(holds) > 0
    assert "kb_meta(threshold,'z:1')." in kb_text
    load = subprocess.run(
        [swipl, "-q", "-g", "halt", out / "kb.pl"], capture_output=True, text=True, timeout=60
    )
    assert (load.returncode, load.stdout, load.stderr) == (0, "", "")

    # Run again with only pl: kb.pl is replaced; the earlier run's facts/, kb.qlf and its
    # signature go with it, so the folder holds one run; nothing half-written remains.
    again = run_neurosym(
        "extract",
        "--checkpoint",
        checkpoint,
        "--env",
        "rgw2",
        "--episodes",
        1,
        "--out",
        out,
        "--quiet",
    )
    assert again.returncode == 0, again.stderr
    assert again.stdout == ""
    assert "episode(1," not in (out / "kb.pl").read_text()
    assert sorted(p.name for p in out.iterdir()) == [".neurosym", "kb.pl", "notes.txt", "recording"]
    assert Recording.load(out / "recording").episodes["seed"].tolist() == [0]
    store = sorted(p.name for p in (out / ".neurosym").iterdir())
    assert store[:2] == ["current", "lock"] and len(store) == 4  # this run and the one before
    assert all(name.startswith("run-") for name in store[2:])


@pytest.mark.parametrize(
    ("args", "parts"),
    [
        (["--env", "bw1"], ["was trained on rgw2 (rgw family", "bw1 is a boxworld environment"]),
        (["--map", "nowhere.txt"], ["map 'nowhere.txt'"]),
        (["--env", "rgw-random", "--map", "x.txt"], ["--map goes with a fixed-map RGW env"]),
        (["--env", "nowhere"], ["nowhere"]),
        (["--env-option", "bogus=1"], ["unknown option 'bogus' for rgw2", "enemy"]),
        (["--env", "rgw-random", "--env-option", "width=3"], ["width must be an integer >= 5"]),
        (["--env", "rgw2", "--threshold", "top:5"], ["bad threshold 'top:5'", "quantile:0.9"]),
        (["--env", "rgw2", "--format", "pl,csv"], ["bad --format 'pl,csv'", "pl, parquet"]),
        (["--env", "rgw2", "--episodes", "0"], ["--episodes must be at least 1"]),
        (["--env", "rgw2", "--top-keys", "0"], ["--top-keys must be at least 1"]),
    ],
)
def test_bad_input_is_refused_and_nothing_is_written(
    run_neurosym, checkpoint: Path, tmp_path: Path, args: list[str], parts: list[str]
) -> None:
    out = tmp_path / "kb"
    proc = run_neurosym("extract", "--checkpoint", checkpoint, "--out", out, *args)
    one_line_error(proc, *parts)
    assert not out.exists()


@pytest.mark.parametrize("content", [b"not a checkpoint at all", None])
def test_unreadable_checkpoint_is_refused(
    run_neurosym, tmp_path: Path, content: bytes | None
) -> None:
    ckpt = tmp_path / "broken.pt"
    if content is not None:
        ckpt.write_bytes(content)
    out = tmp_path / "kb"
    proc = run_neurosym("extract", "--checkpoint", ckpt, "--env", "rgw2", "--out", out)
    one_line_error(proc, str(ckpt))
    assert not out.exists()


def test_out_that_is_a_file_is_refused(run_neurosym, checkpoint: Path, tmp_path: Path) -> None:
    out = tmp_path / "kb.pl"
    out.write_text("% someone's file\n")
    proc = run_neurosym("extract", "--checkpoint", checkpoint, "--env", "rgw2", "--out", out)
    one_line_error(proc, "exists and is not a folder")
    assert out.read_text() == "% someone's file\n"


def test_env_defaults_to_the_checkpoints(run_neurosym, checkpoint: Path, tmp_path: Path) -> None:
    out = tmp_path / "kb"
    proc = run_neurosym("extract", "--checkpoint", checkpoint, "--episodes", 1, "--out", out)
    assert proc.returncode == 0, proc.stderr
    assert "rgw2: 1 episodes (greedy, seed 0)" in proc.stdout
    assert (out / "kb.pl").is_file()


@pytest.mark.subprocess
def test_example_script_runs(checkpoint: Path, tmp_path: Path) -> None:
    """examples/extract_and_query.py goes from a checkpoint to rule answers."""
    import os
    import sys

    repo = Path(__file__).resolve().parents[2]
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join(filter(None, [str(repo), os.environ.get("PYTHONPATH")])),
    }
    proc = subprocess.run(
        [sys.executable, repo / "examples" / "extract_and_query.py", checkpoint, tmp_path / "kb"],
        capture_output=True, text=True, cwd=tmp_path, env=env, timeout=300,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "sword before enemy in episodes: [" in proc.stdout
    assert "how the network links sword and enemy:" in proc.stdout
    assert (tmp_path / "kb" / "kb.pl").is_file()


def test_top_keys_keeps_more_mhdpa_keys(run_neurosym, tmp_path: Path) -> None:
    ckpt = small_checkpoint(tmp_path / "mhdpa.pt", "mhdpa", 5, value_size=8)
    counts = {}
    for n in (1, 3):
        out = tmp_path / f"kb{n}"
        proc = run_neurosym("extract", "--checkpoint", ckpt, "--episodes", 1, "--out", out,
                            "--format", "pl,parquet", "--top-keys", n, "--quiet")  # fmt: skip
        assert proc.returncode == 0, proc.stderr
        table = pd.read_parquet(out / "facts" / "attention.parquet")
        counts[n] = table.groupby(["t", "head", "query"]).size()  # query: the cell's entity name
    assert counts[1].index.equals(counts[3].index) and (counts[3] == 3 * counts[1]).all()
