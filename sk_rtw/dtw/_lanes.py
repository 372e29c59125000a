"""DTW of one series against many references at once: one reference per SIMD lane.

The DTW recursion of one pair is a chain: every cell waits for the cell to its left, so
a pair runs at the latency of an add and two comparisons per cell, however wide the
core's vector units. References of the same length share the band, so the recursions of
``L`` of them against the same query can run side by side, lane ``l`` of every row
buffer holding reference ``l``: ``L`` independent chains that the compiler vectorises,
at the throughput of the vector units instead of the latency of one chain.

Every lane performs, for its pair, the operations of the one-pair kernels
(:func:`~._point_costs._cost_row`, :func:`~._kernels.cell_value`) in the same order, so the
distances are those of :func:`~._pruned.pairwise_segments` bit for bit. Only point
distances made of flat segments (squared coordinate differences) are computed in lanes
(their cost is a few instructions; any other segment's cost dominates its cell anyway).

:func:`lane_blocks` groups the references: equal lengths together, blocks of
:data:`WIDE` (then :data:`NARROW`) lanes; lengths shared by fewer than :data:`MIN_RUN`
references stay with the one-pair kernel, as do calls of fewer than :data:`MIN_PAIRS`
pairs and references whose block would exceed :data:`BLOCK_BYTES` (the one-pair kernel
holds two rows; a block holds its references and two rows in every lane).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ._kernels import sakoe_chiba_rows
from ._point_costs import _HUGE, _TINY, FLAT, robust_distance
from ._pruned import pruned_distance

_INF = np.inf

#: Lanes of the wide kernel (blocks of full runs of equal length) and of the narrow one
#: (what is left of a run). The wide kernel is about 6x the one-pair kernel per pair on
#: full blocks (2 cores with AVX-512; ``benchmarks/dtw_speed.py``), the narrow one 3.5x.
WIDE = 32
NARROW = 8
#: Lengths shared by fewer references than this are left to the one-pair kernel: a block
#: of ``NARROW`` lanes costs about as much as three single pairs.
MIN_RUN = 3
#: Calls with fewer pairs than this keep the one-pair kernel: grouping the references costs
#: about 0.1 ms, and a few series fill few lanes (8 series of 96 samples, symmetric, 28
#: pairs: the same time either way; 16 series, 120 pairs: 1.6x faster in lanes).
MIN_PAIRS = 64


#: A block holds its references and two rows, ``(T (p + 2) WIDE)`` doubles per thread;
#: longer or wider references than this allows keep the one-pair kernel (two rows).
BLOCK_BYTES = 128 * 2**20


def lanes_apply(segments: np.ndarray, n_pairs: int, max_length: int) -> bool:
    """Whether the lanes compute these pairs: flat segments only, enough pairs, and
    blocks of at most :data:`BLOCK_BYTES` for references of ``max_length`` samples."""
    point_size = int(segments[:, 1].max())
    block = 8 * WIDE * (max_length + 1) * (point_size + 2)
    return (
        n_pairs >= MIN_PAIRS
        and block <= BLOCK_BYTES
        and bool(np.all(segments[:, 2] == FLAT))
    )


def lane_blocks(lengths: np.ndarray) -> tuple[list[np.ndarray], np.ndarray]:
    """References grouped for the lane kernels.

    Parameters
    ----------
    lengths : ndarray of int, shape (m,)
        Length of every reference.

    Returns
    -------
    blocks : list of two ndarrays of int, shapes (n_wide, WIDE) and (n_narrow, NARROW)
        Reference indices of every block, all of one length, increasing; ``-1`` pads
        the last lanes of a block.
    single : ndarray of int
        The references left to the one-pair kernel.
    """
    lengths = np.asarray(lengths, dtype=np.int64)
    order = np.argsort(lengths, kind="stable")
    _, starts, counts = np.unique(lengths[order], return_index=True, return_counts=True)
    wide, narrow, single = [], [], []
    for start, count in zip(starts, counts, strict=True):
        run = order[start : start + count]
        if count < MIN_RUN:
            single.append(run)
            continue
        full = count - count % WIDE
        wide.extend(np.split(run[:full], full // WIDE) if full else [])
        rest = run[full:]
        for first in range(0, len(rest), NARROW):
            narrow.append(rest[first : first + NARROW])

    def stack(parts: list[np.ndarray], width: int) -> np.ndarray:
        out = np.full((len(parts), width), -1, dtype=np.int64)
        for row, part in enumerate(parts):
            out[row, : len(part)] = part
        return out

    rest = np.concatenate(single) if single else np.zeros(0, dtype=np.int64)
    return [stack(wide, WIDE), stack(narrow, NARROW)], np.sort(rest)


@njit(cache=True, nogil=True, inline="always")
def _step(prev, left, c, lane, cost):
    """:func:`~._kernels.cell_value` in one lane: the same comparisons, the same sum."""
    best = prev[c, lane]
    if prev[c + 1, lane] < best:
        best = prev[c + 1, lane]
    if left[lane] < best:
        best = left[lane]
    return cost + best


@njit(cache=True, nogil=True, inline="always")
def _amerced_step(prev, left, c, lane, cost, penalty):
    """:func:`~._kernels.cell_value` in one lane: the same comparisons, the same sums."""
    best = prev[c, lane]
    up = prev[c + 1, lane] + penalty
    if up < best:
        best = up
    step = left[lane] + penalty
    if step < best:
        best = step
    return cost + best


@njit(cache=True, nogil=True, inline="always")
def _segment_costs(xr, yb, Y, c, refs, first, segments, squared, cost, lanes):
    """Point costs of ``xr`` to column ``c`` of every lane, as :func:`_cost_row` computes
    them for flat segments (the same sums in the same order, the same fallback)."""
    for lane in range(lanes):
        cost[lane] = 0.0
    for s in range(segments.shape[0]):
        for lane in range(lanes):
            sq = 0.0
            for k in range(segments[s, 0], segments[s, 1]):
                diff = xr[k] - yb[c, k, lane]
                sq += diff * diff
            cost[lane] += sq
    if squared:
        return
    extreme = False
    for lane in range(lanes):
        extreme |= (cost[lane] < _TINY) | (cost[lane] > _HUGE)
    for lane in range(lanes):
        if extreme and (cost[lane] < _TINY or cost[lane] > _HUGE):
            j = refs[lane] if refs[lane] >= 0 else first
            cost[lane] = robust_distance(xr, Y[j, c], segments)
        else:
            cost[lane] = math.sqrt(cost[lane])


@njit(cache=True, nogil=True, inline="always")
def _block(X, lx, Y, ly, segments, squared, window, i, refs, symmetric, out, lanes, penalty):
    """The distances of query ``i`` to the references of one block into ``out[i]``
    (amerced by ``penalty``; the plain cell where it is 0: every loop over the lanes is
    written twice, as a test inside them would stop their vectorisation)."""
    first = refs[0]
    if symmetric:  # indices increase along a block: skip one below the diagonal
        last = first
        for lane in range(lanes):
            if refs[lane] > last:
                last = refs[lane]
        if last <= i:
            return
    nx, ny, p = lx[i], ly[first], X.shape[2]
    lo, hi = sakoe_chiba_rows(nx, ny, window)
    # the references, lane by lane (padding lanes repeat the first)
    yb = np.empty((ny, p, lanes))
    for lane in range(lanes):
        j = refs[lane] if refs[lane] >= 0 else first
        for c in range(ny):
            for k in range(p):
                yb[c, k, lane] = Y[j, c, k]
    prev = np.full((ny + 1, lanes), _INF)
    cur = np.full((ny + 1, lanes), _INF)
    prev[0, :] = 0.0
    left = np.empty(lanes)
    cost = np.empty(lanes)
    univariate = segments.shape[0] == 1 and segments[0, 1] == 1
    flat = yb.reshape(ny * p, lanes)  # univariate: row c is column c of every lane
    x = X[i]
    for r in range(nx):
        for lane in range(lanes):
            cur[lo[r], lane] = _INF
            left[lane] = _INF
        if univariate and penalty == 0.0:  # as _cost_row: |a - b| exactly, at any magnitude
            a = x[r, 0]
            for c in range(lo[r], hi[r]):
                for lane in range(lanes):
                    diff = abs(a - flat[c, lane])
                    point = diff * diff if squared else diff
                    left[lane] = _step(prev, left, c, lane, point)
                    cur[c + 1, lane] = left[lane]
        elif univariate:
            a = x[r, 0]
            for c in range(lo[r], hi[r]):
                for lane in range(lanes):
                    diff = abs(a - flat[c, lane])
                    point = diff * diff if squared else diff
                    left[lane] = _amerced_step(prev, left, c, lane, point, penalty)
                    cur[c + 1, lane] = left[lane]
        elif penalty == 0.0:
            for c in range(lo[r], hi[r]):
                _segment_costs(x[r], yb, Y, c, refs, first, segments, squared, cost, lanes)
                for lane in range(lanes):
                    left[lane] = _step(prev, left, c, lane, cost[lane])
                    cur[c + 1, lane] = left[lane]
        else:
            for c in range(lo[r], hi[r]):
                _segment_costs(x[r], yb, Y, c, refs, first, segments, squared, cost, lanes)
                for lane in range(lanes):
                    left[lane] = _amerced_step(prev, left, c, lane, cost[lane], penalty)
                    cur[c + 1, lane] = left[lane]
        prev, cur = cur, prev
    for lane in range(lanes):
        j = refs[lane]
        if j >= 0 and (not symmetric or j > i):
            out[i, j] = prev[ny, lane]


# Two entry points on purpose: the number of lanes must be a compile-time constant for
# the lane loops to vectorise (passed at run time, the wide kernel ran 1.7x slower).
def _pairwise_wide(X, lx, Y, ly, segments, squared, window, blocks, symmetric, out, penalty):
    """Every query of ``X`` against every block of ``blocks`` (``WIDE`` lanes) into
    ``out``; with ``symmetric`` (``Y`` is ``X``) only the pairs ``j > i``; ``penalty``:
    amerced DTW's."""
    n_blocks = blocks.shape[0]
    for task in prange(X.shape[0] * n_blocks):
        i = task // n_blocks
        _block(X, lx, Y, ly, segments, squared, window, i, blocks[task - i * n_blocks],
               symmetric, out, WIDE, penalty)  # fmt: skip


