"""The exception types neurosym raises on bad input.

Every error a user can cause (a bad map, an unreadable checkpoint, a Prolog
syntax error, a value the fact writer cannot represent) is a NeurosymError.
The CLI prints it as one line and exits non-zero; library users catch one type.
"""

from __future__ import annotations


class NeurosymError(Exception):
    """Base class: a problem with the user's input, reported as one line."""


class ConfigError(NeurosymError, ValueError):
    """An option or parameter out of range, or an unknown name."""


class MapError(NeurosymError, ValueError):
    """A Relational-Grid-World map that cannot be played (names row and column)."""


class CheckpointError(NeurosymError):
    """A checkpoint that is missing, corrupt, foreign, or does not fit the request."""


class FactError(NeurosymError, ValueError):
    """A Python value the Prolog fact writer cannot write faithfully."""


class PrologError(NeurosymError):
    """An error raised inside SWI-Prolog; the message is Prolog's own."""

    def __init__(self, message: str, term: object | None = None) -> None:
        super().__init__(message)
        self.term = term


class OutputError(NeurosymError):
    """A file neurosym could not write (disk full, file-size limit, no permission); one line."""
