"""Quick-load files: compile a Prolog source to ``.qlf`` with a swipl subprocess.

Consulting runs at roughly 70k facts/s; loading the same facts from a ``.qlf``
is about 20 times faster. ``qcompile`` runs in a separate ``swipl`` (the one
:mod:`neurosym.prolog.locate` finds, so the ``.qlf`` matches the Prolog janus
embeds) so that compiling never loads anything into this process. SWI-Prolog
writes the ``.qlf`` through a staging file, so readers never see half of one.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

from neurosym.atomic import atomic_write
from neurosym.errors import OutputError, PrologError
from neurosym.prolog import signature
from neurosym.prolog.locate import swipl_executable
from neurosym.terms import atom_text

QLF_MODULE = "neurosym_qlf"


def qlf_path(source: Path | str) -> Path:
    """Where ``qcompile`` puts the quick-load file of ``source``: same stem, ``.qlf``."""
    return Path(source).with_suffix(".qlf")


def is_fresh(source: Path | str) -> bool:
    """True when the ``.qlf`` of ``source`` exists and is not older than the source."""
    source, target = Path(source), qlf_path(source)
    return target.is_file() and target.stat().st_mtime_ns >= source.stat().st_mtime_ns


def qcompile(source: Path | str, target: Path | str | None = None) -> Path:
    """Compile ``source`` into a ``.qlf``, sign it, and return where it was put.

    The ``.qlf`` is built beside ``source`` (same stem) and, when ``target``
    is given, copied there atomically. Compiling runs the source's
    directives (in a separate swipl), so only call this on a source that is
    trusted or has been checked as data, and only on a file nobody else can
    change meanwhile (one neurosym just wrote, or a private copy,
    :mod:`neurosym.prolog.snapshot`): the signature
    (:mod:`neurosym.prolog.signature`) is made from the bytes compiled and the
    bytes built, so later loads tell this ``.qlf`` from one that came from
    elsewhere. Raises :class:`PrologError` with swipl's first error (file:line
    included) when the source does not compile cleanly (no ``.qlf`` is left
    behind then), :class:`~neurosym.errors.OutputError` when ``target``
    cannot be written.
    """
    source = Path(source).resolve()
    built = _compile(source)
    qlf_sha, source_sha = signature.sha256(built), signature.sha256(source)
    if target is None or Path(target).resolve() == built:
        signature.sign_digests(built, qlf_sha, source_sha)
        return built
    target = Path(target)
    try:
        signature.signature_path(target).unlink(missing_ok=True)  # stale until signed again
    except OSError as exc:
        raise OutputError(f"cannot write {target}: {exc.strerror}; it was left as it was") from None
    atomic_write(target, lambda tmp: shutil.copyfile(built, tmp))
    signature.sign_digests(target, qlf_sha, source_sha)
    return target


def _compile(source: Path) -> Path:
    """swipl's qcompile of ``source``: the ``.qlf`` beside it."""
    target = qlf_path(source)
    # Compiled in module neurosym_qlf: the .qlf replays directives qualified with
    # it, and neurosym's bridge forwards dynamic/discontiguous/multifile from
    # there to the KB module that loads the file.
    goal = f"qcompile({QLF_MODULE}:{atom_text(str(source))})"
    cmd = [str(swipl_executable()), "-f", "none", "--no-packs", "-q", "--on-error=status",
           "-g", goal, "-t", "halt"]  # fmt: skip
    try:
        signature.signature_path(target).unlink(missing_ok=True)  # stale until signed again
    except OSError as exc:
        raise OutputError(f"cannot write {target}: {exc.strerror}; it was left as it was") from None
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0 or not target.is_file():
        target.unlink(missing_ok=True)
        lines = [ln.strip() for ln in proc.stderr.splitlines() if ln.strip()]
        errors = [ln.removeprefix("ERROR: ") for ln in lines if ln.startswith("ERROR:")]
        detail = (
            errors[0] if errors else (lines[0] if lines else f"swipl exited with {proc.returncode}")
        )
        more = f" (and {len(errors) - 1} more errors)" if len(errors) > 1 else ""
        raise PrologError(f"qcompile {source} failed: {detail}{more}")
    return target