def _pairwise_narrow(X, lx, Y, ly, segments, squared, window, blocks, symmetric, out, penalty):
    """:func:`pairwise_wide` for blocks of ``NARROW`` lanes."""
    n_blocks = blocks.shape[0]
    for task in prange(X.shape[0] * n_blocks):
        i = task // n_blocks
        _block(X, lx, Y, ly, segments, squared, window, i, blocks[task - i * n_blocks],
               symmetric, out, NARROW, penalty)  # fmt: skip


def _listed_pairs(X, lx, Y, ly, segments, squared, window, rows, columns, out, penalty):
    """The pairs ``(rows[k], columns[k])`` one at a time (the one-pair kernel's plain
    recursion), into ``out``: the references no block holds."""
    for k in prange(rows.shape[0]):
        i, j = rows[k], columns[k]
        out[i, j] = pruned_distance(X[i, : lx[i]], Y[j, : ly[j]], segments, squared, window,
                                    _INF, penalty)  # fmt: skip


pairwise_wide = njit(cache=True, nogil=True, parallel=True)(_pairwise_wide)
pairwise_narrow = njit(cache=True, nogil=True, parallel=True)(_pairwise_narrow)
listed_pairs = njit(cache=True, nogil=True, parallel=True)(_listed_pairs)


def lane_distances(flat_x, lx, flat_y, ly, segments, squared, window, symmetric,
                   penalty) -> np.ndarray:  # fmt: skip
    """DTW (amerced by ``penalty``) of every series of ``flat_x`` against every series
    of ``flat_y`` (kernel form): the references of a common length in lanes, the others
    one pair at a time; with ``symmetric`` (``flat_y`` is ``flat_x``) the upper triangle,
    mirrored. The values of the one-pair kernels, bit for bit."""
    lx, ly = np.asarray(lx, dtype=np.int64), np.asarray(ly, dtype=np.int64)
    values = np.zeros((flat_x.shape[0], flat_y.shape[0]))
    (wide, narrow), single = lane_blocks(ly)
    for kernel, blocks in ((pairwise_wide, wide), (pairwise_narrow, narrow)):
        if len(blocks):
            kernel(flat_x, lx, flat_y, ly, segments, squared, window, blocks, symmetric, values,
                   penalty)  # fmt: skip
    if len(single):
        rows, columns = np.meshgrid(np.arange(flat_x.shape[0]), single, indexing="ij")
        if symmetric:  # the upper triangle, as the one-pair kernel orients it
            upper = rows < columns
            rows, columns = rows[upper], columns[upper]
        listed_pairs(flat_x, lx, flat_y, ly, segments, squared, window, rows.ravel(),
                     columns.ravel(), values, penalty)  # fmt: skip
    if symmetric:
        values = np.triu(values, 1) + np.triu(values, 1).T
    return values
