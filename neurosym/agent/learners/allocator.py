"""Keep freed memory in the process instead of handing it back to the kernel.

Why: a forward and backward over an update batch allocates and frees tensors
of 5-15 MB many times (the query projection's input gradient, the entities'
gradient, concatenations). glibc's malloc returns blocks that large to the
kernel (``munmap``, or trimming the heap's top), so the next allocation of the
same size touches fresh pages, and every 4 KB page costs a page fault. On the
virtual machines this project runs on, a fault is expensive: measured on the
2-core development VM, one rgw2 update batch (1,352 observations, PrediNet)
took 145 ms with 23 k page faults (36 ms of it in the kernel) and 107 ms with
none once freed memory was kept; MHDPA's 717 ms with 79 k faults, 621 ms
(``python experiments/allocator.py``). Small batches gain little (a bw1 PrediNet
batch of 368 faulted little either way). The PyTorch CPU performance guides recommend
jemalloc or tcmalloc for the same reason; glibc's own ``mallopt`` switches
give the same effect here with nothing to install.

What it sets (glibc only; elsewhere it does nothing): no trimming of the heap
(``M_TRIM_THRESHOLD``) and blocks up to 1 GiB from the heap rather than their
own mappings (``M_MMAP_THRESHOLD``; glibc caps it lower on some versions, then
the cap holds). Both are needed: fixing the trim threshold alone also freezes
glibc's adaptive mmap threshold at 128 KB, and A3C on bw1 with K = 1 then ran
at half speed. 64 MiB of head room when the heap grows (``M_TOP_PAD``) was
tried and dropped: no fewer faults, and K = 1 ran ~8 % slower with it. The
cost is that a process keeps its peak heap: a learner's memory stays at its
largest batch's size (tens of MB here) instead of shrinking between updates.
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
