"""Where the files neurosym ships are: the rule files and the curated agents.

In a clone they are the repository's ``rules/`` and ``checkpoints/``, beside the
package; an installed wheel carries them inside the package as
``neurosym/rules/`` and ``neurosym/checkpoints/`` (setup.py maps the folders in).
The clone's folders come first, so an editable install reads what is being
edited. A bare name stands for a shipped file: ``--rules rgw`` is
``rgw.pl`` among the rule files, ``--checkpoint rgw2-predinet`` the agent
``rgw2-predinet.pt``.
"""

from __future__ import annotations

import os
from pathlib import Path

from neurosym.errors import ConfigError

_PACKAGE = Path(__file__).resolve().parent


def rules_dir() -> Path | None:
    """The folder of the shipped rule files (``rgw.pl``, ``relations.pl``, ...), or None."""
    for folder in (_PACKAGE.parent / "rules", _PACKAGE / "rules"):
        if (folder / "relations.pl").is_file() and (folder / "rgw.pl").is_file():
            return folder
    return None


def checkpoints_dir() -> Path | None:
    """The folder of the shipped agents (``*.pt``), or None."""
    for folder in (_PACKAGE.parent / "checkpoints", _PACKAGE / "checkpoints"):
        if folder.is_dir() and any(folder.glob("*.pt")):
            return folder
    return None


def shipped_rule_names() -> list[str]:
    """The shipped rule files' names without ``.pl`` (empty when none are found)."""
    folder = rules_dir()
    return sorted(p.stem for p in folder.glob("*.pl")) if folder else []


def _bare(name: str) -> bool:
    return os.sep not in name and "/" not in name and not Path(name).exists()


def rule_file(name: str | os.PathLike[str]) -> Path:
    """A rule file argument as a path: an existing file, or a shipped rule file's bare name.

    ``rgw`` and ``rgw.pl`` name ``rules/rgw.pl`` when no file of that name is
    in the working folder. Anything else is returned as given (the loader
    reports a missing file).
    """
    text = os.fspath(name)
    if not _bare(text):
        return Path(text)
    stem = text[:-3] if text.endswith(".pl") else text
    folder = rules_dir()
    if folder is not None and (folder / f"{stem}.pl").is_file():
        return folder / f"{stem}.pl"
    if "." in text:  # a file name that is not there: the loader says so
        return Path(text)
    names = ", ".join(shipped_rule_names()) or "none found: neurosym's rules/ folder is missing"
    raise ConfigError(f"no rule file {text!r}: give a .pl file or a shipped rule name ({names})")


def checkpoint_file(name: str | os.PathLike[str]) -> Path:
    """A checkpoint argument as a path: an existing file, or a shipped agent's bare name.

    ``rgw2-predinet`` (or ``rgw2-predinet.pt``) names the shipped agent when no
    file of that name is in the working folder; anything else is returned as
    given, so the checkpoint reader reports it.
    """
    text = os.fspath(name)
    if not _bare(text):
        return Path(text)
    stem = text[:-3] if text.endswith(".pt") else text
    folder = checkpoints_dir()
    if folder is not None and (folder / f"{stem}.pt").is_file():
        return folder / f"{stem}.pt"
    return Path(text)


def shipped_agent_names() -> list[str]:
    """The shipped agents' names (file names without ``.pt``)."""
    folder = checkpoints_dir()
    return sorted(p.stem for p in folder.glob("*.pt")) if folder else []
