"""Publishing a run's products: all at once, one writer at a time, nothing of a failed run.

A kill is simulated by ``os._exit`` at the Nth file-system step of a publish
(every rename, link, unlink and removal), in a subprocess, for every N: the
folder must then read as wholly the old run or wholly the new one.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pandas as pd
import pytest

from neurosym.errors import OutputError
from neurosym.publish import STORE, publish
from neurosym.record.recording import Recording

REPO = Path(__file__).resolve().parents[1]
OWNED = ("kb.pl", "kb.qlf", "recording")

PUBLISH = """
import os, shutil, sys
from pathlib import Path
from neurosym.publish import publish

out, tag, kill_at = Path(sys.argv[1]), sys.argv[2], int(sys.argv[3])
calls = 0

def counted(fn):
    def step(*args, **kwargs):
        global calls
        calls += 1
        if calls == kill_at:
            os._exit(9)
        return fn(*args, **kwargs)
    return step

def write(run):
    (run / "kb.pl").write_text(tag)
    (run / "kb.qlf").write_text(tag)
    (run / "recording").mkdir()
    (run / "recording" / "meta.json").write_text(tag)

if kill_at:
    for name in ("replace", "rename", "symlink", "link", "unlink", "rmdir"):
        setattr(os, name, counted(getattr(os, name)))
    shutil.rmtree = counted(shutil.rmtree)
publish(out, write, owned=("kb.pl", "kb.qlf", "recording"))
print(calls)
"""


def _publish(out: Path, tag: str, kill_at: int = 0) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(PUBLISH), str(out), tag, str(kill_at)],
        capture_output=True, text=True, env=env, timeout=120,
    )  # fmt: skip


def _seen(out: Path) -> set[str | None]:
    """The tags a reader sees through the products' names (None: missing)."""
    seen: set[str | None] = set()
    for rel in ("kb.pl", "kb.qlf", "recording/meta.json"):
        try:
            seen.add((out / rel).read_text())
        except FileNotFoundError:
            seen.add(None)
    return seen


def test_a_kill_at_any_step_leaves_the_folder_wholly_old_or_wholly_new(tmp_path: Path) -> None:
    out = tmp_path / "out"
    assert _publish(out, "old").returncode == 0
    (out / "notes.txt").write_text("mine")
    probe = tmp_path / "probe"
    assert _publish(probe, "old").returncode == 0
    steps = _publish(probe, "new")
    assert steps.returncode == 0, steps.stderr
    assert _seen(probe) == {"new"}
    for kill_at in range(1, 40):
        proc = _publish(out, "new", kill_at)
        seen = _seen(out)
        assert seen in ({"old"}, {"new"}), (kill_at, seen)
        assert (out / "notes.txt").read_text() == "mine"
        if proc.returncode == 0:  # ran to the end: every step has been killed once
            break
        assert proc.returncode == 9, proc.stderr
        if seen == {"old"}:
            continue
        assert _publish(out, "old").returncode == 0  # back to the old state for the next kill
    else:
        raise AssertionError("the publish never ran to its end")
    assert kill_at > 3
    # the next run finishes and cleans up what the killed ones left
    assert _publish(out, "last").returncode == 0
    assert _seen(out) == {"last"}
    assert sorted(p.name for p in out.iterdir()) == [
        STORE,
        "kb.pl",
        "kb.qlf",
        "notes.txt",
        "recording",
    ]
    runs = [p.name for p in (out / STORE).iterdir() if p.name.startswith("run-")]
    assert len(runs) == 2  # the published run and the one before, for readers still reading it


HOLD = """
import sys, time
from pathlib import Path
from neurosym.publish import check_out
check_out(Path(sys.argv[1]))
print("holding", flush=True)
sys.stdin.read()
"""


def test_a_second_writer_is_refused_while_the_first_holds_the_folder(
    tmp_path: Path, run_neurosym
) -> None:
    out = tmp_path / "out"
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    holder = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(HOLD), str(out)],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=env,
    )  # fmt: skip
    try:
        assert holder.stdout.readline() == "holding\n"
        with pytest.raises(OutputError) as err:
            publish(out, lambda run: (run / "kb.pl").write_text("x"), owned=OWNED)
        assert str(err.value) == (
            f"another neurosym run is writing {out}; wait for it to end or pick another --out"
        )
        proc = run_neurosym(
            "extract", "--checkpoint", REPO / "checkpoints" / "rgw2-predinet.pt",
            "--episodes", 1, "--out", out, "--quiet",
        )  # fmt: skip
        assert proc.returncode == 1
        assert proc.stderr == (
            f"neurosym extract: error: another neurosym run is writing {out}; "
            "wait for it to end or pick another --out\n"
        )
    finally:
        holder.communicate("", timeout=60)
    assert not out.exists()  # the holder created it and published nothing: removed again
    publish(out, lambda run: (run / "kb.pl").write_text("x"), owned=OWNED)
    assert (out / "kb.pl").read_text() == "x"


