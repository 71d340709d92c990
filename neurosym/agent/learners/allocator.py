"""Keep freed memory in the process instead of handing it back to the kernel.

Why: a forward and backward over an update batch allocates and frees tensors
of several megabytes many times (the query projection's input gradient, the
entities' gradient, concatenations). glibc's malloc returns blocks that large
to the kernel (``munmap``, or trimming the heap's top), so the next
allocation of the same size touches fresh pages, and every 4 KB page costs a
page fault, which is expensive on virtual machines
(``experiments/allocator.py`` measures the difference). The PyTorch CPU
performance guides recommend jemalloc or tcmalloc for the same reason;
glibc's own ``mallopt`` switches give the same effect with nothing to install.

What it sets (glibc only; elsewhere it does nothing): no trimming of the heap
(``M_TRIM_THRESHOLD``) and blocks up to 1 GiB from the heap rather than their
own mappings (``M_MMAP_THRESHOLD``; glibc caps it lower on some versions, then
the cap holds). Both are needed: fixing the trim threshold alone also freezes
glibc's adaptive mmap threshold at 128 KB, which slows small batches. The
cost is that a process keeps its peak heap: a learner's memory stays at its
largest batch's size instead of shrinking between updates.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import functools

_M_TRIM_THRESHOLD = -1
_M_MMAP_THRESHOLD = -3


@functools.cache
def _libc() -> ctypes.CDLL | None:
    name = ctypes.util.find_library("c")
    if name is None:
        return None
    try:
        libc = ctypes.CDLL(name)
    except OSError:
        return None
    return libc if hasattr(libc, "mallopt") else None  # glibc (musl and macOS have none)


def keep_freed_memory() -> bool:
    """Ask glibc to keep freed blocks for reuse (module docstring); True if it took every setting.

    Idempotent and cheap: every learner process calls it when it starts. A
    forked child inherits the setting from its parent anyway.
    """
    libc = _libc()
    if libc is None:
        return False
    ok = bool(libc.mallopt(_M_TRIM_THRESHOLD, ctypes.c_int(2**30)))
    mmap_ok = bool(libc.mallopt(_M_MMAP_THRESHOLD, ctypes.c_int(2**30)))
    if not mmap_ok:  # older glibc caps the threshold at 32 MiB on 64-bit machines
        mmap_ok = bool(libc.mallopt(_M_MMAP_THRESHOLD, ctypes.c_int(32 << 20)))
    return ok and mmap_ok
