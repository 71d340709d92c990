"""Atomic writes: files get the umask's permissions, and a write that fails part-way leaves nothing.

Both run in a subprocess: the umask and the file-size limit (a full disk,
simulated with RLIMIT_FSIZE and SIGXFSZ ignored, so a write raises EFBIG)
are process-wide.
"""

from __future__ import annotations

import os
import resource
import signal
import socket
import stat
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]

WRITE_ALL = """
import os, sys
from pathlib import Path
import pandas as pd
from neurosym.atomic import atomic_write, open_atomic, write_bytes_atomic
from neurosym.facts.prolog_writer import write_prolog
from neurosym.record.recording import Recording
from neurosym.agent.run.metrics import write_rows as _write_rows
from neurosym.agent.checkpoint import save_checkpoint
from neurosym.agent.config import ModelConfig
from neurosym.agent.networks.model import ActorCritic

out = Path(sys.argv[1])
write_bytes_atomic(out / "bytes.bin", b"x")
atomic_write(out / "cb.txt", lambda p: p.write_text("y"))
with open_atomic(out / "ctx.txt", "w") as fh:
    fh.write("z")
write_prolog(out / "kb.pl", {"p": pd.DataFrame({"x": [1, 2]})})
Recording().save(out / "recording")
_write_rows(out / "metrics.csv", [{"frames": 1}])
config = ModelConfig.for_family("rgw", "predinet", (10, 10, 10), 1.0)
save_checkpoint(out / "checkpoint.pt", model=ActorCritic(config), config=config, env_name="rgw2")
"""


def _python(code: str, *args: object, preexec=None, timeout: float = 120):
    env = {**os.environ, "PYTHONPATH": str(REPO), "PYTHONHASHSEED": "0"}
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code), *map(str, args)],
        capture_output=True, text=True, cwd=REPO, env=env, timeout=timeout, preexec_fn=preexec,
    )  # fmt: skip


@pytest.mark.parametrize("mask", [0o002, 0o022, 0o077])
def test_written_files_get_the_umask_permissions(tmp_path: Path, mask: int) -> None:
    proc = _python(WRITE_ALL, tmp_path, preexec=lambda: os.umask(mask))
    assert proc.returncode == 0, proc.stderr
    files = [p for p in tmp_path.rglob("*") if p.is_file()]
    names = {p.name for p in files}
    assert {"bytes.bin", "kb.pl", "episodes.parquet", "meta.json", "metrics.csv"} <= names
    assert "checkpoint.pt" in names
    for p in files:
        assert oct(p.stat().st_mode & 0o777) == oct(0o666 & ~mask), p
    assert not [p for p in files if p.name.endswith(".tmp")]


def _limit_file_size(limit: int):
    def preexec() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # the write raises EFBIG instead
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    return preexec


FILL = """
import sys
from pathlib import Path
import numpy as np, pandas as pd
from neurosym.errors import NeurosymError
from neurosym.facts.prolog_writer import write_prolog
from neurosym.agent.run.metrics import write_rows as _write_rows

out = Path(sys.argv[1])
what = sys.argv[2]
try:
    if what == "kb":
        write_prolog(out / "kb.pl", {"p": pd.DataFrame({"x": np.arange(200_000)})})
    elif what == "metrics":
        _write_rows(out / "metrics.csv", [{"frames": i} for i in range(100_000)])
    else:
        from neurosym.agent.checkpoint import save_checkpoint
        from neurosym.agent.config import ModelConfig
        from neurosym.agent.networks.model import ActorCritic

        config = ModelConfig.for_family("rgw", "predinet", (10, 10, 10), 1.0)
        save_checkpoint(out / "checkpoint.pt", model=ActorCritic(config), config=config, env_name="rgw2")
except NeurosymError as exc:
    print(exc, file=sys.stderr)
    sys.exit(1)
"""


