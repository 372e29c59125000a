"""Numba kernels: the DTW recursion over a cost matrix, its band, backtracking.

The recursion ``D[i, j] = C[i, j] + min(D[i-1, j], D[i, j-1], D[i-1, j-1])`` is written
once (:func:`cell_value`) and used by every DTW of the package (:mod:`._pruned` computes the
point costs inside it), ties on the way back broken once (:func:`choose_step`). Amerced
DTW (Herrmann and Webb, 2023) adds a penalty ``w`` to the steps off the diagonal,
``min(D[i-1, j] + w, D[i, j-1] + w, D[i-1, j-1])`` (:func:`cell_value`): 0 is plain
DTW, larger penalties move the measure towards the direct, diagonal alignment. The
kernels take ``penalty`` and run the plain cell where it is 0 (the same values, bit for
bit). ``fastmath`` is never enabled: the band uses ``inf`` for forbidden cells.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

_INF = np.inf


@njit(cache=True, nogil=True)
def sakoe_chiba_rows(nx: int, ny: int, window: float):
    """Allowed column range ``[lo[i], hi[i])`` of each row of an ``nx x ny`` DTW matrix.

    ``window`` is the band radius as a fraction of the shorter series (aeon's convention);
    a negative value means no band. The band follows the diagonal of the ``a x b`` matrix
    (``a`` the shorter side) step by step: at step ``s`` of ``max(a, b) + 1`` the cells
    ``(r, floor(s b / steps))`` with ``|r - floor(s a / steps)| <= floor(window a)`` are
    allowed. One sweep over the steps (``O(nx + ny)``); ``lo`` and ``hi`` are
    non-decreasing.
    """
    lo = np.zeros(nx, dtype=np.int64)
    hi = np.full(nx, ny, dtype=np.int64)
    if window < 0.0 or window >= 1.0:
        return lo, hi
    transpose = nx > ny
    a, b = (ny, nx) if transpose else (nx, ny)
    steps = max(a, b) + 1
    thickness = int(window * min(a, b))
    covered = 0  # rows [0, covered) have their lo (not transposed)
    released = 0  # rows [0, released) have their hi (not transposed)
    previous = 0
    for step in range(steps):
        ai = math.floor(step / steps * a)
        bi = math.floor(step / steps * b)
        start = max(0, ai - thickness)
        stop = min(a, ai + thickness + 1)
        if transpose:  # row bi of the nx x ny matrix holds the columns [start, stop)
            if step == 0 or bi != previous:
                lo[bi] = start
            hi[bi] = stop
        else:  # rows [start, stop) hold column bi: first step sets lo, last one hi
            while covered < stop:
                lo[covered] = bi
                covered += 1
            while released < start:
                hi[released] = previous + 1
                released += 1
        previous = bi
    if not transpose:
        while released < a:
            hi[released] = previous + 1
            released += 1
    return lo, hi


@njit(cache=True, nogil=True, inline="always")
def _accumulate_row(cost_row, prev, cur, i, lo, hi, ny, penalty):
    """Fill row ``i`` of the accumulated cost from row ``i - 1`` (off-diagonal steps
    ``penalty`` each).

    ``prev`` and ``cur`` are padded rows of length ``ny + 1``: entry ``j + 1`` holds column
    ``j`` and entry 0 is the ``inf`` (or, before row 0, zero) sentinel. Only columns in
    ``[lo, hi)`` are allowed; the others are set to ``inf``.
    """
    cur[0] = _INF
    for j in range(1, lo + 1):
        cur[j] = _INF
    _band_row(cost_row, prev, cur, lo, hi, penalty)
    for j in range(hi + 1, ny + 1):
        cur[j] = _INF


@njit(cache=True, nogil=True, inline="always")
def _band_row(cost_row, prev, cur, lo, hi, penalty):
    """:func:`_accumulate_row` for two rows that are reused: only the band is written.

    Both buffers start as ``inf`` (:func:`_two_rows`). Because ``lo`` and ``hi`` never
    decrease, the entries that the next row reads outside this row's band are either
    still ``inf`` or the one at ``lo`` (column ``lo - 1``), which is reset here: a row
    costs its band's width, not the series' length.
    """
    cur[lo] = _INF
    left = _INF
    if penalty == 0.0:  # two loops: a test per cell would slow plain DTW by 40 %
        for j in range(lo, hi):
            left = cell_value(prev[j], prev[j + 1], left, cost_row[j], 0.0)
            cur[j + 1] = left
    else:
        for j in range(lo, hi):
            left = cell_value(prev[j], prev[j + 1], left, cost_row[j], penalty)
            cur[j + 1] = left


@njit(cache=True, nogil=True, inline="always")
def cell_value(diagonal, up, left, cost, penalty):
    """The recursion at one cell: ``cost`` plus the least of the cells above-left, above
    and left, the last two with amerced DTW's ``penalty`` added (0: plain DTW, compared
    in the same order). The neighbours come as numbers: an array handed to an inlined
    function is reference-counted at every cell, several times the recursion's cost."""
    best = diagonal
    if penalty == 0.0:
        if up < best:
            best = up
        if left < best:
            best = left
        return cost + best
    step = up + penalty
    if step < best:
        best = step
    step = left + penalty
    if step < best:
        best = step
    return cost + best


