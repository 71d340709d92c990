"""``neurosym setup-prolog``: SWI-Prolog >= 9.1.12 and janus-swi for this Python environment.

janus-swi, neurosym's bridge to Prolog, compiles against a SWI-Prolog >= 9.1.12
when it is installed, and pip cannot provide one; so it is not a hard dependency
(``pip install neurosym`` works on any machine; ``neurosym[prolog]`` names it for
machines that have such a Prolog on PATH) and this command does the Prolog half:

1. a SWI-Prolog >= 9.1.12: ``--swipl PATH``, else the one neurosym would use
   (:func:`neurosym.prolog.locate.find_swipl`), else 9.2.9 built from source into
   ``<env>/swipl`` by the shipped ``setup_swipl.sh`` (about 70 s on 2 cores);
2. ``<env>/bin/swipl`` linked to it: ``swipl`` works once the environment is
   activated, and neurosym finds it there (:mod:`neurosym.prolog.locate`);
3. janus-swi built against it (pip ``--no-binary janus-swi``, that ``swipl``
   first on PATH, no cached wheel), unless a janus-swi that loads that Prolog's
   library is there already; then janus answers a goal as the check.

``make setup`` runs it too, so a clone and a wheel install the same way.
"""

from __future__ import annotations

import argparse
import importlib
import importlib.metadata
import importlib.resources
import os
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

from neurosym.errors import NeurosymError
from neurosym.flags import add_options, option
from neurosym.prolog.locate import ENV_VAR, SETUP_HINT, SwiProlog, check_swipl, find_swipl

JANUS_REQUIREMENT = "janus-swi>=1.5.3"
"""what pip installs; pyproject.toml's ``prolog`` extra names the same (tests/test_wheel.py)"""

# Run in the environment's Python: janus answers a goal, then the libswipl it loaded is named.
_CHECK = """
import janus_swi
print(janus_swi.query_once("X is 6 * 7")["X"])
try:
    with open("/proc/self/maps") as maps:
        print(next((l.split(None, 5)[-1].strip() for l in maps if "libswipl" in l), ""))
except OSError:
    print("")
"""


@dataclass(kw_only=True)
class SetupOptions:
    """``neurosym setup-prolog``'s options."""

    swipl: str | None = option(None, metavar="PATH")
    """use this swipl binary (SWI-Prolog >= 9.1.12) instead of finding or building one"""


def configure(parser: argparse.ArgumentParser) -> None:
    add_options(parser, SetupOptions)


def run(args: SetupOptions) -> int:
    prefix = Path(sys.prefix)
    own = sys.prefix != sys.base_prefix or os.environ.get("CONDA_PREFIX") == sys.prefix
    if not own or not os.access(prefix / "bin", os.W_OK):  # never the system's /usr/bin
        raise NeurosymError(
            f"{sys.executable} is not a virtual environment's Python that may write to "
            f"{prefix / 'bin'}: run it in one (python3 -m venv .venv && . .venv/bin/activate)"
        )
    swipl, how = choose_swipl(args.swipl, prefix)
    print(f"SWI-Prolog {swipl.version_text}: {swipl.executable} ({how})", flush=True)
    link = link_swipl(prefix, swipl.executable)
    print(f"swipl: {link} -> {os.readlink(link) if link.is_symlink() else link} "
          "(on PATH once the environment is activated)", flush=True)  # fmt: skip
    print(ensure_janus(swipl, link))
    return 0


def choose_swipl(explicit: str | None, prefix: Path) -> tuple[SwiProlog, str]:
    """The SWI-Prolog to use and how it was got: given, found, or built into ``prefix/swipl``."""
    if explicit:
        return check_swipl(Path(explicit).absolute(), f"--swipl {explicit}"), "given"
    if os.environ.get(ENV_VAR):
        return find_swipl(), ENV_VAR  # a bad NEUROSYM_SWIPL is the user's to fix: one line
    try:
        return find_swipl(), "found"
    except NeurosymError as exc:  # what was found, without the advice to run this command
        found = str(exc).partition(SETUP_HINT)[0].rstrip(": ")
        print(f"{found}: building SWI-Prolog into {prefix / 'swipl'}", flush=True)
    built = build_swipl(prefix)
    find_swipl.cache_clear()
    return check_swipl(built, f"the swipl built into {prefix / 'swipl'}"), "built"