def test_a_failed_run_changes_nothing_and_removes_a_folder_it_created(tmp_path: Path) -> None:
    out = tmp_path / "out"

    def failing(run: Path) -> None:
        (run / "kb.pl").write_text("half")
        raise OutputError("disk full")

    with pytest.raises(OutputError, match="disk full"):
        publish(out, failing, owned=OWNED)
    assert not out.exists()
    publish(out, lambda run: (run / "kb.pl").write_text("old"), owned=OWNED)
    before = sorted(str(p.relative_to(out)) for p in out.rglob("*"))
    with pytest.raises(OutputError, match="disk full"):
        publish(out, failing, owned=OWNED)
    assert (out / "kb.pl").read_text() == "old"
    assert sorted(str(p.relative_to(out)) for p in out.rglob("*")) == before


def test_a_run_replaces_its_command_s_products_and_keeps_the_others(tmp_path: Path) -> None:
    out = tmp_path / "out"
    publish(out, lambda run: [(run / n).write_text("extract 1") for n in ("kb.pl", "kb.qlf")],
            owned=OWNED)  # fmt: skip
    publish(out, lambda run: (run / "probes.parquet").write_text("probe"),
            owned=("kb.pl", "probes.parquet"))  # fmt: skip
    assert not (out / "kb.pl").exists()  # the probe run's own KB was not written this time
    assert (out / "kb.qlf").read_text() == "extract 1"  # extract's, not the probe's: carried
    publish(out, lambda run: (run / "kb.pl").write_text("extract 2"), owned=OWNED)
    assert (out / "kb.pl").read_text() == "extract 2"
    assert not (out / "kb.qlf").exists()  # no .qlf of another run beside the new kb.pl
    assert (out / "probes.parquet").read_text() == "probe"


def test_a_product_name_held_by_a_fifo_is_refused_before_anything_changes(tmp_path: Path) -> None:
    out = tmp_path / "out"
    publish(out, lambda run: (run / "kb.pl").write_text("old"), owned=OWNED)
    os.mkfifo(out / "kb.qlf")
    with pytest.raises(OutputError) as err:
        publish(out, lambda run: [(run / n).write_text("new") for n in ("kb.pl", "kb.qlf")],
                owned=OWNED)  # fmt: skip
    assert str(err.value) == (
        f"cannot write {out / 'kb.qlf'}: it exists and is a FIFO, not a regular file; "
        "nothing was written"
    )
    assert (out / "kb.pl").read_text() == "old"


def test_a_recording_is_read_from_one_run_while_another_is_published(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "out"

    def recording(seed: int) -> Recording:
        episodes = pd.DataFrame(
            {"episode": [0], "steps": [1], "return": [1.0], "outcome": ["terminal"], "seed": [seed]}
        )
        return Recording(episodes=episodes, meta={"seed": seed})

    publish(out, lambda run: recording(1).save(run / "recording"), owned=OWNED)
    read_parquet = pd.read_parquet

    def publish_meanwhile(path, *args, **kwargs):  # noqa: ANN001, ANN202
        monkeypatch.setattr(pd, "read_parquet", read_parquet)
        publish(out, lambda run: recording(2).save(run / "recording"), owned=OWNED)
        return read_parquet(path, *args, **kwargs)

    monkeypatch.setattr(pd, "read_parquet", publish_meanwhile)
    rec = Recording.load(out / "recording")
    assert rec.meta == {"seed": 1} and rec.episodes["seed"].tolist() == [1]
    assert Recording.load(out / "recording").episodes["seed"].tolist() == [2]


def test_published_names_the_run_folder_readers_read_from(tmp_path: Path) -> None:
    from neurosym.publish import published

    out = tmp_path / "out"
    assert published(out) == out  # nothing published: the folder itself (older layout too)
    publish(out, lambda run: (run / "kb.pl").write_text("one"), owned=OWNED)
    first = published(out)
    assert first.parent == (out / STORE).resolve() and (first / "kb.pl").read_text() == "one"
    publish(out, lambda run: (run / "kb.pl").write_text("two"), folders=("x",), prefix=".old-")
    assert (first / "kb.pl").read_text() == "one"  # kept for a reader still reading it
    assert (published(out) / "kb.pl").read_text() == "two"
