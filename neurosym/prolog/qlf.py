"""Quick-load files: compile a Prolog source to ``.qlf`` with a swipl subprocess.

Consulting runs at roughly 70k facts/s; loading the same facts from a ``.qlf``
is about 20 times faster. ``qcompile`` runs in a separate ``swipl`` (the one
:mod:`neurosym.prolog.locate` finds, so the ``.qlf`` matches the Prolog janus
embeds) so that compiling never loads anything into this process. SWI-Prolog
writes the ``.qlf`` through a staging file, so readers never see half of one.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

from neurosym.errors import PrologError
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


def qcompile(source: Path | str) -> Path:
    """Compile ``source`` into ``<stem>.qlf`` beside it, sign it, and return that path.

    Compiling runs the source's directives (in a separate swipl), so only
    call this on a source that is trusted or has been checked as data; the
    signature (:mod:`neurosym.prolog.signature`) then lets later loads tell
    this ``.qlf`` from one that came from elsewhere. Raises :class:`PrologError` with swipl's first error (file:line included)
    when the source does not compile cleanly; no ``.qlf`` is left behind then.
    """
    source = Path(source).resolve()
    target = qlf_path(source)
    # Compiled in module neurosym_qlf: the .qlf replays directives qualified with
    # it, and neurosym's bridge forwards dynamic/discontiguous/multifile from
    # there to the KB module that loads the file.
    goal = f"qcompile({QLF_MODULE}:{atom_text(str(source))})"
    cmd = [str(swipl_executable()), "-f", "none", "--no-packs", "-q", "--on-error=status",
           "-g", goal, "-t", "halt"]  # fmt: skip
    signature.signature_path(target).unlink(missing_ok=True)  # stale until signed again
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
    signature.sign(target, source)
    return target
