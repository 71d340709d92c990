"""A small representation of Prolog compound terms on the Python side.

Environments describe events and held items with terms such as
``picked(sword)`` or ``opened(lock(red))``. They are built as ``Term`` values
so that nothing downstream has to parse strings; ``str(term)`` gives the
canonical Prolog text (atoms quoted exactly when Prolog needs it), which is
what recordings store in their tables.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

_SOLO_ATOM = re.compile(r"^[a-z][A-Za-z0-9_]*$")


def atom_text(name: str) -> str:
    """Prolog text of the atom ``name``: bare when it is a plain identifier, quoted otherwise."""
    if _SOLO_ATOM.match(name):
        return name
    escaped = name.replace("\\", "\\\\").replace("'", "\\'").replace("\n", "\\n").replace("\t", "\\t")
    return f"'{escaped}'"


@dataclass(frozen=True, slots=True)
class Term:
    """A compound term ``functor(args...)``; args are str (atoms), int, float or Term."""

    functor: str
    args: tuple[str | int | float | Term, ...] = ()

    def __str__(self) -> str:
        if not self.args:
            return atom_text(self.functor)
        inner = ",".join(_arg_text(a) for a in self.args)
        return f"{atom_text(self.functor)}({inner})"


def _arg_text(value: str | int | float | Term) -> str:
    if isinstance(value, Term):
        return str(value)
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return repr(value)
    return atom_text(value)
