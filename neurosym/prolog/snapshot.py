"""Private copies of files: what neurosym checks is exactly what it then reads, loads or compiles.

Checking a file and then opening it again by name would let a file swapped in
between (a writer on a shared drive) be loaded or compiled unchecked. So a
fact file or ``.qlf`` is copied once, into a folder only this user can enter,
and the check, the load and the compile all read that copy. Copying also
yields the bytes' SHA-256 (for signatures) and how many opening brackets the
text holds, which bounds how deeply any term in it can nest.
"""

from __future__ import annotations

import contextlib
import hashlib
import shutil
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from neurosym.errors import PrologError


@dataclass(frozen=True)
class Snapshot:
    """A private copy of ``source``: its path, SHA-256 and number of ``( [ {`` bytes."""

    path: Path
    source: Path
    sha256: str
    brackets: int


@contextlib.contextmanager
def snapshot(source: Path) -> Iterator[Snapshot]:
    """Copy ``source`` into a private temporary folder (0700), removed on exit.

    Raises :class:`PrologError` (one line) when ``source`` cannot be read or
    the temporary folder cannot be written.
    """
    try:
        folder = Path(tempfile.mkdtemp(prefix="neurosym-"))
    except OSError as exc:
        raise PrologError(f"cannot copy {source} to a private temporary folder: {exc.strerror}") from None
    try:
        yield _copy(source, folder / source.name)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def count_brackets(path: Path) -> int:
    """How many ``( [ {`` bytes ``path`` holds (0 when it cannot be read: loading it will say why)."""
    brackets = 0
    try:
        with path.open("rb") as fh:
            while chunk := fh.read(1 << 20):
                brackets += chunk.count(b"(") + chunk.count(b"[") + chunk.count(b"{")
    except OSError:
        return 0
    return brackets


def _copy(source: Path, copy: Path) -> Snapshot:
    digest = hashlib.sha256()
    brackets = 0
    try:
        with source.open("rb") as src, copy.open("xb") as dst:
            while chunk := src.read(1 << 20):
                digest.update(chunk)
                brackets += chunk.count(b"(") + chunk.count(b"[") + chunk.count(b"{")
                dst.write(chunk)
    except OSError as exc:
        what = exc.strerror or type(exc).__name__
        failed = exc.filename or source
        raise PrologError(f"cannot read {source}: {what} ({failed})" if failed != str(source)
                          else f"cannot read {source}: {what}") from None
    return Snapshot(copy, source, digest.hexdigest(), brackets)
