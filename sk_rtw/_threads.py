"""How many threads a computation of this package uses, set per call, never on import.

scikit-learn's convention: ``n_jobs=None`` means one thread (unless a
``joblib.parallel_config(n_jobs=...)`` context says otherwise), ``-1`` every usable core,
``-2`` all but one. Within that limit a fit only uses several threads when its work per
epoch is large enough to pay for them: torch and numba threads that wait for a core
collapse a fit when another process keeps cores busy (measured: 43 s instead of 1.8 s on 2
cores, docs: alignment speed).

:func:`limited_threads` sets torch's and numba's thread counts for the duration of a call
and restores the caller's values afterwards; importing sk_rtw changes nothing.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Callable, Iterable
from concurrent.futures import ThreadPoolExecutor
from typing import TypeVar

import numba
import torch
from joblib import effective_n_jobs

from ._numba import check_n_jobs

_Item = TypeVar("_Item")
_Result = TypeVar("_Result")

#: Elementwise work per epoch (points x taps) that one thread handles before a second
#: one pays off.
WORK_PER_THREAD = 2_000_000


def usable_cores() -> int:
    """Cores this process may run on (its CPU affinity where the system tells it)."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # pragma: no cover - non-Linux
        return os.cpu_count() or 1


def resolve_n_jobs(n_jobs: int | None) -> int:
    """scikit-learn's ``n_jobs`` as a thread count (None: 1, -1: every usable core)."""
    check_n_jobs(n_jobs)
    if n_jobs is None:
        n_jobs = effective_n_jobs(None)
    if n_jobs < 0:
        return max(1, usable_cores() + 1 + n_jobs)
    return max(1, int(n_jobs))


def threads_for(n_jobs: int | None, work: float) -> int:
    """Threads for a computation of ``work`` elementwise operations per step."""
    wanted = resolve_n_jobs(n_jobs)
    return int(max(1, min(wanted, work // WORK_PER_THREAD, usable_cores())))


@contextlib.contextmanager
def limited_threads(n_threads: int):
    """Run the block with ``n_threads`` torch and numba threads; restore them afterwards."""
    torch_before = torch.get_num_threads()
    numba_before = numba.get_num_threads()
    numba_threads = min(n_threads, numba.config.NUMBA_NUM_THREADS)
    try:
        if torch_before != n_threads:
            torch.set_num_threads(n_threads)
        if numba_before != numba_threads:
            numba.set_num_threads(numba_threads)
        yield
    finally:
        if torch.get_num_threads() != torch_before:
            torch.set_num_threads(torch_before)
        if numba.get_num_threads() != numba_before:
            numba.set_num_threads(numba_before)


def thread_map(
    function: Callable[[_Item], _Result], items: Iterable[_Item], n_threads: int
) -> list[_Result]:
    """``[function(item) for item in items]``, on up to ``n_threads`` Python threads.

    For independent pieces of work that spend their time in this package's compiled
    kernels (all ``nogil``) and in torch, which release the GIL; the results come back in
    the order of ``items``. One thread (or one item) is a plain loop.
    """
    items = list(items)
    workers = min(int(n_threads), len(items))
    if workers <= 1:
        return [function(item) for item in items]
    with ThreadPoolExecutor(max_workers=workers) as pool:
        return list(pool.map(function, items))
