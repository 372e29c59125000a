"""One lock around this package's multi-threaded numba launches, and the n_jobs rule.

numba's ``workqueue`` threading layer (the one it falls back to when neither OpenMP nor TBB
is available) aborts the process if two Python threads launch parallel kernels at the
same time; :func:`numba_threads` holds a lock around every parallel launch of this
package, so concurrent calls from threads (joblib's threading backend, dask threads) wait
for each other instead. The threading layer itself is left as the user or numba chose it:
importing sk_rtw changes no process-wide setting (:mod:`sk_rtw._threads` sets thread
counts per call and restores them).

Every kernel of the package is compiled with ``nogil=True`` (tests check it): fits in
several Python threads (a grid search on joblib's threading backend) run their kernels
side by side rather than in turn.
"""

from __future__ import annotations

import contextlib
import os
import threading
import types
from collections.abc import Callable
from typing import Any

import numba
import numpy as np

#: Serialises this package's multi-threaded numba launches.
PARALLEL_LOCK = threading.RLock()


def check_n_jobs(n_jobs: Any) -> None:
    """scikit-learn's rule: None or a non-zero integer (negative counts from the cores)."""
    if n_jobs is None:
        return
    if isinstance(n_jobs, bool) or not isinstance(n_jobs, (int, np.integer)):
        raise TypeError(f"n_jobs must be None or an integer, got {n_jobs!r}")
    if n_jobs == 0:
        raise ValueError(
            "n_jobs must not be 0: use None or 1 for one thread, -1 for all cores, or a "
            "positive count"
        )


def n_threads(n_jobs: int | None) -> int:
    """scikit-learn's ``n_jobs`` convention as a thread count (None: 1; -1: all cores)."""
    check_n_jobs(n_jobs)
    if n_jobs is None or n_jobs == 1:
        count = 1
    elif n_jobs < 0:
        count = max(1, (os.cpu_count() or 1) + 1 + n_jobs)
    else:
        count = n_jobs
    return min(count, numba.config.NUMBA_NUM_THREADS)


@contextlib.contextmanager
def numba_threads(n_jobs: int | None = -1):
    """Run this package's parallel kernels on ``n_jobs`` threads, one launch at a time."""
    with PARALLEL_LOCK:
        previous = numba.get_num_threads()
        numba.set_num_threads(n_threads(n_jobs))
        try:
            yield
        finally:
            numba.set_num_threads(previous)


def launch(serial, parallel, work: int, threshold: int, *args) -> None:
    """Run ``serial(*args)``, or ``parallel(*args)`` on the fit's threads (numba's current
    count, set by :mod:`sk_rtw._threads`) when ``work`` reaches ``threshold`` and more than
    one thread is allowed: the two builds of one kernel, threads only where they pay."""
    threads = numba.get_num_threads()
    if work < threshold or threads < 2:
        serial(*args)
        return
    with numba_threads(threads):
        parallel(*args)


def row_builds(functions: dict, **options) -> dict:
    """Each kernel over rows (a ``prange`` loop) compiled twice, serial and threaded, by
    name: what :func:`launch_rows` launches."""
    return {
        name: (serial_build(function, **options), numba.njit(**options, parallel=True)(function))
        for name, function in functions.items()
    }


def serial_build(function: Callable[..., Any], **options) -> Any:
    """``function`` (a ``prange`` kernel) compiled without threads, beside its threaded
    build.

    numba's on-disk cache names an entry by the function's module, qualified name and
    line, and keys it by signature: the ``parallel`` flag is not part of it. Two builds
    of one function with ``cache=True`` therefore share one entry, and whichever compiled
    first is loaded for the other in the next process (a "serial" build that launches
    threads, or the reverse). The serial build is a copy of the function under its own
    qualified name, so it has a cache entry of its own.
    """
    copy = types.FunctionType(
        function.__code__, function.__globals__, function.__name__, function.__defaults__,
        function.__closure__,
    )  # fmt: skip
    copy.__qualname__ = f"{function.__qualname__}__serial"
    copy.__module__ = function.__module__
    copy.__doc__ = function.__doc__
    return numba.njit(**options)(copy)


def launch_rows(builds: dict, name: str, threshold: int, *arrays) -> None:
    """Launch kernel ``name`` of :func:`row_builds` on its arguments (row arrays first),
    threaded from ``threshold`` rows (:func:`launch`)."""
    serial, parallel = builds[name]
    launch(serial, parallel, arrays[0].shape[0], threshold, *arrays)
