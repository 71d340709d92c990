"""Progress of ``neurosym probe`` and ``intervene`` on stderr: one bar per stage, as the recorder's.

Shown only when asked (the commands ask when stderr is a terminal), and
transient: nothing of it stays on the screen or reaches a pipe.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from neurosym.display import show


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
