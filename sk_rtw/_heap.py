"""Large temporaries without a page fault per element: glibc's heap kept for them.

An epoch of a long alignment allocates dozens of temporaries of the same size (``N x Z x
point size`` doubles: 64 MB for 8 quaternion series at ``Z = 256,000``). glibc's
``malloc`` serves every block above its mmap threshold (at most 32 MB, and a block of
the size last freed is above it) with a fresh ``mmap`` and returns it with ``munmap``
when freed, so each temporary's pages are faulted in and zeroed again: a multiplication
of two such tensors takes 3-5x the time it takes in reused memory (the retired study
``heap_reuse.py``, docs/benchmarks/studies.md), and RTW's time per epoch grew 8.2x for
4x the length from 64,000 to 256,000 samples (2.4 to 19.2 s; 1.6 to 7.5 s, 4.8x, with
the heap kept).

:func:`heap_for_temporaries` keeps such blocks in the heap for the duration of a
fit (``M_MMAP_MAX = 0``, trimming off: ``M_TRIM_THRESHOLD = -1``; the largest positive
threshold, 2**31 - 1 bytes, is below what a 256,000-sample epoch frees at once, and the
pages trimmed were faulted in again in the next epoch) and afterwards gives the free
heap back to the system (``malloc_trim``) and leaves the allocator where its own adaptive
rule ends for a program with large arrays (mmap threshold 32 MB, trim threshold 64 MB,
mmap allowed again). Only fits whose temporaries exceed :data:`LARGE_TEMPORARY` bytes
use it, and only where the C library is glibc; elsewhere it does nothing. Its price is
memory: freed blocks of other sizes stay in the heap, and the peak of a 256,000-sample
alignment of 8 quaternion series rose from 6.0 to 9.3-9.9 GB (the engine keeps the heap only
where twice its estimated peak fits in the free memory). The settings are
the process's: fits that overlap (threads of a grid search) share them, set by the first
to start and given back by the last to finish.

Why the process keeps fixed thresholds after such a fit, instead of its own: glibc can
neither be asked for its current thresholds nor told to adapt them again once one is set
(``mallopt(3)``: setting any of the mmap or trim parameters turns the dynamic threshold
off for the life of the process), so nothing here could restore the state before the
fit. What it leaves is where that adaptive rule ends anyway for a program that frees
blocks of 32 MB or more -- and the fit just did, many times. Fits of smaller
temporaries, and every platform other than glibc, never touch the allocator.
"""

from __future__ import annotations

import contextlib
import ctypes
import ctypes.util
import functools
import sys
import threading

#: Bytes of one temporary from which a fit keeps its blocks in the heap.
LARGE_TEMPORARY = 8 * 2**20

# mallopt parameters (glibc's malloc.h)
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD, _M_MMAP_MAX = -1, -3, -4
#: Where glibc's adaptive thresholds end (DEFAULT_MMAP_THRESHOLD_MAX on 64-bit systems,
#: the trim threshold twice it) and its default count of mmapped blocks.
_MMAP_THRESHOLD_MAX = 32 * 2**20
_MMAP_MAX = 65536
#: Fits inside :func:`heap_for_temporaries` now, and the lock that guards the count.
_holders = 0
_lock = threading.Lock()


@functools.cache
def _glibc() -> ctypes.CDLL | None:
    if not sys.platform.startswith("linux"):
        return None
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        if not hasattr(libc, "gnu_get_libc_version"):  # musl: mallopt without these
            return None
        libc.mallopt.argtypes = (ctypes.c_int, ctypes.c_int)
        libc.malloc_trim.argtypes = (ctypes.c_size_t,)
    except (OSError, AttributeError):  # pragma: no cover - no C library found
        return None
    return libc


@contextlib.contextmanager
def heap_for_temporaries(temporary_bytes: float):
    """Keep freed blocks of a fit with ``temporary_bytes``-sized temporaries in the heap.

    Parameters
    ----------
    temporary_bytes : float
        Size of the fit's largest per-epoch temporary; below :data:`LARGE_TEMPORARY`, or
        without glibc, the block runs with the allocator as it is.
    """
    global _holders
    libc = _glibc() if temporary_bytes >= LARGE_TEMPORARY else None
    if libc is None:
        yield
        return
    with _lock:
        if _holders == 0:
            libc.mallopt(_M_MMAP_MAX, 0)
            libc.mallopt(_M_TRIM_THRESHOLD, -1)  # mallopt(3): -1 disables trimming
        _holders += 1
    try:
        yield
    finally:
        with _lock:
            _holders -= 1
            if _holders == 0:
                libc.mallopt(_M_MMAP_MAX, _MMAP_MAX)
                libc.mallopt(_M_MMAP_THRESHOLD, _MMAP_THRESHOLD_MAX)
                libc.mallopt(_M_TRIM_THRESHOLD, 2 * _MMAP_THRESHOLD_MAX)
                libc.malloc_trim(0)
