"""The one place that finds SWI-Prolog and hands janus-swi its home.

janus-swi needs SWI-Prolog >= 9.1.12. When an older system Prolog is around,
janus can pick up the wrong home and die with "incompatible VM-signature", so
neurosym decides which Prolog to use, in this order:

1. ``NEUROSYM_SWIPL``: the path of a ``swipl`` binary (must be >= 9.1.12);
2. ``<sys.prefix>/bin/swipl``: the link ``neurosym setup-prolog`` puts into the venv, then
   ``<sys.prefix>/swipl/bin/swipl``: the Prolog it builds there when none is found;
3. ``swipl`` on ``PATH``, when it is >= 9.1.12.

Without one, or without janus-swi, the one-line error says to run ``neurosym setup-prolog``.

:func:`import_janus` sets ``SWI_HOME_DIR`` to that Prolog's home before the
first ``import janus_swi``; every neurosym module gets janus from there.
:func:`swipl_executable` is for subprocess uses (qcompile, plunit runs).
"""

from __future__ import annotations

import functools
import os
import shutil
import subprocess
import sys
import threading
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

from neurosym.errors import NeurosymError

MIN_VERSION = 90112  # 9.1.12 as current_prolog_flag(version) numbers it
ENV_VAR = "NEUROSYM_SWIPL"


@dataclass(frozen=True)
class SwiProlog:
    """A located SWI-Prolog: its binary, home (PLBASE) and numeric version."""

    executable: Path
    home: Path
    version: int

    @property
    def version_text(self) -> str:
        return f"{self.version // 10000}.{self.version // 100 % 100}.{self.version % 100}"


def _probe(executable: Path) -> SwiProlog | None:
    """Ask ``swipl --dump-runtime-variables`` for its home and version; None if it cannot run."""
    try:
        out = subprocess.run(
            [str(executable), "--dump-runtime-variables"],
            capture_output=True, text=True, timeout=30, check=True,
        ).stdout  # fmt: skip
    except (OSError, subprocess.SubprocessError):
        return None
    values = {}
    for line in out.splitlines():  # lines look like: PLBASE="/usr/lib/swipl";
        name, sep, value = line.partition("=")
        if sep:
            values[name.strip()] = value.strip().rstrip(";").strip('"')
    try:
        return SwiProlog(executable, Path(values["PLBASE"]), int(values["PLVERSION"]))
    except (KeyError, ValueError):
        return None


SETUP_HINT = "run `neurosym setup-prolog`"
"""what every "no Prolog" and "no janus" error tells the user to run"""


def check_swipl(executable: Path, name: str) -> SwiProlog:
    """The SWI-Prolog at ``executable``, which the user named as ``name`` (``NEUROSYM_SWIPL=...``,
    ``--swipl ...``); a one-line NeurosymError when it does not run or is older than 9.1.12."""
    found = _probe(executable)
    if found is None:
        raise NeurosymError(
            f"{name} is not a runnable swipl; point it at a SWI-Prolog >= 9.1.12 binary"
        )
    if found.version < MIN_VERSION:
        raise NeurosymError(f"{name} is SWI-Prolog {found.version_text}; janus-swi needs >= 9.1.12")
    return found


@functools.cache
def find_swipl() -> SwiProlog:
    """Locate the SWI-Prolog neurosym uses (see the module docstring for the order)."""
    explicit = os.environ.get(ENV_VAR)
    if explicit:
        return check_swipl(Path(explicit), f"{ENV_VAR}={explicit}")
    prefix = Path(sys.prefix)
    for venv_swipl in (prefix / "bin" / "swipl", prefix / "swipl" / "bin" / "swipl"):
        if venv_swipl.is_file():
            found = _probe(venv_swipl)
            if found is not None and found.version >= MIN_VERSION:
                return found
    on_path = shutil.which("swipl")
    if on_path:
        found = _probe(Path(on_path))
        if found is not None and found.version >= MIN_VERSION:
            return found
        version = found.version_text if found else "unknown"
        raise NeurosymError(
            f"swipl on PATH ({on_path}) is version {version}; neurosym needs SWI-Prolog >= 9.1.12: "
            f"{SETUP_HINT} (builds one into the venv) or set {ENV_VAR}"
        )
    raise NeurosymError(
        f"no SWI-Prolog found: {SETUP_HINT} (builds one into the venv) or set {ENV_VAR} to a swipl >= 9.1.12"
    )


def swipl_executable() -> Path:
    """Path of the ``swipl`` binary to run in subprocesses."""
    return find_swipl().executable


def import_janus() -> ModuleType:
    """Import janus-swi with ``SWI_HOME_DIR`` pointing at the located Prolog's home."""
    module = sys.modules.get("janus_swi")
    if module is not None:
        return module
    os.environ["SWI_HOME_DIR"] = str(find_swipl().home)
    try:
        import janus_swi
    except ImportError as exc:
        raise NeurosymError(
            f"janus-swi is not installed ({exc}): {SETUP_HINT}, which builds it against "
            f"{find_swipl().executable}"
        ) from exc
    return janus_swi


_consulted: set[str] = set()
_consult_lock = threading.Lock()


def janus_with(*modules: ModuleType) -> ModuleType:
    """janus with each embedded Prolog module consulted, in order, once per process.

    Each is a Python module holding its Prolog module's ``MODULE`` name and
    ``FILE``, the path of its ``.pl`` file shipped in the package, and
    optionally ``SETUP``, a ``(goal, inputs)`` pair run once right after the
    file is loaded."""
    janus = import_janus()
    if any(m.MODULE not in _consulted for m in modules):
        with _consult_lock:
            for m in modules:
                if m.MODULE not in _consulted:
                    _consult(janus, m)
                    _consulted.add(m.MODULE)
    return janus


def _consult(janus: ModuleType, module: ModuleType) -> None:
    """Load one embedded Prolog module: its ``FILE``, then its ``SETUP`` goal if it has one."""
    janus.consult(str(module.FILE))
    setup = getattr(module, "SETUP", None)
    if setup is not None:
        janus.query_once(*setup)
