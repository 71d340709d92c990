"""A learned file is written only when it reads back as exactly the clauses learned.

The writers of learned files (:mod:`neurosym.induce.world`,
:mod:`neurosym.induce.strategy_writer`) spell every value through
:mod:`neurosym.terms`, keep data out of anything but one-line ``%`` comments,
and then hand the text to :func:`check_reads_back` with what it must hold:
the fixed code (directives, background predicates: text of this package,
no data) and each learned clause as a :class:`~neurosym.terms.Term`
structure. SWI-Prolog reads the text with ``read_term/3`` (nothing is run:
no directive, no term expansion, quasi-quotations refused) and compares it,
term by term, with what the parts say; a file that holds one term more or
less, or any term that differs (an atom read as a variable, a quote that
closes early), is refused with one line and not written.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from neurosym.display import plain
from neurosym.errors import OutputError
from neurosym.terms import Term

MODULE = "neurosym_readback"

FILE = Path(__file__).with_name("pl") / "neurosym_readback.pl"
"""The module's source, shipped as package data."""


def comment(text: str) -> str:
    """``text`` as one ``%`` comment line: control characters and newlines shown as escapes,
    so no data can end the comment and become code."""
    return "% " + plain(text) if text else "%"


@dataclass(frozen=True)
class Code:
    """Fixed Prolog text of this package (directives, background predicates): no data in it."""

    text: str


Part = Code | Term
"""What a learned file holds, in order: fixed code, or one learned clause or directive as a term."""


def check_reads_back(text: str, parts: list[Part], path: str | os.PathLike[str]) -> None:
    """Refuse (:class:`OutputError`, one line) a text that does not read back as ``parts``.

    Each :class:`Code` part stands for every term of its text; each
    :class:`Term` part for exactly that term (its :class:`~neurosym.terms.Var`
    arguments are the clause's variables, by name).
    """
    from neurosym.prolog.locate import janus_with

    janus = janus_with(_module())
    kinds = ["code" if isinstance(p, Code) else "term" for p in parts]
    texts = [p.text if isinstance(p, Code) else f"{p} ." for p in parts]
    answer = janus.query_once(
        f"{MODULE}:readback(Text, Kinds, Texts, Result)", {"Text": text, "Kinds": kinds, "Texts": texts}
    )
    difference = str(answer["Result"])
    if difference:
        raise OutputError(
            f"refusing to write {plain(os.fspath(path))}: the learned file would not read back as "
            f"the clauses learned ({plain(difference)}); nothing was written"
        )


def _module():  # type: ignore[no-untyped-def]
    """This module as janus_with's embedded Prolog module (its MODULE and FILE)."""
    import sys

    return sys.modules[__name__]
