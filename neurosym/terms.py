"""A small representation of Prolog terms on the Python side, and its canonical text.

Environments describe events and held items with terms such as
``picked(sword)`` or ``opened(lock(red))``. They are built as ``Term`` values
so that nothing downstream has to parse strings; ``str(term)`` gives the
canonical Prolog text, which is what recordings store in their tables and what
the fact writer (:mod:`neurosym.facts.prolog_writer`) writes.

This module is the single authority on how a Python value is spelled in
Prolog:

* ``str`` -> atom, bare when it is a plain identifier (``[a-z][A-Za-z0-9_]*``),
  quoted otherwise (uppercase or digit first, spaces, quotes, backslashes,
  unicode, symbol chars/operators, the empty atom). Control characters are
  written as ``\\xHH\\`` escapes; lone surrogates cannot be written.
* ``bool`` -> ``true`` / ``false`` (read back as the atoms, i.e. ``str``).
* ``int`` -> integer (any size); ``float`` -> float text that SWI-Prolog reads
  back to the identical double (``-0.0`` and subnormals included). NaN and
  infinities are refused with :class:`~neurosym.errors.FactError`.
* ``Term`` -> compound in functional notation, no spaces: ``f(a,'B',1.5)``;
  operators are never written infix (``'-'(1)``, not ``-1``).
* ``tuple`` / ``list`` inside a ``Term`` -> Prolog list ``[a,b]``.
* :class:`Var` (an unbound variable inside an answer) -> its name, ``_G1``.

Terms cross between Prolog and Python at most :data:`MAX_DEPTH` levels deep
(a compound or a list is one level): deeper ones are refused with one line,
where Python's recursion or SWI-Prolog's C stack would otherwise give out.

:func:`parse_term` reads that canonical text back (``parse_term(str(t)) == t``
for every compound ``t``); a ``Term`` with no arguments is the atom itself.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import TypeAlias

from neurosym.errors import FactError

MAX_DEPTH = 100
"""The deepest nesting of a term that passes between Prolog and Python (facts, answers, inputs)."""

_SOLO_ATOM = re.compile(r"[a-z][A-Za-z0-9_]*")
# Characters that must be escaped inside a quoted atom: the quote and the
# backslash, and every control character (C0, DEL, C1), which SWI-Prolog
# would otherwise reject or mangle in a quoted atom.
_NEEDS_ESCAPE = re.compile(r"[\\'\x00-\x1f\x7f-\x9f]")
_SURROGATE = re.compile(r"[\ud800-\udfff]")
_NAMED_ESCAPES = {"\\": "\\\\", "'": "\\'", "\n": "\\n", "\t": "\\t"}


def _escape_char(match: re.Match[str]) -> str:
    ch = match.group()
    return _NAMED_ESCAPES.get(ch) or f"\\x{ord(ch):x}\\"


def atom_text(name: str) -> str:
    """Prolog text of the atom ``name``: bare when it is a plain identifier, quoted otherwise."""
    if _SOLO_ATOM.fullmatch(name):
        return name
    if _SURROGATE.search(name):
        raise FactError(f"atom {name!r} contains a lone surrogate, which Prolog text cannot hold")
    return "'" + _NEEDS_ESCAPE.sub(_escape_char, name) + "'"


def float_text(value: float) -> str:
    """Prolog text of a finite float that reads back to the identical double."""
    if not math.isfinite(value):
        raise FactError(f"{value!r} cannot be written as a Prolog fact; replace NaN/inf first")
    text = repr(float(value))
    mantissa, e, exponent = text.partition("e")
    if not e:
        return text
    if "." not in mantissa:  # Python's '1e-05' -> '1.0e-5' (ISO Prolog wants the dot)
        mantissa += ".0"
    return f"{mantissa}e{int(exponent)}"


TermArg: TypeAlias = "str | int | float | Term | Var | tuple[TermArg, ...]"


@dataclass(frozen=True, slots=True)
class Var:
    """An unbound Prolog variable inside an answer; ``str()`` is its name, e.g. ``_G1``.

    Variables of one answer share names: ``X = f(Y, Y)`` gives ``f(_G1,_G1)``.
    """

    name: str

    def __str__(self) -> str:
        return self.name


@dataclass(frozen=True, slots=True)
class Term:
    """A compound term ``functor(args...)``; args are str (atoms), int, float, Term or tuple (lists)."""

    functor: str
    args: tuple[TermArg, ...] = ()

    def __post_init__(self) -> None:
        if not isinstance(self.functor, str):
            raise TypeError(f"Term functor must be a str, not {type(self.functor).__name__}")
        args = self.args
        if not isinstance(args, tuple) or any(isinstance(a, list | tuple) for a in args):
            # keep Terms hashable: (nested) lists become tuples
            object.__setattr__(self, "args", tuple(_freeze(a) for a in args))

    def __str__(self) -> str:
        if not self.args:
            return atom_text(self.functor)
        if len(self.args) == 2 and self.functor in _RESERVED_PAIRS:
            raise FactError(_RESERVED_PAIRS[self.functor])
        parts = []
        for arg in self.args:  # a loop, not a generator: one Python frame per level
            parts.append(format_value(arg))
        return f"{atom_text(self.functor)}({','.join(parts)})"


# Binary functors whose text SWI-Prolog 7+ reads as something else.
_RESERVED_PAIRS = {
    ".": "a '.'/2 compound cannot be written as Prolog text: SWI-Prolog reads '.'(A, B) "
    "as dict access; use another functor",
    "[|]": "a '[|]'/2 compound cannot be written as Prolog text: SWI-Prolog reads it as a "
    "list cell; pass a Python list instead",
}


def _freeze(value: object) -> object:
    if isinstance(value, list | tuple):
        return tuple(_freeze(v) for v in value)
    return value


def format_value(value: object) -> str:
    """Canonical Prolog text of one Python value (see the module docstring for the mapping)."""
    if isinstance(value, str):
        return atom_text(value)
    if isinstance(value, Term | Var):
        return str(value)
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return float_text(value)
    if isinstance(value, tuple | list):
        parts = []
        for item in value:
            parts.append(format_value(item))
        return "[" + ",".join(parts) + "]"
    # numpy scalars and the like, without importing numpy here
    kind = getattr(getattr(value, "dtype", None), "kind", None)
    if kind == "b":
        return "true" if bool(value) else "false"
    if kind in ("i", "u"):
        return str(int(value))  # type: ignore[call-overload]
    if kind == "f":
        return float_text(float(value))  # type: ignore[arg-type]
    raise FactError(f"cannot write a {type(value).__name__} ({value!r}) as a Prolog term")


# ---------------------------------------------------------------------------
# Reading canonical text back

ParsedTerm: TypeAlias = "Term | str | int | float | tuple[ParsedTerm, ...]"

_TOKEN = re.compile(
    r"""
    \s*(?:
      (?P<float>-?\d+(?:\.\d+(?:[eE][+-]?\d+)?|[eE][+-]?\d+))
    | (?P<int>-?\d+)
    | (?P<name>[a-z][A-Za-z0-9_]*)
    | (?P<quoted>'(?:[^'\\]|\\x[0-9a-fA-F]+\\|\\[0-7]+\\|\\.|'')*')
    | (?P<var>[A-Z_][A-Za-z0-9_]*)
    | (?P<punct>[(),\[\]|])
    | (?P<symbol>[+\-*/\\^<>=~:.?@\#&$]+|!|;|\{\})
    )""",
    re.VERBOSE | re.DOTALL,
)
_SIMPLE_ESCAPES = {
    "\\": "\\", "'": "'", '"': '"', "`": "`", "n": "\n", "t": "\t", "r": "\r",
    "a": "\a", "b": "\b", "f": "\f", "v": "\v", "0": "\0", "e": "\x1b", "s": " ",
    "\n": "",
}  # fmt: skip
_ESCAPE = re.compile(
    r"\\(x[0-9a-fA-F]+\\|[0-7]+\\|u[0-9a-fA-F]{4}|U[0-9a-fA-F]{8}|.)|''", re.DOTALL
)


def _unescape(match: re.Match[str]) -> str:
    seq = match.group(1)
    if seq is None:  # doubled quote
        return "'"
    if seq[0] == "x":
        return chr(int(seq[1:-1], 16))
    if seq[0] in "uU":
        return chr(int(seq[1:], 16))
    if seq[0].isdigit() and seq.endswith("\\"):
        return chr(int(seq[:-1], 8))
    if seq in _SIMPLE_ESCAPES:
        return _SIMPLE_ESCAPES[seq]
    raise FactError(f"unknown escape sequence \\{seq} in a quoted atom")


class _TermParser:
    """Recursive descent over the canonical text: atoms, numbers, compounds, lists."""

    def __init__(self, text: str) -> None:
        self.text = text
        self.pos = 0
        self.depth = 0

    def fail(self, what: str) -> FactError:
        return FactError(
            f"cannot read {_shorten(self.text)!r} as a Prolog term: {what} at character {self.pos}"
        )

    def next(self) -> tuple[str, str]:
        match = _TOKEN.match(self.text, self.pos)
        if not match or match.lastgroup is None:
            rest = self.text[self.pos :].strip()
            raise self.fail(f"unexpected {rest[:1]!r}" if rest else "unexpected end")
        self.pos = match.end()
        return match.lastgroup, match.group(match.lastgroup)

    def peek_open(self) -> bool:
        """True when a '(' follows immediately (functional notation allows no space)."""
        return self.text.startswith("(", self.pos)

    def term(self) -> ParsedTerm:
        kind, tok = self.next()
        if kind == "int":
            return int(tok)
        if kind == "float":
            return float(tok)
        if kind == "var":
            raise self.fail(f"variable {tok} (facts are ground)")
        if kind == "punct":
            if tok == "[":
                return self.items("]")
            raise self.fail(f"unexpected {tok!r}")
        name = _ESCAPE.sub(_unescape, tok[1:-1]) if kind == "quoted" else tok
        if self.peek_open():
            self.pos += 1
            return Term(name, self.items(")"))
        return name

    def items(self, close: str) -> tuple[ParsedTerm, ...]:
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise self.fail(f"a term nested more than {MAX_DEPTH} levels deep")
        try:
            return self._items(close)
        finally:
            self.depth -= 1

    def _items(self, close: str) -> tuple[ParsedTerm, ...]:
        if close == "]" and self.text[self.pos :].lstrip().startswith("]"):
            self.next()
            return ()
        out = [self.term()]
        while True:
            kind, tok = self.next()
            if tok == ",":
                out.append(self.term())
            elif tok == close:
                return tuple(out)
            else:
                raise self.fail(f"expected ',' or {close!r}, found {tok!r}")


def _shorten(text: str, most: int = 80) -> str:
    return text if len(text) <= most else text[: most - 3] + "..."


def parse_term(text: str) -> ParsedTerm:
    """Read the canonical Prolog text of one ground term back into Python.

    Atoms -> ``str``, integers -> ``int``, floats -> ``float``, compounds ->
    :class:`Term`, lists -> ``tuple``. Raises :class:`FactError` naming the
    position of anything else (variables, operators written infix, trailing text).
    """
    parser = _TermParser(text)
    value = parser.term()
    if text[parser.pos :].strip():
        raise parser.fail("trailing text")
    return value
