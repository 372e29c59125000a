"""Large temporaries kept in glibc's heap during a fit, the allocator left as glibc's
adaptive rule would leave it afterwards; read back from glibc's own counters."""

from __future__ import annotations

import ctypes

import numpy as np
import pytest

from sk_rtw._heap import LARGE_TEMPORARY, _glibc, heap_for_temporaries

pytestmark = pytest.mark.skipif(_glibc() is None, reason="glibc's allocator only")


class _MallInfo2(ctypes.Structure):
    _fields_ = [(name, ctypes.c_size_t) for name in (
        "arena", "ordblks", "smblks", "hblks", "hblkhd", "usmblks", "fsmblks", "uordblks",
        "fordblks", "keepcost",
    )]  # fmt: skip


def _mmapped_bytes_of(nbytes: int) -> int:
    """Bytes glibc serves by mmap for one live array of ``nbytes``."""
    libc = _glibc()
    if not hasattr(libc, "mallinfo2"):  # glibc < 2.33
        pytest.skip("mallinfo2 needs glibc 2.33")
    libc.mallinfo2.restype = _MallInfo2
    before = libc.mallinfo2().hblkhd
    block = np.empty(nbytes // 8)
    block[::512] = 1.0  # touched, as a temporary is
    used = libc.mallinfo2().hblkhd - before
    del block
    return used


def test_a_large_fit_keeps_its_temporaries_in_the_heap_and_gives_them_back():
    large = 128 * 2**20
    assert _mmapped_bytes_of(large) >= large  # glibc's own choice for such a block
    with heap_for_temporaries(large):
        assert _mmapped_bytes_of(large) == 0
        assert _mmapped_bytes_of(large) == 0  # freed and reused, never mmapped
    assert _mmapped_bytes_of(large) >= large  # mmap allowed again afterwards
    assert _mmapped_bytes_of(16 * 2**20) == 0  # below the 32 MB threshold left behind


def test_a_kept_heap_is_not_trimmed_however_much_is_freed():
    """glibc trims the heap's free top once it exceeds the trim threshold, and mallopt's
    largest positive threshold is 2**31 - 1 bytes: a 256,000-sample fit frees more than
    that at the end of each epoch and faulted those pages in again in the next one. The
    kept heap switches trimming off (mallopt(3): -1). The block is never touched, so it
    takes address space, not memory."""
    libc = _glibc()
    if not hasattr(libc, "mallinfo2"):  # glibc < 2.33
        pytest.skip("mallinfo2 needs glibc 2.33")
    libc.mallinfo2.restype = _MallInfo2
    nbytes = 2**31 + 2**27
    with heap_for_temporaries(LARGE_TEMPORARY):
        block = np.empty(nbytes // 8)
        if libc.mallinfo2().hblkhd >= nbytes:  # the heap could not grow: glibc mmapped it
            pytest.skip("no room for the heap to grow by 2 GB here")
        del block
        kept = libc.mallinfo2().keepcost  # the free top the heap could give back
    assert kept >= nbytes


def test_a_small_fit_leaves_the_allocator_alone():
    large = 128 * 2**20
    with heap_for_temporaries(LARGE_TEMPORARY - 1):
        assert _mmapped_bytes_of(large) >= large


def test_overlapping_fits_keep_the_heap_until_the_last_one_ends():
    """Two fits that overlap (threads of a grid search): the first to end leaves the
    heap kept for the other; the last one gives the allocator back."""
    large = 128 * 2**20
    first, second = heap_for_temporaries(large), heap_for_temporaries(large)
    first.__enter__()
    second.__enter__()
    first.__exit__(None, None, None)
    assert _mmapped_bytes_of(large) == 0  # the second fit still runs
    second.__exit__(None, None, None)
    assert _mmapped_bytes_of(large) >= large


def test_the_engine_keeps_the_heap_only_where_twice_its_estimate_fits(monkeypatch):
    """The heap kept may hold about twice a fit's peak: with less free memory than twice
    the estimate the fit leaves the allocator alone (asks for no kept heap)."""
    import importlib

    from sk_rtw import align

    fit = importlib.import_module("sk_rtw.align._fit")
    memory = importlib.import_module("sk_rtw.align._memory")
    asked, estimates = [], []
    estimate = memory.estimated_memory

    def recorded_heap(nbytes):
        asked.append(nbytes)
        return heap_for_temporaries(0)

    def recorded_estimate(*args, **kwargs):
        estimates.append(estimate(*args, **kwargs))
        return estimates[-1]

    monkeypatch.setattr(fit, "heap_for_temporaries", recorded_heap)
    monkeypatch.setattr(memory, "estimated_memory", recorded_estimate)
    monkeypatch.setattr(memory, "available_memory", lambda: 2**40)
    X = np.random.default_rng(0).standard_normal((4, 30)).cumsum(1)
    for free_share in (3.0, 1.5):
        monkeypatch.setattr(fit, "available_memory",
                            lambda share=free_share: int(share * estimates[-1]))  # fmt: skip
        align(X, n_epochs=1, random_state=0)
    assert asked[0] == 4 * 120 * 8 and asked[1] == 0  # N Z doubles; none kept when tight
