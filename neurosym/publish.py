"""A command's products into its output folder as one unit: written aside, published by one rename.

Used by ``neurosym extract``, ``probe`` and ``intervene``. The folder ``out``
looks like this::

    out/kb.pl -> .neurosym/current/kb.pl     one link per product, the same for every run
    out/recording -> .neurosym/current/recording
    out/.neurosym/current -> run-...         the published run
    out/.neurosym/run-.../                   its products (and those of the run before)
    out/.neurosym/lock                       locked by the run writing into out

A run writes its products into a new ``run-...`` folder and publishes them
all at once by replacing the ``current`` link: one rename, so a reader, or a
``kill -9`` at any moment, sees every product of the previous run or every
product of the new one, never kb.pl of one beside kb.qlf of the other. A
second run into the same folder is refused while the first holds the lock
(:func:`claim`). A failed run leaves the previous products as they were and
removes a folder it created. Files in ``out`` that are not products (notes,
other tools' outputs) are left alone; products of another command in the
same folder (probe's tables beside extract's KB) are carried into the new
run. Readers that open several files of one product (a recording) resolve
its link once, so they read one run even while another is published.
"""

from __future__ import annotations

import atexit
import ctypes
import errno
import fcntl
import os
import shutil
import tempfile
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

from neurosym.atomic import PUBLISH_STORE, file_kind, umask
from neurosym.errors import ConfigError, OutputError

STORE = PUBLISH_STORE
"""the hidden folder in ``out`` holding the lock, the run folders and the ``current`` link"""

CURRENT = "current"
RUN_PREFIX = "run-"
# staging folders of the older layout (one rename per product), cleaned up when found
_LEGACY_STAGES = (".stage-", ".extract-", ".meaning-")


@dataclass
class _Claim:
    fd: int
    created: bool
    """``out`` did not exist before: removed again unless a run is published into it"""
    published: bool = False


_claims: dict[Path, _Claim] = {}


def _error(out: Path, exc: OSError) -> OutputError:
    return OutputError(f"cannot write into {out}: {exc.strerror or exc}")


def check_out(out: Path) -> Path:
    """Refuse an --out that exists and is not a folder, then :func:`claim` it for this run."""
    if out.exists() and not out.is_dir():
        raise ConfigError(f"--out {out} exists and is not a folder")
    claim(out)
    return out


def claim(out: Path) -> Path:
    """Lock ``out`` for this process (creating it if needed) until its run is published.

    A second run into the same folder is refused in one line at once rather
    than after its work. Held until :func:`publish` returns or the process
    ends; a folder created here is removed again if nothing is published.
    """
    key = Path(os.path.abspath(out))
    if key in _claims:
        return out
    created = not out.exists()
    try:
        (out / STORE).mkdir(parents=True, exist_ok=True)
        fd = os.open(out / STORE / "lock", os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o666)
    except OSError as exc:
        if created:
            _remove_created(out)
        raise _error(out, exc) from None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError as exc:
        os.close(fd)
        if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
            raise OutputError(
                f"another neurosym run is writing {out}; wait for it to end or pick another --out"
            ) from None
        raise _error(out, exc) from None
    _claims[key] = _Claim(fd, created)
    return out


def release(out: Path) -> None:
    """Give up the claim on ``out``; a folder the claim created and nothing published into is removed."""
    held = _claims.pop(Path(os.path.abspath(out)), None)
    if held is None:
        return
    if held.created and not held.published:
        _remove_created(out)
    os.close(held.fd)


@atexit.register
def _release_all() -> None:
    for key in list(_claims):
        release(key)


def _remove_created(out: Path) -> None:
    shutil.rmtree(out / STORE, ignore_errors=True)
    try:
        out.rmdir()
    except OSError:
        pass  # someone put something there meanwhile: leave it