@pytest.mark.parametrize(
    ("what", "name"),
    [("kb", "kb.pl"), ("metrics", "metrics.csv"), ("checkpoint", "checkpoint.pt")],
)
def test_a_write_that_fails_part_way_leaves_the_old_file(
    tmp_path: Path, what: str, name: str
) -> None:
    (tmp_path / name).write_text("old\n")
    proc = _python(FILL, tmp_path, what, preexec=_limit_file_size(64 * 1024))
    assert proc.returncode == 1, proc.stderr
    assert proc.stderr.count("\n") == 1, proc.stderr
    assert f"cannot write {tmp_path / name}: File too large" in proc.stderr
    assert (tmp_path / name).read_text() == "old\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == [name]  # no temporary file left


@pytest.mark.parametrize("how", ["bytes", "callback", "context"])
def test_a_target_that_is_not_a_regular_file_is_refused(tmp_path: Path, how: str) -> None:
    from neurosym.atomic import atomic_write, open_atomic, write_bytes_atomic
    from neurosym.errors import OutputError

    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    sock = tmp_path / "sock"
    server = socket.socket(socket.AF_UNIX)
    server.bind(str(sock))
    device = tmp_path / "null"
    device.symlink_to("/dev/null")  # a rename would replace the link, never /dev/null itself
    cases = ((fifo, "a FIFO"), (sock, "a socket"), (device, "a character device"))
    try:
        for target, kind in cases:
            with pytest.raises(OutputError) as err:
                if how == "bytes":
                    write_bytes_atomic(target, b"x")
                elif how == "callback":
                    atomic_write(target, lambda p: p.write_bytes(b"x"))
                else:
                    with open_atomic(target, "wb") as fh:
                        fh.write(b"x")
            assert str(err.value) == (
                f"cannot write {target}: it exists and is {kind}, not a regular file; "
                "nothing was written"
            )
    finally:
        server.close()
    assert stat.S_ISFIFO(fifo.lstat().st_mode) and stat.S_ISSOCK(sock.lstat().st_mode)
    assert device.is_symlink() and stat.S_ISCHR(os.stat("/dev/null").st_mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fifo", "null", "sock"]


def test_a_folder_that_cannot_be_made_is_one_line(tmp_path: Path) -> None:
    import pandas as pd

    from neurosym.agent.checkpoint import save_checkpoint
    from neurosym.agent.config import ModelConfig
    from neurosym.agent.networks.model import ActorCritic
    from neurosym.errors import OutputError
    from neurosym.facts.prolog_writer import write_prolog
    from neurosym.record.recording import Recording

    (tmp_path / "file").write_text("in the way\n")
    below = tmp_path / "file" / "sub"
    config = ModelConfig.for_family("rgw", "predinet", (9, 10, 10), 1.0)
    writers = (
        lambda: save_checkpoint(below / "a.pt", model=ActorCritic(config), config=config,
                                env_name="rgw2"),
        lambda: write_prolog(below / "kb.pl", {"p": pd.DataFrame({"x": [1]})}),
        lambda: Recording().save(below),
    )  # fmt: skip
    for write in writers:
        with pytest.raises(OutputError) as err:
            write()
        assert str(err.value) == f"cannot make folder {below}: Not a directory"
    assert (tmp_path / "file").read_text() == "in the way\n"


def test_plot_refuses_an_output_that_is_not_a_regular_file(run_neurosym, tmp_path: Path) -> None:
    fifo = tmp_path / "fig.png"
    os.mkfifo(fifo)
    proc = run_neurosym("plot", "predinet", "--checkpoint", REPO / "checkpoints" /
                        "rgw2-predinet.pt", "--out", fifo)  # fmt: skip
    assert (proc.returncode, proc.stdout) == (1, "")
    assert proc.stderr == (
        f"neurosym plot: error: cannot write {fifo}: it exists and is a FIFO, not a regular file; "
        "nothing was written\n"
    )
    assert stat.S_ISFIFO(fifo.lstat().st_mode)
