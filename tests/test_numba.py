"""Threads: no process-wide change on import, the lock around parallel launches."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from sk_rtw._numba import n_threads


def run_python(code: str, **env) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        capture_output=True,
        text=True,
        env={**os.environ, **env},
        timeout=300,
    )


def test_importing_the_package_changes_no_process_wide_setting():
    """numba's threading layer and thread count, torch's threads: as before the import."""
    result = run_python(
        """
        import numba, torch
        before = (numba.config.THREADING_LAYER, numba.get_num_threads(), torch.get_num_threads())
        import sk_rtw
        from sk_rtw import RTWNearestCentroid, align
        after = (numba.config.THREADING_LAYER, numba.get_num_threads(), torch.get_num_threads())
        print(before == after, before, after)
        """
    )
    assert result.returncode == 0, result.stderr[-2000:]
    assert result.stdout.split()[0] == "True", result.stdout


def test_a_fit_restores_the_callers_thread_counts():
    import numba
    import numpy as np
    import torch

    from sk_rtw import align

    torch_before, numba_before = torch.get_num_threads(), numba.get_num_threads()
    align(np.random.default_rng(0).standard_normal((3, 20)), n_epochs=2, n_jobs=-1)
    assert (torch.get_num_threads(), numba.get_num_threads()) == (torch_before, numba_before)


def test_concurrent_launches_on_the_workqueue_layer_do_not_abort():
    """Four threads computing DTW (and the parallel sinc kernel) at the same time: numba's
    workqueue layer aborts the process without the lock around this package's launches."""
    result = run_python(
        """
        import threading, numba, numpy as np
        from sk_rtw import dtw_pairwise_distance
        from sk_rtw.align._sinc_kernel import window_sums
        X = np.random.default_rng(0).standard_normal((40, 60))
        expected = dtw_pairwise_distance(X, n_jobs=2)
        errors = []
        def work():
            try:
                for _ in range(3):
                    assert np.array_equal(dtw_pairwise_distance(X, n_jobs=2), expected)
                    values = np.ones((400, 60, 21, 1))
                    base = np.zeros((400, 300), dtype=np.int64) + 30
                    frac = np.full((400, 300), 0.25)
                    u, du = np.empty((400, 300, 1)), np.empty((400, 300, 1))
                    window_sums(values, base, base, frac, np.full(400, 60), 10, u, du)
                    assert np.allclose(u, 1.0)
            except Exception as exc:
                errors.append(exc)
        threads = [threading.Thread(target=work) for _ in range(4)]
        [t.start() for t in threads]
        [t.join() for t in threads]
        assert not errors, errors
        print(numba.threading_layer())
        """,
        NUMBA_THREADING_LAYER="workqueue",
    )
    assert result.returncode == 0, result.stderr[-2000:]
    assert result.stdout.strip().splitlines()[-1] == "workqueue"


def test_every_compiled_kernel_releases_the_gil():
    """Threads (joblib's threading backend, a grid search on threads, dask threads) run
    this package's kernels side by side only if none holds the GIL."""
    import importlib
    import pkgutil

    from numba.core.dispatcher import Dispatcher

    import sk_rtw

    kernels = {}
    for info in pkgutil.walk_packages(sk_rtw.__path__, "sk_rtw."):
        module = importlib.import_module(info.name)
        for name, value in vars(module).items():
            if isinstance(value, Dispatcher) and value.py_func.__module__ == info.name:
                kernels[f"{info.name}.{name}"] = value
    assert len(kernels) >= 40  # the DTW, band, medoid, baseline, soft-DTW and sinc kernels
    holding = sorted(name for name, kernel in kernels.items()
                     if not kernel.targetoptions.get("nogil"))  # fmt: skip
    assert not holding, f"kernels compiled without nogil=True: {holding}"


def test_a_layer_chosen_by_the_user_is_kept():
    result = run_python(
        """
        import numba, numpy as np
        from sk_rtw import dtw_pairwise_distance
        dtw_pairwise_distance(np.zeros((3, 5)), n_jobs=2)
        print(numba.threading_layer())
        """,
        NUMBA_THREADING_LAYER="omp",
    )
    assert result.returncode == 0, result.stderr[-2000:]
    assert result.stdout.strip().splitlines()[-1] == "omp"


