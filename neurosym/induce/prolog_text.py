"""The Prolog text induce copies into learned files, read from the package's pl/ folder.

Each ``neurosym/induce/pl/NAME.pl`` opens with a ``/* ... */`` comment that says what
the file is; the text after it is what a learned file carries, byte for byte.
"""

from __future__ import annotations

from functools import cache
from importlib import resources


@cache
def pl_text(name: str) -> str:
    """The text of ``neurosym/induce/pl/NAME`` after its opening comment."""
    text = (resources.files("neurosym.induce") / "pl" / name).read_text(encoding="utf-8")
    return text.split("*/\n", 1)[1]
