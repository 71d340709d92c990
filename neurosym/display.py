"""Data shown as text: what a knowledge base, a recording or a file holds reaches the
terminal as characters, never as rich markup, styling, hyperlinks or raw escapes.

Every table the toolkit prints passes its cells through :func:`show`.
"""

from __future__ import annotations

from rich.markup import escape

# Control characters with a conventional short escape; the rest print as \xNN / \uNNNN.
_NAMED = {"\n": "\\n", "\t": "\\t", "\r": "\\r", "\x1b": "\\e"}


def _visible(ch: str) -> str:
    if ch.isprintable():
        return ch
    if ch in _NAMED:
        return _NAMED[ch]
    code = ord(ch)
    return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}"


def plain(value: object) -> str:
    """``str(value)`` with every non-printable character written as a visible escape."""
    text = str(value)
    if text.isprintable():
        return text
    return "".join(_visible(ch) for ch in text)


def show(value: object) -> str:
    """A table cell for rich: :func:`plain`, with rich markup escaped so ``[x]`` prints as ``[x]``."""
    return escape(plain(value))
