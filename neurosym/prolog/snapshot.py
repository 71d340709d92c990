"""Private copies of files: what neurosym checks is exactly what it then reads, loads or compiles.

Checking a file and then opening it again by name would let a file swapped in
between (a writer on a shared drive) be loaded or compiled unchecked. So a
fact file or ``.qlf`` is copied once, into a folder only this user can enter,
and the check, the load and the compile all read that copy. Copying also
yields the bytes' SHA-256 (for signatures) and a bound on how deeply any
term in the text can nest (:func:`nesting_bound`).
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
    """A private copy of ``source``: its path, SHA-256 and :func:`nesting_bound`."""

    path: Path
    source: Path
    sha256: str
    nesting: int


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


# Each level of nesting SWI-Prolog's parser recurses on starts with one of
# these: an opening bracket, or a prefix operator (the symbolic ones hold one
# of "$+-:?\\"; the others are these words). A fact file cannot add operators.
_NESTING_BYTES = b"([{$+-:?\\"
_PREFIX_WORDS = (
    b"discontiguous", b"dynamic", b"initialization", b"meta_predicate", b"module_transparent",
    b"multifile", b"public", b"table", b"thread_initialization", b"thread_local", b"volatile",
)  # fmt: skip
_TAIL = 24  # longer than any word above: a word cut between two chunks is still counted


class _Nesting:
    """Counts, chunk by chunk, what :func:`nesting_bound` counts."""

    def __init__(self) -> None:
        self.count = 0
        self.tail = b""

    def add(self, chunk: bytes) -> None:
        self.count += sum(chunk.count(bytes([b])) for b in _NESTING_BYTES)
        text = self.tail + chunk  # a word within the tail is counted twice: a bound, still
        self.count += sum(text.count(word) for word in _PREFIX_WORDS)
        self.tail = chunk[-_TAIL:]


def nesting_of(text: str) -> int:
    """:func:`nesting_bound` of a text."""
    nesting = _Nesting()
    nesting.add(text.encode())
    return nesting.count


def nesting_bound(path: Path) -> int:
    """An upper bound on how deeply any term in ``path`` nests (0 when it cannot be read).

    Every level takes an opening bracket or a prefix operator, so this counts
    the bytes and words that can start one.
    """
    nesting = _Nesting()
    try:
        with path.open("rb") as fh:
            while chunk := fh.read(1 << 20):
                nesting.add(chunk)
    except OSError:
        return 0
    return nesting.count


def _copy(source: Path, copy: Path) -> Snapshot:
    digest = hashlib.sha256()
    nesting = _Nesting()
    try:
        with source.open("rb") as src, copy.open("xb") as dst:
            while chunk := src.read(1 << 20):
                digest.update(chunk)
                nesting.add(chunk)
                dst.write(chunk)
    except OSError as exc:
        what = exc.strerror or type(exc).__name__
        raise PrologError(f"cannot read {source}: {what}") from None
    return Snapshot(copy, source, digest.hexdigest(), nesting.count)
