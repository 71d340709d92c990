"""Atomic file writes: the one helper behind every file neurosym writes.

A file is written to a temporary name in the same folder and renamed onto
its final name, so a reader (or a ``kill -9`` half-way) never leaves half a
file under that name. Two details every writer needs and used to get wrong:

* permissions: ``mkstemp`` creates the temporary file 0600, and a rename
  keeps them, so KBs, recordings and checkpoints were unreadable for
  colleagues on a shared drive. The file is given ``0o666 & ~umask`` before
  the rename, as ``open()`` would have done.
* failure: a write that fails part-way (a full disk, a quota, a file-size
  limit) removes the temporary file and raises :class:`OutputError`, one line
  naming the file; whatever was at the final name is left untouched.
* the target: a rename replaces whatever has the name, so ``--out /dev/null``
  would turn the device into a regular file. A target that exists and is not
  a regular file (a device, FIFO, socket or folder) is refused before
  anything is written (:func:`check_target`).
* the inputs: an output that is one of the command's inputs (``--kb X --out
  X``, or the link an extract folder publishes its KB under) would replace
  it; :func:`refuse_overwrite` refuses that before the work starts.
"""

from __future__ import annotations

import contextlib
import os
import stat
import tempfile
import threading
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import IO, Any

from neurosym.errors import OutputError

_umask_lock = threading.Lock()


def umask() -> int:
    """The process umask, read without changing it where the OS allows.

    Linux reports it in ``/proc/self/status``; elsewhere it is read by setting
    and restoring it under a lock (``os.umask`` has no read-only form).
    """
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    with _umask_lock:
        mask = os.umask(0o022)
        os.umask(mask)
    return mask


def file_mode() -> int:
    """The mode a new file gets from ``open()``: ``0o666 & ~umask``."""
    return 0o666 & ~umask()


def _error(path: Path, exc: OSError) -> OutputError:
    reason = exc.strerror or str(exc) or type(exc).__name__
    return OutputError(f"cannot write {path}: {reason}; it was left as it was")


_KINDS = (
    (stat.S_ISDIR, "a folder"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISFIFO, "a FIFO"),
    (stat.S_ISSOCK, "a socket"),
)


def file_kind(path: str | os.PathLike[str]) -> str | None:
    """What ``path`` is when it exists and is not a regular file (``"a FIFO"``), else None.

    A symbolic link counts as what it points to; a dangling one as absent.
    """
    try:
        mode = os.stat(path).st_mode
    except (FileNotFoundError, NotADirectoryError):
        return None
    except OSError:
        return None  # unreadable: the write itself will say why
    if stat.S_ISREG(mode):
        return None
    return next((kind for test, kind in _KINDS if test(mode)), "not a regular file")


def check_target(path: str | os.PathLike[str]) -> Path:
    """Refuse, with one OutputError line, a target that exists and is not a regular file.

    A rename onto a device, FIFO or socket would replace it with a regular
    file (``--out /dev/null`` run as root); onto a folder it fails late.
    """
    kind = file_kind(path)
    if kind is not None:
        raise OutputError(
            f"cannot write {os.fspath(path)}: it exists and is {kind}, not a regular file; "
            "nothing was written"
        )
    return Path(path)


def make_folder(path: str | os.PathLike[str]) -> Path:
    """``mkdir -p path``, or one OutputError line naming it (read-only file system, a file in the way)."""
    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"cannot make folder {path}: {exc.strerror or exc}") from None
    return path


def atomic_write(path: str | os.PathLike[str], write: Callable[[Path], Any]) -> Path:
    """Call ``write(tmp_path)`` and move the result onto ``path`` in one rename.

    ``write`` must create or fill the file at ``tmp_path`` (it exists, empty).
    Raises :class:`OutputError` when writing or renaming fails with an OSError.
    """
    path = check_target(path)
    folder = path.parent if str(path.parent) else Path(".")
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=folder)
    except OSError as exc:
        raise _error(path, exc) from None
    os.close(fd)
    try:
        write(Path(tmp))
        os.chmod(tmp, file_mode())
        os.replace(tmp, path)
    except OSError as exc:
        Path(tmp).unlink(missing_ok=True)
        raise _error(path, exc) from None
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


@contextlib.contextmanager
def open_atomic(path: str | os.PathLike[str], mode: str = "wb", **kwargs: Any) -> Iterator[IO[Any]]:
    """``with open_atomic(p, "w") as fh: ...``: the file appears at ``p`` only if the block succeeds."""
    path = check_target(path)
    folder = path.parent if str(path.parent) else Path(".")
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=folder)
    except OSError as exc:
        raise _error(path, exc) from None
    try:
        with os.fdopen(fd, mode, **kwargs) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, file_mode())
        os.replace(tmp, path)
    except OSError as exc:
        Path(tmp).unlink(missing_ok=True)
        raise _error(path, exc) from None
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_bytes_atomic(path: str | os.PathLike[str], data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically (see :func:`open_atomic`)."""
    with open_atomic(path, "wb") as fh:
        fh.write(data)
    return Path(path)


PUBLISH_STORE = ".neurosym"
"""The hidden folder of a published output folder (:data:`neurosym.publish.STORE`): its run
folders hold the products, and ``out/NAME`` links into it."""


def refuse_overwrite(
    out: str | os.PathLike[str],
    inputs: Iterable[str | os.PathLike[str] | None],
    flag: str = "--out",
) -> Path:
    """Refuse, with one OutputError line, an output that would replace an input or a published product.

    ``out`` is refused when it is the same file as one of ``inputs`` (by
    device and inode: through symbolic links, hard links and other spellings
    of the path), when it is a product link of a published folder
    (``out/kb.pl -> .neurosym/current/kb.pl``, :mod:`neurosym.publish`), or
    when it lies inside such a folder's store. Inputs that do not exist (or
    None) are skipped. Call it before the work, so nothing is lost or done in vain.
    """
    path = Path(out)
    try:
        mine = os.stat(path)
    except (OSError, ValueError):
        mine = None
    for source in inputs:
        if source is None or mine is None:
            continue
        try:
            theirs = os.stat(source)
        except (OSError, ValueError):
            continue
        if (mine.st_dev, mine.st_ino) == (theirs.st_dev, theirs.st_ino):
            raise OutputError(
                f"{flag} {os.fspath(path)} is the input {os.fspath(source)} (the same file): "
                "writing it would replace that input; choose another output; nothing was written"
            )
    if path.is_symlink() and Path(os.readlink(path)).parts[:1] == (PUBLISH_STORE,):
        raise OutputError(
            f"{flag} {os.fspath(path)} is a product of a published folder (a link into "
            f"{PUBLISH_STORE}/); writing it would replace that product; choose another output; "
            "nothing was written"
        )
    if PUBLISH_STORE in Path(os.path.abspath(path)).parts[:-1]:
        raise OutputError(
            f"{flag} {os.fspath(path)} lies inside a published folder's store ({PUBLISH_STORE}/), "
            "which only the command that published it writes; choose another output; nothing was written"
        )
    return path
