"""A strategy file for ``neurosym play``: its path and the fact sets it reads.

A strategy (``neurosym induce strategy``, or one written by hand)
defines ``goal(E, T, Object)`` and declares near its top, in a line of its
own, which facts it reads::

    %! features: world        (at/5, holding/3, object/2, terrain/4, grid/3, ...)
    %! features: relations    (the network's holds/5, attends/8, attention/6)
    %! features: both

A file without the line reads the world's facts. Relations need the network
that made them: ``neurosym play --checkpoint``.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

from neurosym.errors import ConfigError

FEATURES = ("world", "relations", "both")
_LINE = re.compile(r"^\s*%!\s*features\s*:\s*(\S+)\s*$")
_HEAD_LINES = 60
"""the features line is looked for in the file's first lines"""


@dataclass(frozen=True)
class Policy:
    """A strategy file and what it reads."""

    path: Path
    features: str

    @property
    def needs_network(self) -> bool:
        """True when the strategy reads the network's relation facts."""
        return self.features in ("relations", "both")


def read_policy(path: str | os.PathLike[str]) -> Policy:
    """The strategy file at ``path``; ConfigError (one line) when missing or its features line is bad."""
    file = Path(path)
    if not file.is_file():
        raise ConfigError(
            f"no such policy file: {file} (give a strategy .pl that defines goal(E, T, Object), "
            "e.g. one written by neurosym induce strategy)"
        )
    try:
        with file.open(encoding="utf-8") as handle:
            head = [line for _, line in zip(range(_HEAD_LINES), handle, strict=False)]
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"cannot read policy file {file}: {exc}") from None
    features = "world"
    for line in head:
        match = _LINE.match(line)
        if match:
            features = match.group(1)
            break
    if features not in FEATURES:
        raise ConfigError(f"{file}: '%! features: {features}' is not one of {', '.join(FEATURES)}")
    return Policy(file, features)
