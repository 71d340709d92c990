"""Private copies of files: what neurosym checks is exactly what it then reads, loads or compiles.

Checking a file and then opening it again by name would let a file swapped in
between (a writer on a shared drive) be loaded or compiled unchecked. So a
fact file or ``.qlf`` is copied once, into a folder only this user can enter,
and the check, the load and the compile all read that copy. Copying also
yields the bytes' SHA-256 (for signatures) and a bound on how deeply a term
of the text can nest while SWI-Prolog reads it (its opening brackets; see
:func:`nesting_bound` for the bound of code). Copying is one pass over the
bytes: hashing and counting run in C, about 0.15 s for 55 MB.
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import os
import shutil
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from neurosym.errors import PrologError


@dataclass(frozen=True)
class Snapshot:
    """A private copy of ``source``: its path, SHA-256 and opening brackets (``nesting``).

    ``nesting`` bounds how deeply a term nests while it is read: reading
    recurses on brackets only (a fact file cannot add operators).
    """

    path: Path
    source: Path
    sha256: str  # "" when not asked for
    nesting: int


@contextlib.contextmanager
def snapshot(source: Path, digest: bool = True) -> Iterator[Snapshot]:
    """Copy ``source`` into a private temporary folder (0700), removed on exit.

    ``digest=False`` leaves the SHA-256 out (a fact file read as data needs
    none; a signature does).

    Raises :class:`PrologError` (one line) when ``source`` cannot be read or
    the temporary folder cannot be written.
    """
    try:
        folder = Path(tempfile.mkdtemp(prefix="neurosym-"))
    except OSError as exc:
        raise PrologError(f"cannot copy {source} to a private temporary folder: {exc.strerror}") from None
    try:
        try:
            str(folder).encode("utf-8")
        except UnicodeEncodeError:
            shown = os.fsencode(folder).decode("utf-8", "backslashreplace")
            raise PrologError(
                f"cannot load {source}: the temporary folder {shown} has a name that is not valid "
                "UTF-8, which SWI-Prolog cannot open; set TMPDIR to another folder"
            ) from None
        yield _copy(source, folder / source.name, digest)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


# Each level of nesting SWI-Prolog's parser recurses on starts with an opening
# bracket: ``f(``, ``(``, ``[`` or ``{`` (operators are parsed in a loop, not by
# recursion: a fact 300,000 prefix operators deep reads on a 1 MB C stack).
# The full bound (:func:`nesting_bound`, for files that are consulted or
# compiled as code) also counts what can start a prefix operator (the
# symbolic ones hold one of "$+-:?\\"; the others are these words), since
# compiling a term may recurse where reading it did not. A fact file cannot
# add operators.
_BRACKETS = b"([{"
_NESTING_BYTES = b"([{$+-:?\\"
# (thread_initialization holds initialization: counted by that.)
_PREFIX_WORDS = (
    b"discontiguous", b"dynamic", b"initialization", b"meta_predicate", b"module_transparent",
    b"multifile", b"public", b"table", b"thread_local", b"volatile",
)  # fmt: skip
_TAIL = 24  # longer than any word above: a word cut between two chunks is still counted


class _Nesting:
    """Counts, chunk by chunk, what :func:`nesting_bound` counts (``full``) or only the brackets."""

    def __init__(self, full: bool = True) -> None:
        self.count = 0
        self.tail = b""
        self.full = full

    def add(self, chunk: bytes) -> None:
        kept = _NESTING_BYTES if self.full else _BRACKETS
        self.count += len(chunk) - len(chunk.translate(None, kept))  # one pass, in C
        if self.full:
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


def _copy(source: Path, copy: Path, hashed: bool) -> Snapshot:
    """Copy ``source`` to ``copy``, hashing it and counting its brackets on the way.

    A failure to read names the source; a failure to write (a full disk, a
    file-size limit) names the private copy, so neither is mistaken for the other.
    """
    digest = hashlib.sha256() if hashed else None
    nesting = _Nesting(full=False)
    try:
        src = source.open("rb")
    except OSError as exc:
        raise PrologError(f"cannot read {source}: {_why(exc)}") from None
    with src:
        try:
            dst = copy.open("xb")
        except OSError as exc:
            raise PrologError(_write_error(source, copy, exc)) from None
        with dst:
            while True:
                try:
                    chunk = src.read(1 << 20)
                except OSError as exc:
                    raise PrologError(f"cannot read {source}: {_why(exc)}") from None
                if not chunk:
                    break
                if digest is not None:
                    digest.update(chunk)
                nesting.add(chunk)
                try:
                    dst.write(chunk)
                except OSError as exc:
                    raise PrologError(_write_error(source, copy, exc)) from None
    return Snapshot(copy, source, digest.hexdigest() if digest else "", nesting.count)


def _why(exc: OSError) -> str:
    return exc.strerror or type(exc).__name__


def _write_error(source: Path, copy: Path, exc: OSError) -> str:
    """One line: the private copy of ``source`` could not be written, and why."""
    hint = ""
    if exc.errno == errno.EFBIG:
        hint = " (the file-size limit, ulimit -f, is smaller than the file)"
    elif exc.errno in (errno.ENOSPC, errno.EDQUOT):
        hint = " (make room there, or set TMPDIR to a folder with room)"
    return (
        f"cannot load {source}: neurosym reads a private copy of every file it loads and could "
        f"not write it to {copy.parent}: {_why(exc)}{hint}"
    )
