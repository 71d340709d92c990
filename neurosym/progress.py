"""Progress displays on stderr: the stages of ``neurosym probe`` and ``intervene``, and a
column of figures for the training bar that never cuts a figure in a narrow terminal.

:class:`Stages` is shown only when asked (the commands ask when stderr is a
terminal) and is transient: nothing of it stays on the screen or reaches a pipe.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from rich.console import Console, ConsoleOptions, RenderResult
from rich.measure import Measurement
from rich.progress import ProgressColumn, Task
from rich.text import Text

from neurosym.display import show

FIELD_SEPARATOR = "  "
"""between two figures of a :class:`FieldsColumn` (one space stays inside a figure: ``29 %``)"""


class Fields:
    """Figures separated by two spaces, shown whole: those that do not fit the width are left
    out, from the last, rather than one cut mid-word (``succes…``) or wrapped (``29`` / ``%``)."""

    def __init__(self, text: str, style: str = "") -> None:
        self.fields = [f for f in text.split(FIELD_SEPARATOR) if f.strip()]
        self.style = style

    def __rich_measure__(self, console: Console, options: ConsoleOptions) -> Measurement:
        whole = len(FIELD_SEPARATOR.join(self.fields))
        return Measurement(min(whole, len(self.fields[0]) if self.fields else 0), whole)

    def __rich_console__(self, console: Console, options: ConsoleOptions) -> RenderResult:
        shown: list[str] = []
        for field in self.fields:
            if len(FIELD_SEPARATOR.join([*shown, field])) > options.max_width:
                break
            shown.append(field)
        yield Text(FIELD_SEPARATOR.join(shown), style=self.style, no_wrap=True, overflow="crop")


class FieldsColumn(ProgressColumn):
    """A progress column showing the task field ``name`` as :class:`Fields`."""

    def __init__(self, name: str, style: str = "") -> None:
        self.name, self.style = name, style
        super().__init__()

    def render(self, task: Task) -> Fields:
        return Fields(str(task.fields.get(self.name, "")), self.style)


class Stages:
    """Context manager; :meth:`stage` starts a bar and returns its ``advance(k)``."""

    def __init__(self, enabled: bool) -> None:
        self.enabled = enabled
        self._progress: Any = None
        self._task: Any = None

    def __enter__(self) -> Stages:
        if self.enabled:
            from rich.console import Console
            from rich.progress import (
                BarColumn,
                MofNCompleteColumn,
                Progress,
                TextColumn,
                TimeElapsedColumn,
            )

            self._progress = Progress(
                TextColumn("{task.description}"),
                BarColumn(),
                MofNCompleteColumn(),
                TimeElapsedColumn(),
                console=Console(stderr=True),
                transient=True,
            )
            self._progress.start()
        return self

    def stage(self, description: str, total: int) -> Callable[[int], None]:
        """A bar of ``total`` steps for what comes next (the previous stage's bar goes)."""
        if self._progress is None:
            return lambda k=1: None
        if self._task is not None:
            self._progress.remove_task(self._task)
        task = self._task = self._progress.add_task(show(description), total=total)
        return lambda k=1: self._progress.advance(task, k)

    def describe(self, description: str) -> None:
        """Change the text of the current bar (e.g. the experiment now playing)."""
        if self._progress is not None and self._task is not None:
            self._progress.update(self._task, description=show(description))

    def __exit__(self, *exc: object) -> None:
        if self._progress is not None:
            self._progress.stop()
