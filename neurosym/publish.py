"""A command's products into its output folder: staged, then each moved in by one rename.

Used by ``neurosym extract``, ``probe`` and ``intervene``. Only the names the
run produced are replaced in the folder; anything else there is left alone.
A run killed part-way (``kill -9``) leaves the previous products as they
were: everything is written in a staging folder inside ``out`` first, a file
replaces its old version in one rename, and a folder is swapped with its old
version in one ``renameat2(RENAME_EXCHANGE)`` where Linux offers it. What a
killed run left (its staging folder, a folder half-swapped by the fallback)
is cleaned up or put back by the next run. A failed run leaves nothing
half-written, and a folder it created is removed again.
"""

from __future__ import annotations

import ctypes
import os
import shutil
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path

from neurosym.errors import ConfigError, OutputError

STAGE_PREFIX = ".stage-"


def check_out(out: Path) -> Path:
    """Refuse an --out that exists and is not a folder."""
    if out.exists() and not out.is_dir():
        raise ConfigError(f"--out {out} exists and is not a folder")
    return out


def publish(
    out: Path,
    write: Callable[[Path], object],
    folders: Iterable[str] = (),
    prefix: str = STAGE_PREFIX,
) -> dict[str, Path]:
    """Call ``write(stage)``, then move every product it left in ``stage`` into ``out``.

    ``folders``: the names of folder products, which a killed run may have
    moved aside (recovered by the next run); ``prefix`` names the staging
    folder (``PREFIX<pid>-...``). Returns name -> final path.
    """
    created = not out.exists()
    out.mkdir(parents=True, exist_ok=True)
    _recover(out, set(folders), prefix)
    stage = Path(tempfile.mkdtemp(prefix=f"{prefix}{os.getpid()}-", dir=out))
    ok = False
    try:
        write(stage)
        written: dict[str, Path] = {}
        for name in sorted(p.name for p in stage.iterdir() if not p.name.startswith(".")):
            _move_into_place(stage / name, out / name)
            written[name] = out / name
        ok = True
        return written
    except OSError as exc:
        raise OutputError(f"cannot write into {out}: {exc.strerror or exc}") from None
    finally:
        shutil.rmtree(stage, ignore_errors=True)
        if created and not ok:
            shutil.rmtree(out, ignore_errors=True)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _recover(out: Path, folders: set[str], prefix: str) -> None:
    """Undo what a killed run left in ``out``: its staging folder, a folder it had moved aside."""
    for entry in out.iterdir():
        name = entry.name
        if name.startswith(prefix):
            pid = name[len(prefix) :].split("-", 1)[0]
            if pid.isdigit() and not _alive(int(pid)):
                shutil.rmtree(entry, ignore_errors=True)
        elif name.startswith(".") and ".old-" in name:
            product, _, pid = name[1:].rpartition(".old-")
            if product in folders and pid.isdigit() and not _alive(int(pid)):
                if (out / product).exists():
                    shutil.rmtree(entry, ignore_errors=True)
                else:  # killed between moving the old folder aside and the new one in
                    os.replace(entry, out / product)


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths in one step (Linux renameat2 RENAME_EXCHANGE); False where unsupported."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        renameat2 = libc.renameat2
    except (OSError, AttributeError):
        return False
    at_fdcwd, rename_exchange = -100, 2
    return renameat2(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), rename_exchange) == 0


def _move_into_place(src: Path, dst: Path) -> None:
    """Rename ``src`` onto ``dst``: a file in one os.replace, a folder by swapping it with the old one."""
    if src.is_dir():
        if dst.is_dir() and _exchange(src, dst):
            shutil.rmtree(src, ignore_errors=True)  # src now holds the old folder
            return
        old = None
        if dst.exists():
            old = dst.with_name(f".{dst.name}.old-{os.getpid()}")
            shutil.rmtree(old, ignore_errors=True)
            os.replace(dst, old)
        os.replace(src, dst)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
    else:
        os.replace(src, dst)