def publish(
    out: Path,
    write: Callable[[Path], object],
    owned: Iterable[str] | None = None,
    *,
    folders: Iterable[str] = (),
    prefix: str = "",
) -> dict[str, Path]:
    """Call ``write(run)`` on a new run folder, then publish every product it left there at once.

    ``owned``: the names this command writes; one of them the run did not
    write (kb.qlf without --qlf) is dropped, so no product of an earlier run
    stays beside the new ones; nor does one written into ``out`` as a
    regular file by another command (:func:`_adopt`: removed by the same
    rename that publishes). Other products of the previous run are carried over. Default: the names written. Returns name -> path in ``out``.
    ``folders`` and ``prefix`` are accepted from callers written for the
    older layout (a staging folder per run) and no longer needed.
    """
    claim(out)
    key = Path(os.path.abspath(out))
    try:
        store = out / STORE
        previous = _current(store)
        _clean(out, store, keep={previous})
        run = Path(tempfile.mkdtemp(prefix=RUN_PREFIX, dir=store))
        try:
            os.chmod(run, 0o777 & ~umask())  # mkdtemp's 0700 would hide it from colleagues
            write(run)
            produced = sorted(p.name for p in run.iterdir() if not p.name.startswith("."))
            mine = set(produced) | set(owned or ())
            _check_names(out, run, produced)
            if previous is not None:
                _carry(store / previous, run, mine)
                _adopt(out, store / previous, mine - set(produced))
            _switch(store, run.name)  # the one rename that publishes the run
        except BaseException:
            shutil.rmtree(run, ignore_errors=True)
            raise
        _claims[key].published = True
        products = sorted(p.name for p in run.iterdir() if not p.name.startswith("."))
        _link_products(out, products, dropped=mine - set(products))
        _clean(out, store, keep={run.name, previous})
        return {name: out / name for name in produced}
    except OSError as exc:
        raise _error(out, exc) from None
    finally:
        release(out)


def published(folder: Path) -> Path:
    """The folder holding the products last published into ``folder``, resolved once.

    A reader that opens several products of one run (kb.pl, facts/,
    recording/) reads them all from here, so a run published meanwhile cannot
    give it a mix. A folder of the older layout (no ``.neurosym``) is itself.
    """
    name = _current(folder / STORE)
    return (folder / STORE / name).resolve() if name is not None else folder


def _current(store: Path) -> str | None:
    """The run folder ``current`` names, None before the first run (or if it is gone)."""
    try:
        name = os.readlink(store / CURRENT)
    except OSError:
        return None
    return name if (store / name).is_dir() else None


def _clean(out: Path, store: Path, keep: set[str | None]) -> None:
    """Remove run folders but ``keep`` (killed or superseded runs) and what the older layout left."""
    for entry in store.iterdir():
        if entry.name.startswith(RUN_PREFIX) and entry.name not in keep:
            shutil.rmtree(entry, ignore_errors=True)
        elif entry.name.startswith(f".{CURRENT}."):  # a link a killed run had not renamed yet
            entry.unlink(missing_ok=True)
    for entry in out.iterdir():
        name = entry.name
        if name.startswith(_LEGACY_STAGES) and entry.is_dir() and not entry.is_symlink():
            pid = name.lstrip(".").partition("-")[2].split("-", 1)[0]
            if pid.isdigit() and not _alive(int(pid)):
                shutil.rmtree(entry, ignore_errors=True)
        elif name.startswith(".") and ".old-" in name:
            product, _, pid = name[1:].rpartition(".old-")
            if pid.isdigit() and not _alive(int(pid)) and entry.is_dir():
                if (out / product).exists():
                    shutil.rmtree(entry, ignore_errors=True)
                else:  # killed between moving the old folder aside and the new one in
                    os.replace(entry, out / product)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _check_names(out: Path, run: Path, names: list[str]) -> None:
    """Refuse, before publishing, a name in ``out`` a product's link may not replace.

    A link or a product of the same kind (a file for a file, a folder for a
    folder) is replaced; a device, FIFO or socket, or a folder where a file
    goes, is refused in one line.
    """
    for name in names:
        target = out / name
        if target.is_symlink() or not os.path.lexists(target):
            continue
        if (run / name).is_dir():
            ok, kind = target.is_dir(), file_kind(target) or "a regular file"
        else:
            kind = file_kind(target)
            ok = kind is None
        if not ok:
            what = "a folder" if (run / name).is_dir() else "a regular file"
            raise OutputError(
                f"cannot write {target}: it exists and is {kind}, not {what}; nothing was written"
            )


