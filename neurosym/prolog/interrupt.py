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

A call that stays inside one foreign function (a huge ``X is 7^20000000``)
stops when that function returns.

    >>> with interruptible():
    ...     janus.query_once("sleep(1000)")   # Ctrl-C: KeyboardInterrupt
"""

from __future__ import annotations

import os
import select
import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

MODULE = "neurosym_interrupt"

SOURCE = r"""
:- module(neurosym_interrupt, [stop/1]).

%   stop(+Block): posted to the main thread by the watcher; aborts the goal
%   while interruptible block Block still runs.
stop(Block) :-
    py_call('neurosym.prolog.interrupt':running(Block), Running),
    (   Running == @(true)
    ->  abort
    ;   true
    ).
"""

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


def _noted(signum: int, frame: Any) -> None:
    """SIGINT handler inside a block: note it; the block raises KeyboardInterrupt when it ends."""
    _state.requested = True


@contextmanager
def interruptible() -> Iterator[None]:
    """Run janus calls so that Ctrl-C stops them with KeyboardInterrupt (see the module docstring).

    Nested blocks and blocks outside the main thread, or while SIGINT is
    ignored, run as they are.
    """
    if (
        threading.current_thread() is not threading.main_thread()
        or _state.block != 0
        or signal.getsignal(signal.SIGINT) in (signal.SIG_IGN, None)
    ):
        yield
        return
    _start_watcher()
    previous = signal.signal(signal.SIGINT, _noted)
    old_fd = signal.set_wakeup_fd(_state.write_fd, warn_on_full_buffer=False)
    _state.blocks += 1
    _state.requested = False
    _state.block = _state.blocks
    try:
        yield
    except BaseException:
        if not _state.requested:
            raise
    finally:
        _state.block = 0
        signal.set_wakeup_fd(old_fd)
        signal.signal(signal.SIGINT, previous)
    if _state.requested:
        _state.requested = False
        raise KeyboardInterrupt
