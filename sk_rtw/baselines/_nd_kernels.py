"""Numba recursion of dynamic time warping over N series jointly (an N-dimensional grid).

Cell ``(i_1, ..., i_N)`` of the grid matches sample ``i_n`` of every series ``n``; its
cost is the sum over the pairs ``a < b`` of the pairwise point costs
``C_ab[i_a, i_b]``. A cell is reached from any of its ``2^N - 1`` predecessors that step
back by one in a non-empty subset of the axes. The accumulated cost is stored flat in
C order, in which every predecessor comes before its successor.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _strides(shape):
    n = shape.size
    strides = np.empty(n, dtype=np.int64)
    step = 1
    for k in range(n - 1, -1, -1):
        strides[k] = step
        step *= shape[k]
    return strides


@njit(cache=True, nogil=True)
def _step_offsets(strides):
    """Flat offset of the predecessor reached by stepping back along the axes in ``mask``."""
    n = strides.size
    offsets = np.zeros(1 << n, dtype=np.int64)
    for mask in range(1, 1 << n):
        for k in range(n):
            if (mask >> k) & 1:
                offsets[mask] += strides[k]
    return offsets


@njit(cache=True, nogil=True)
def _step_order(n):
    """Step masks by decreasing number of axes (diagonal first), then increasing mask."""
    order = np.empty((1 << n) - 1, dtype=np.int64)
    pos = 0
    for bits in range(n, 0, -1):
        for mask in range(1, 1 << n):
            count = 0
            for k in range(n):
                count += (mask >> k) & 1
            if count == bits:
                order[pos] = mask
                pos += 1
    return order


@njit(cache=True, nogil=True)
def accumulate(pair_costs, pairs, shape, window, D):
    """Fill the flat accumulated cost ``D`` (size ``prod(shape)``) in place.

    ``window >= 0`` keeps only cells with ``|i_a/(T_a-1) - i_b/(T_b-1)| <= window`` for
    every pair (a band around the joint diagonal); other cells get ``inf``.
    """
    n = shape.size
    n_pairs = pairs.shape[0]
    offsets = _step_offsets(_strides(shape))
    scale = np.empty(n)
    for k in range(n):
        scale[k] = 1.0 / max(shape[k] - 1, 1)
    idx = np.zeros(n, dtype=np.int64)
    n_masks = 1 << n
    for f in range(D.size):
        cost = 0.0
        inside = True
        for p in range(n_pairs):
            a = pairs[p, 0]
            b = pairs[p, 1]
            if window >= 0.0 and abs(idx[a] * scale[a] - idx[b] * scale[b]) > window:
                inside = False
                break
            cost += pair_costs[p, idx[a], idx[b]]
        if not inside:
            D[f] = np.inf
        elif f == 0:
            D[f] = cost
        else:
            at_start = 0
            for k in range(n):
                if idx[k] == 0:
                    at_start |= 1 << k
            best = np.inf
            for mask in range(1, n_masks):
                if mask & at_start == 0:
                    value = D[f - offsets[mask]]
                    if value < best:
                        best = value
            D[f] = cost + best
        k = n - 1
        while k >= 0:
            idx[k] += 1
            if idx[k] < shape[k]:
                break
            idx[k] = 0
            k -= 1


@njit(cache=True, nogil=True)
def backtrack(D, shape):
    """Optimal path ``(L, N)`` from the first to the last cell of a filled grid.

    Ties prefer steps along more axes (the diagonal first), as the 2-D DTW kernel does.
    """
    n = shape.size
    strides = _strides(shape)
    offsets = _step_offsets(strides)
    order = _step_order(n)
    idx = shape - 1
    max_steps = 1
    for k in range(n):
        max_steps += shape[k] - 1
    path = np.empty((max_steps, n), dtype=np.int64)
    path[0] = idx
    steps = 1
    while True:
        f = 0
        at_start = 0
        for k in range(n):
            f += idx[k] * strides[k]
            if idx[k] == 0:
                at_start |= 1 << k
        if at_start == (1 << n) - 1:
            break
        best = np.inf
        chosen = 0
        for mask in order:
            if mask & at_start == 0:
                value = D[f - offsets[mask]]
                if value < best:
                    best = value
                    chosen = mask
        if chosen == 0:  # every predecessor is outside the band: take the diagonal-most
            for mask in order:
                if mask & at_start == 0:
                    chosen = mask
                    break
        for k in range(n):
            if (chosen >> k) & 1:
                idx[k] -= 1
        path[steps] = idx
        steps += 1
    return path[:steps][::-1].copy()