@pytest.mark.parametrize(("n_jobs", "expected"), [(None, 1), (1, 1), (2, 2), (-1, None)])
def test_n_jobs_convention(n_jobs, expected):
    import numba

    count = n_threads(n_jobs)
    if expected is None:
        assert count == min(os.cpu_count() or 1, numba.config.NUMBA_NUM_THREADS)
    else:
        assert count == min(expected, numba.config.NUMBA_NUM_THREADS)


@pytest.mark.parametrize(
    ("n_jobs", "work", "expected"), [(None, 1e12, 1), (1, 1e12, 1), (2, 1e3, 1), (2, 1e12, 2)]
)
def test_threads_follow_n_jobs_and_the_problem_size(n_jobs, work, expected):
    from sk_rtw._threads import threads_for, usable_cores

    assert threads_for(n_jobs, work) == min(expected, usable_cores())


def test_thread_map_keeps_the_order_and_runs_side_by_side():
    """Two items that each wait for the other (a barrier of two) finish only if they run
    at the same time; the results come back in the items' order; one thread is a plain
    loop in the caller's thread."""
    import threading

    from sk_rtw._threads import thread_map

    barrier = threading.Barrier(2, timeout=10)

    def meet(item):
        barrier.wait()  # BrokenBarrierError after 10 s if the other item is not running
        return item * 10, threading.get_ident()

    results = thread_map(meet, [1, 2], n_threads=2)
    assert [value for value, _ in results] == [10, 20]
    assert results[0][1] != results[1][1]
    serial = thread_map(lambda item: (item, threading.get_ident()), range(5), n_threads=1)
    assert serial == [(k, threading.get_ident()) for k in range(5)]


def test_the_serial_and_threaded_builds_of_a_kernel_have_their_own_cache_entries(tmp_path):
    """numba's disk cache keys an entry by function and signature, not by ``parallel``:
    two plain builds of one function share it, and the second build loads the first's
    code (the "threaded" kernel then runs on one thread). The threaded build of
    :func:`row_builds` must run its rows on two threads, in the process that compiles it
    and in the next one that loads it from the cache; the serial one on one. Each row
    records the numba thread that ran it (no timing)."""
    module = tmp_path / "kernel_module.py"
    module.write_text(
        textwrap.dedent(
            """
            import numba
            from numba import prange
            from sk_rtw._numba import row_builds

            def work(out):
                for i in prange(out.shape[0]):
                    total = 0.0
                    for k in range(20000):  # enough work that a scheduler shares the rows
                        total += k * 1e-12
                    out[i] = numba.get_thread_id() + 0.0 * total

            BUILDS = row_builds({"work": work}, cache=True, nogil=True)
            """
        )
    )
    code = f"""
        import sys, numba, numpy as np
        sys.path.insert(0, {str(tmp_path)!r})
        import kernel_module
        serial, threaded = kernel_module.BUILDS["work"]
        numba.set_num_threads(2)
        for kernel in (serial, threaded):
            out = np.full(400, -1.0)
            kernel(out)
            print(len(np.unique(out)))
    """
    if (os.cpu_count() or 1) < 2:
        pytest.skip("needs two cores to run a threaded kernel on two threads")
    for _ in range(2):  # the second process loads both builds from the cache
        result = run_python(code, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
        assert result.returncode == 0, result.stderr[-2000:]
        assert result.stdout.split()[-2:] == ["1", "2"], result.stdout


def test_stale_kernel_caches_are_dropped(tmp_path):
    """An index older than a source the kernels inline is removed; a newer one stays."""
    from sk_rtw._numba_cache import drop_stale_caches

    cache = tmp_path / "__pycache__"
    cache.mkdir()
    old, new, data = cache / "m.f-1.py311.nbi", cache / "m.g-9.py311.nbi", cache / "m.f-1.nbc"
    source = tmp_path / "inlined.py"
    for path in (old, new, data, source):
        path.write_text("x")
    os.utime(old, (1000, 1000))
    os.utime(source, (2000, 2000))
    os.utime(new, (3000, 3000))
    assert drop_stale_caches(tmp_path, [source]) == 1
    assert not old.exists() and new.exists() and data.exists()
    assert drop_stale_caches(tmp_path / "nowhere", [source]) == 0


def test_the_dtw_kernels_follow_the_point_geometry_they_inline():
    from sk_rtw.manifolds import _point_kernels, _spd_pairs, _sphere_kernels

    sources = {Path(p).name for p in _point_kernels.compiled_sources()}
    assert sources == {Path(m.__file__).name for m in (_point_kernels, _spd_pairs,
                                                        _sphere_kernels)}  # fmt: skip