@njit(cache=True, nogil=True, inline="always")
def _two_rows(ny):
    """The buffers of :func:`_band_row`: the row "before" row 0 and an ``inf`` row."""
    return _first_prev(ny), np.full(ny + 1, _INF)


@njit(cache=True, nogil=True, inline="always")
def _first_prev(ny):
    """The row "before" row 0: zero at the sentinel, ``inf`` elsewhere."""
    prev = np.full(ny + 1, _INF)
    prev[0] = 0.0
    return prev


@njit(cache=True, nogil=True)
def accumulated_cost(cost: np.ndarray, window: float, penalty: float = 0.0) -> np.ndarray:
    """Full accumulated cost matrix ``D`` (``inf`` outside the band; ``penalty``: amerced
    DTW's)."""
    nx, ny = cost.shape
    lo, hi = sakoe_chiba_rows(nx, ny, window)
    D = np.empty((nx, ny + 1))
    prev = _first_prev(ny)
    for i in range(nx):
        _accumulate_row(cost[i], prev, D[i], i, lo[i], hi[i], ny, penalty)
        prev = D[i]
    return D[:, 1:].copy()


@njit(cache=True, nogil=True)
def final_cost(
    cost: np.ndarray, nx: int, ny: int, window: float, penalty: float = 0.0
) -> float:
    """DTW distance over the top-left ``nx x ny`` block of ``cost`` (two rows of memory;
    ``penalty``: amerced DTW's)."""
    lo, hi = sakoe_chiba_rows(nx, ny, window)
    prev, cur = _two_rows(ny)
    for i in range(nx):
        _band_row(cost[i], prev, cur, lo[i], hi[i], penalty)
        prev, cur = cur, prev
    return prev[ny]


@njit(cache=True, nogil=True, inline="always")
def _step_back(D, i, j):
    """One step back along the optimal path (ties: diagonal, then up, then left)."""
    if i == 0:
        return i, j - 1
    if j == 0:
        return i - 1, j
    return choose_step(i, j, D[i - 1, j - 1], D[i - 1, j], D[i, j - 1])


@njit(cache=True, nogil=True, inline="always")
def choose_step(i, j, diag, up, left):
    """The cell before ``(i, j)``, both positive, from its three neighbours' accumulated
    costs: the cheapest, ties broken diagonal, then up, then left (every backtracking of
    the package breaks them so)."""
    if diag <= up and diag <= left:
        return i - 1, j - 1
    if up <= left:
        return i - 1, j
    return i, j - 1


@njit(cache=True, nogil=True)
def path_length(D: np.ndarray) -> int:
    """Number of steps of the optimal path encoded in an accumulated cost matrix."""
    i, j = D.shape[0] - 1, D.shape[1] - 1
    steps = 1
    while i > 0 or j > 0:
        i, j = _step_back(D, i, j)
        steps += 1
    return steps


@njit(cache=True, nogil=True, parallel=True)
def final_cost_batch(costs, nxs, nys, window, per_step, penalty):
    """:func:`final_cost` for a stack of cost matrices, in parallel.

    With ``per_step`` the distance is divided by the length of the optimal path.
    """
    n = costs.shape[0]
    values = np.empty(n)
    for k in prange(n):
        if per_step:
            D = accumulated_cost(costs[k, : nxs[k], : nys[k]], window, penalty)
            values[k] = D[-1, -1] / path_length(D)
        else:
            values[k] = final_cost(costs[k], nxs[k], nys[k], window, penalty)
    return values


@njit(cache=True, nogil=True)
def backtrack(D: np.ndarray):
    """Optimal warping path (list of index pairs) from an accumulated cost matrix."""
    i, j = D.shape[0] - 1, D.shape[1] - 1
    path = [(i, j)]
    while i > 0 or j > 0:
        i, j = _step_back(D, i, j)
        path.append((i, j))
    path.reverse()
    return path