def _carry(old: Path, run: Path, mine: set[str]) -> None:
    """Bring the previous run's products that are not this command's into the new run folder."""
    for entry in old.iterdir():
        if entry.name in mine or entry.name.startswith("."):
            continue
        if entry.is_dir() and not entry.is_symlink():
            shutil.copytree(entry, run / entry.name, symlinks=True, copy_function=_link_or_copy)
        else:
            _link_or_copy(entry, run / entry.name)


def _adopt(out: Path, old: Path, names: Iterable[str]) -> None:
    """Make each regular file ``out/NAME`` this run drops a link into ``current`` first.

    Such a file was written into ``out`` outside :func:`publish` (the page
    ``neurosym report --recording`` writes beside extract's products). Kept
    in the previous run's folder and linked like a product, it still reads
    the same until the rename that publishes the run, which removes it in
    the same step: no reader sees it beside the new run's products.
    """
    for name in names:
        target = out / name
        if target.is_symlink() or not target.is_file() or (old / name).is_dir():
            continue  # a folder there: removed after the rename, as before
        kept = old / f".adopt-{os.getpid()}-{name}"
        kept.unlink(missing_ok=True)
        _link_or_copy(target, kept)
        os.replace(kept, old / name)
        link = out / STORE / f".link-{os.getpid()}-{name}"
        link.unlink(missing_ok=True)
        os.symlink(f"{STORE}/{CURRENT}/{name}", link)
        os.replace(link, target)


def _link_or_copy(src: str | Path, dst: str | Path) -> None:
    """A hard link (no second copy of the bytes), or a copy where the file system has none."""
    try:
        os.link(src, dst, follow_symlinks=False)
    except OSError:
        shutil.copy2(src, dst, follow_symlinks=False)


def _switch(store: Path, run: str) -> None:
    """Point ``current`` at ``run`` in one rename of a new link over the old one."""
    tmp = store / f".{CURRENT}.{os.getpid()}"
    tmp.unlink(missing_ok=True)
    os.symlink(run, tmp)
    os.replace(tmp, store / CURRENT)


def _link_products(out: Path, names: list[str], dropped: set[str]) -> None:
    """Make ``out/NAME`` the link into ``current`` for every product; remove the dropped ones.

    Once made, a product's link stays the same from run to run: publishing
    the next run changes only ``current``. A regular file or folder of the
    older layout is replaced by its link here.
    """
    for name in names:
        target, link = out / name, f"{STORE}/{CURRENT}/{name}"
        if target.is_symlink() and os.readlink(target) == link:
            continue
        tmp = out / STORE / f".link-{os.getpid()}-{name}"
        tmp.unlink(missing_ok=True)
        os.symlink(link, tmp)
        if target.is_dir() and not target.is_symlink():
            if _exchange(tmp, target):
                shutil.rmtree(tmp, ignore_errors=True)  # tmp now holds the old folder
                continue
            shutil.rmtree(target)
        os.replace(tmp, target)
    for name in dropped:
        target = out / name
        if target.is_symlink() and os.readlink(target) == f"{STORE}/{CURRENT}/{name}":
            target.unlink()
        elif target.is_dir() and not target.is_symlink():
            shutil.rmtree(target, ignore_errors=True)  # the older layout's copy
        elif target.is_file():
            target.unlink()


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths in one step (Linux renameat2 RENAME_EXCHANGE); False where unsupported."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        renameat2 = libc.renameat2
    except (OSError, AttributeError):
        return False
    at_fdcwd, rename_exchange = -100, 2
    return renameat2(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), rename_exchange) == 0
