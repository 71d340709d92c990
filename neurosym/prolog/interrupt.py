"""Ctrl-C for janus calls: SIGINT stops the Prolog goal running, even inside a blocking foreign call.

Why it is needed: while a janus call runs, Python's main thread is in C, and
Python runs its SIGINT handler only when the call returns; SWI-Prolog, which
janus starts with ``--no-signals``, never sees the signal. A goal blocked in
``sleep/1`` or ``read/1`` (or one that takes no inferences, so that the
heartbeat never calls Python) ignored Ctrl-C; and Python's default handler,
raising KeyboardInterrupt inside janus's own conversion code after such a
call, has crashed the process.

How, inside ``with interruptible():`` (main thread only; elsewhere it does nothing):

* Python's SIGINT handler only notes the signal (no exception inside janus);
* ``signal.set_wakeup_fd``: the C-level handler writes to a pipe even while
  the main thread is in Prolog; a watcher thread reads it and posts
  ``thread_signal(Main, neurosym_interrupt:stop(N))`` to the Prolog thread of
  the main thread, then kicks it out of any blocking system call
  (``pthread_kill``: the call returns EINTR and Prolog handles the signal);
* ``stop(N)`` aborts the goal while block N still runs (``abort/0``: a
  ``catch/3`` in the goal cannot swallow it), and does nothing when the
  signal arrives after the block ended;
* when the block ends after a Ctrl-C, whatever it raised or returned,
  KeyboardInterrupt is raised (the CLI's one line, exit 130).

Installing the handler and the pipe takes system calls (tens of microseconds
here); a loop of many short calls opens :func:`sigint_region` once around the
loop, inside which ``interruptible()`` only marks the call and Ctrl-C outside
a marked call raises KeyboardInterrupt at once, as Python's own handler does.

A call that stays inside one foreign function (a huge ``X is 7^20000000``)
stops when that function returns.

    >>> with interruptible():
    ...     janus.query_once("sleep(1000)")   # Ctrl-C: KeyboardInterrupt
    >>> with sigint_region():                 # many calls: the handler installed once
    ...     for goal in goals:
    ...         with interruptible():
    ...             janus.query_once(goal)
"""

from __future__ import annotations

import os
import select
import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

MODULE = "neurosym_interrupt"

FILE = Path(__file__).resolve().with_name("pl") / "interrupt.pl"
"""the Prolog module (``stop/1``), shipped in the package"""

_KICK_SECONDS = 0.25
"""how often the watcher kicks the main thread again until the block ends"""


class _State:
    """What the watcher thread and the main thread share."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.block = 0  # number of the running block; 0: none
        self.blocks = 0  # blocks started so far
        self.requested = False  # Ctrl-C seen in the running block
        self.posted = 0  # the block the watcher signalled Prolog for
        self.read_fd = -1
        self.write_fd = -1
        self.region = False  # a sigint_region is open
        self.prolog_thread: Any = None
        self.main_ident = threading.main_thread().ident


_state = _State()


def running(block: int) -> bool:
    """Called from Prolog (stop/1): True while interruptible block ``block`` runs."""
    return block != 0 and block == _state.block


def _janus() -> Any:
    import sys

    from neurosym.prolog.locate import janus_with

    return janus_with(sys.modules[__name__])


def _start_watcher() -> None:
    """The pipe and the watcher thread, once per process (in the main thread)."""
    if _state.read_fd >= 0:
        return
    _state.prolog_thread = _janus().query_once("thread_self(T)")["T"]
    read_fd, write_fd = os.pipe()
    os.set_blocking(write_fd, False)
    os.set_blocking(read_fd, False)
    _state.read_fd, _state.write_fd = read_fd, write_fd
    threading.Thread(target=_watch, name="neurosym-interrupt", daemon=True).start()


def _watch() -> None:
    """Watcher thread: on SIGINT during a block, signal Prolog, then kick it until the block ends."""
    while True:
        ready, _, _ = select.select([_state.read_fd], [], [], _KICK_SECONDS)
        seen = False
        if ready:
            try:
                seen = signal.SIGINT in os.read(_state.read_fd, 512)
            except BlockingIOError:
                pass
        block = _state.block
        if block == 0 or not (seen or _state.posted == block):
            continue
        if _state.posted != block:
            _state.posted = block
            try:
                _janus().query_once(
                    "thread_signal(T, neurosym_interrupt:stop(B))",
                    {"T": _state.prolog_thread, "B": block},
                )
            except Exception:  # noqa: BLE001 - the thread may be gone; the kick still helps
                pass
        if _state.block == block and _state.main_ident is not None:
            signal.pthread_kill(_state.main_ident, signal.SIGINT)  # EINTR for a blocking call


def _handler(signum: int, frame: Any) -> None:
    """SIGINT inside a region: noted during a marked call (raised when it ends), raised otherwise."""
    if _state.block:
        _state.requested = True
    else:
        raise KeyboardInterrupt


@contextmanager
def sigint_region() -> Iterator[None]:
    """Install the SIGINT handler and the wakeup pipe for the ``interruptible()`` calls inside.

    Outside the main thread, while SIGINT is ignored, or inside another
    region, it does nothing.
    """
    if (
        _state.region
        or threading.current_thread() is not threading.main_thread()
        or signal.getsignal(signal.SIGINT) in (signal.SIG_IGN, None)
    ):
        yield
        return
    _start_watcher()
    previous = signal.signal(signal.SIGINT, _handler)
    old_fd = signal.set_wakeup_fd(_state.write_fd, warn_on_full_buffer=False)
    _state.region = True
    try:
        yield
    finally:
        _state.region = False
        signal.set_wakeup_fd(old_fd)
        signal.signal(signal.SIGINT, previous)


class interruptible:  # noqa: N801 - used like a function: ``with interruptible():``
    """Run janus calls so that Ctrl-C stops them with KeyboardInterrupt (see the module docstring).

    Opens a :func:`sigint_region` of its own when none is open. Nested
    blocks, and blocks outside the main thread, run as they are. A class,
    not a generator: inside a region it costs a few attribute writes.
    """

    __slots__ = ("_marks", "_region")

    def __enter__(self) -> None:
        self._marks = False
        self._region: Any = None
        if _state.block or threading.get_ident() != _state.main_ident:
            return
        if not _state.region:
            self._region = sigint_region()
            self._region.__enter__()
            if not _state.region:  # SIGINT ignored
                return
        self._marks = True
        _state.blocks += 1
        _state.requested = False
        _state.block = _state.blocks

    def __exit__(self, kind: Any, exc: Any, tb: Any) -> bool:
        if not self._marks:
            return self._close(kind, exc, tb)
        _state.block = 0
        requested, _state.requested = _state.requested, False
        self._close(None, None, None)
        if requested:
            raise KeyboardInterrupt
        return False

    def _close(self, kind: Any, exc: Any, tb: Any) -> bool:
        return bool(self._region is not None and self._region.__exit__(kind, exc, tb))