def build_swipl(prefix: Path) -> Path:
    """Run the shipped ``setup_swipl.sh`` for ``prefix``: the path of the swipl it built."""
    script = importlib.resources.files("neurosym") / "setup_swipl.sh"
    with importlib.resources.as_file(script) as path:
        proc = subprocess.run(["bash", str(path), str(prefix)], stdout=subprocess.PIPE, text=True)
    lines = proc.stdout.splitlines()
    if proc.returncode != 0 or not lines:
        raise NeurosymError(
            f"building SWI-Prolog into {prefix / 'swipl'} failed (its messages are above); "
            f"or install SWI-Prolog >= 9.1.12 yourself and pass --swipl PATH"
        )
    return Path(lines[-1])


def link_swipl(prefix: Path, executable: Path) -> Path:
    """``prefix/bin/swipl`` made a link to ``executable`` (one rename: never half a link)."""
    link = prefix / "bin" / "swipl"
    if link.exists() and link.resolve() == executable.resolve():
        return link
    if link.exists() and not link.is_symlink():
        raise NeurosymError(
            f"{link} is another program, not a link; remove it or pass --swipl {link}"
        )
    built = prefix / "swipl" / "bin" / "swipl"
    target = os.path.join("..", "swipl", "bin", "swipl") if executable == built else executable
    tmp = link.with_name(f".swipl.{os.getpid()}.tmp")
    tmp.unlink(missing_ok=True)
    os.symlink(target, tmp)
    os.replace(tmp, link)
    return link


def ensure_janus(swipl: SwiProlog, link: Path) -> str:
    """janus-swi loading ``swipl``'s library, built now if it is missing or loads another;
    the line that says which."""
    if janus_loads(swipl):
        return f"janus-swi {_janus_version()}: loads this SWI-Prolog (nothing to build)"
    reinstall = ["--force-reinstall"] if _janus_version() else []
    env = {**os.environ, "PATH": f"{link.parent}{os.pathsep}{os.environ.get('PATH', '')}",
           "SWI_HOME_DIR": str(swipl.home)}  # fmt: skip
    print(f"building {JANUS_REQUIREMENT} against {swipl.executable} with pip", flush=True)
    proc = subprocess.run(
        [sys.executable, "-m", "pip", "install", "-q", "--no-cache-dir", "--no-deps",
         "--no-binary", "janus-swi", *reinstall, JANUS_REQUIREMENT],
        env=env,
    )  # fmt: skip
    importlib.invalidate_caches()
    if proc.returncode != 0:
        raise NeurosymError(
            f"pip could not build {JANUS_REQUIREMENT} against {swipl.executable} "
            "(pip's messages are above)"
        )
    if not janus_loads(swipl):
        raise NeurosymError(
            f"janus-swi {_janus_version()} was built but does not load {swipl.executable}'s library"
        )
    return f"janus-swi {_janus_version()}: built against this SWI-Prolog, answers Prolog goals"


def janus_loads(swipl: SwiProlog) -> bool:
    """Whether janus-swi, in a fresh process of this Python, answers a goal with ``swipl``'s
    libswipl (where the process's memory map names it: Linux)."""
    env = {**os.environ, "SWI_HOME_DIR": str(swipl.home)}
    try:
        proc = subprocess.run([sys.executable, "-c", _CHECK], env=env, capture_output=True,
                              text=True, timeout=120)  # fmt: skip
    except subprocess.TimeoutExpired:
        return False
    lines = proc.stdout.splitlines()
    if proc.returncode != 0 or len(lines) != 2 or lines[0] != "42":
        return False
    libdir = _libdir(swipl)
    return not lines[1] or libdir is None or Path(lines[1]).resolve().parent == libdir


def _libdir(swipl: SwiProlog) -> Path | None:
    """The folder of ``swipl``'s libswipl (``PLLIBDIR``), or None when it does not say."""
    out = subprocess.run([str(swipl.executable), "--dump-runtime-variables"],
                         capture_output=True, text=True, timeout=30).stdout  # fmt: skip
    for line in out.splitlines():
        name, _, value = line.partition("=")
        if name.strip() == "PLLIBDIR":
            return Path(value.strip().rstrip(";").strip('"')).resolve()
    return None


def _janus_version() -> str:
    """The installed janus-swi's version, or "" when there is none."""
    try:
        return importlib.metadata.version("janus-swi")
    except importlib.metadata.PackageNotFoundError:
        return ""
