"""Numba kernels: the DTW recursion over a cost matrix, band, backtracking, cost matrices.

The recursion ``D[i, j] = C[i, j] + min(D[i-1, j], D[i, j-1], D[i-1, j-1])`` is written
once (:func:`_cell`) and used by every public function, ties on the way back broken once
(:func:`choose_step`). ``fastmath`` is never enabled: the band uses ``inf`` for forbidden
cells. Given the cost of some path (a bound), the rows skip the cells that cannot beat
it and store only what they compute (:func:`_pruned_row`): the result is the same.

Point distances that numba computes itself are described by "segments" ``(start, stop,
code)`` of a flattened point, translated by :func:`segment_codes` from the manifold's
:attr:`~sk_rtw.manifolds.Manifold.distance_segments`: code 0 Euclidean, 1 great-circle on
a sphere, 2 sign-invariant great circle (quaternions), ``k + 1`` affine-invariant SPD(k)
for ``2 <= k <= MAX_KERNEL_SIZE`` (:mod:`~sk_rtw.dtw._spd_kernels`); a product space is
several segments, combined as ``sqrt(sum d_s^2)``. The kernels read points in their kernel form
(:func:`kernel_points`): the coordinates as they are, except an SPD block, which becomes
its features (prepared once per point, so that a pair costs no eigendecomposition).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ..manifolds import Manifold
from ._spd_kernels import MAX_KERNEL_SIZE, feature_width, spd_features, spd_squared_distance

_INF = np.inf

#: The kernel's codes of the manifolds' distance kinds.
SEGMENT_EUCLIDEAN = 0
SEGMENT_SPHERE = 1
SEGMENT_SIGN_INVARIANT_SPHERE = 2
#: SPD(k) blocks, 2 <= k <= MAX_KERNEL_SIZE, have the code ``SEGMENT_SPD2 + k - 2``.
SEGMENT_SPD2 = 3
SEGMENT_CODES = {
    "euclidean": SEGMENT_EUCLIDEAN,
    "sphere": SEGMENT_SPHERE,
    "sign-invariant sphere": SEGMENT_SIGN_INVARIANT_SPHERE,
}
#: SPD(k) blocks with a kernel form: their size ``k * k``, their code and ``k``.
_SPD_BLOCKS = {k * k: (SEGMENT_SPD2 + k - 2, k) for k in range(2, MAX_KERNEL_SIZE + 1)}


@njit(cache=True, nogil=True, inline="always")
def spd_size(code):
    """The matrix size ``k`` of an SPD segment's code."""
    return code - SEGMENT_SPD2 + 2


def _layout(manifold: Manifold) -> list[tuple[int, int, int, int, int]] | None:
    """Every segment as ``(start, stop, kernel start, kernel stop, code)``: where it lies
    in the flat point and in its kernel form; None if one has no kernel distance."""
    segments = manifold.distance_segments
    if segments is None:
        return None
    rows, offset = [], 0
    for start, stop, kind in segments:
        if kind == "spd" and stop - start in _SPD_BLOCKS:
            code, k = _SPD_BLOCKS[stop - start]
            width = feature_width(k)
        elif kind in SEGMENT_CODES:
            code, width = SEGMENT_CODES[kind], stop - start
        else:
            return None
        rows.append((start, stop, offset, offset + width, code))
        offset += width
    return rows


def segment_codes(manifold: Manifold) -> np.ndarray | None:
    """``(n_segments, 3)`` int64 ``(start, stop, code)`` rows of the kernel form of a point
    (:func:`kernel_points`), or None (no kernel form: the manifold's ``pairwise_dist``)."""
    rows = _layout(manifold)
    if rows is None:
        return None
    return np.array([(a, b, code) for _, _, a, b, code in rows], dtype=np.int64)


def kernel_points(manifold: Manifold, flat: np.ndarray) -> np.ndarray:
    """Flat points ``(..., p)`` (validated) in the kernels' form: unchanged (the same
    array) unless the manifold has SPD blocks, which become their features."""
    rows = _layout(manifold)
    if rows is None or all(code < SEGMENT_SPD2 for *_, code in rows):
        return flat
    lead = flat.shape[:-1]
    points = np.ascontiguousarray(flat, dtype=np.float64).reshape(-1, flat.shape[-1])
    out = np.empty((points.shape[0], rows[-1][3]))
    for start, stop, a, b, code in rows:
        if code >= SEGMENT_SPD2:
            k = spd_size(code)
            features = spd_features(np.ascontiguousarray(points[:, start:stop]), k)
            bad = ~np.isfinite(features).all(1)
            if bad.any():
                point = points[int(np.argmax(bad)), start:stop].reshape(k, k)
                raise ValueError(
                    f"the SPD({k}) point {point.tolist()} has no Cholesky factor in float64 "
                    "(it is not positive definite, or too close to singular); regularise "
                    "it (add a multiple of the identity)"
                )
            out[:, a:b] = features
        else:
            out[:, a:b] = points[:, start:stop]
    return out.reshape(*lead, out.shape[-1])


def kernel_series(collection) -> np.ndarray:
    """A :class:`~sk_rtw.utils.SeriesCollection`'s padded series ``(n, T, p)`` in the
    kernels' form, C-contiguous."""
    flat = collection.data.reshape(collection.n_series, collection.max_length, -1)
    return np.ascontiguousarray(kernel_points(collection.manifold, flat))


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
def _accumulate_row(cost_row, prev, cur, i, lo, hi, ny):
    """Fill row ``i`` of the accumulated cost from row ``i - 1``.

    ``prev`` and ``cur`` are padded rows of length ``ny + 1``: entry ``j + 1`` holds column
    ``j`` and entry 0 is the ``inf`` (or, before row 0, zero) sentinel. Only columns in
    ``[lo, hi)`` are allowed; the others are set to ``inf``.
    """
    cur[0] = _INF
    for j in range(1, lo + 1):
        cur[j] = _INF
    _band_row(cost_row, prev, cur, lo, hi)
    for j in range(hi + 1, ny + 1):
        cur[j] = _INF


@njit(cache=True, nogil=True, inline="always")
def _band_row(cost_row, prev, cur, lo, hi):
    """:func:`_accumulate_row` for two rows that are reused: only the band is written.

    Both buffers start as ``inf`` (:func:`_two_rows`). Because ``lo`` and ``hi`` never
    decrease, the entries that the next row reads outside this row's band are either
    still ``inf`` or the one at ``lo`` (column ``lo - 1``), which is reset here: a row
    costs its band's width, not the series' length.
    """
    cur[lo] = _INF
    left = _INF
    for j in range(lo, hi):
        left = _cell(prev, left, j, cost_row[j])
        cur[j + 1] = left


@njit(cache=True, nogil=True)
def _cell(prev, left, j, cost):
    """The recursion at column ``j``: ``cost`` plus the least of the cells above-left
    (``prev[j]``), above (``prev[j + 1]``) and left, in padded rows."""
    best = prev[j]
    if prev[j + 1] < best:
        best = prev[j + 1]
    if left < best:
        best = left
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
def accumulated_cost(cost: np.ndarray, window: float) -> np.ndarray:
    """Full accumulated cost matrix ``D`` (``inf`` outside the band)."""
    nx, ny = cost.shape
    lo, hi = sakoe_chiba_rows(nx, ny, window)
    D = np.empty((nx, ny + 1))
    prev = _first_prev(ny)
    for i in range(nx):
        _accumulate_row(cost[i], prev, D[i], i, lo[i], hi[i], ny)
        prev = D[i]
    return D[:, 1:].copy()


@njit(cache=True, nogil=True)
def final_cost(cost: np.ndarray, nx: int, ny: int, window: float) -> float:
    """DTW distance over the top-left ``nx x ny`` block of ``cost`` (two rows of memory)."""
    lo, hi = sakoe_chiba_rows(nx, ny, window)
    prev, cur = _two_rows(ny)
    for i in range(nx):
        _band_row(cost[i], prev, cur, lo[i], hi[i])
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
def final_cost_batch(costs, nxs, nys, window, per_step):
    """:func:`final_cost` for a stack of cost matrices, in parallel.

    With ``per_step`` the distance is divided by the length of the optimal path.
    """
    n = costs.shape[0]
    values = np.empty(n)
    for k in prange(n):
        if per_step:
            D = accumulated_cost(costs[k, : nxs[k], : nys[k]], window)
            values[k] = D[-1, -1] / path_length(D)
        else:
            values[k] = final_cost(costs[k], nxs[k], nys[k], window)
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


@njit(cache=True, nogil=True, inline="always")
def _accumulate_scaled(value, scale, ssq):
    """One step of the overflow-free sum of squares ``scale^2 ssq`` (as LAPACK's nrm2)."""
    magnitude = abs(value)
    if magnitude > 0.0:
        if scale < magnitude:
            ssq = 1.0 + ssq * (scale / magnitude) ** 2
            scale = magnitude
        else:
            ssq += (magnitude / scale) ** 2
    return scale, ssq


@njit(cache=True, nogil=True)
def _robust_distance(xi, yj, segments):
    """``sqrt(sum_s d_s^2)`` without overflow or underflow (for extreme magnitudes)."""
    scale, ssq = 0.0, 1.0
    for s in range(segments.shape[0]):
        start, stop, code = segments[s, 0], segments[s, 1], segments[s, 2]
        if code == SEGMENT_EUCLIDEAN:
            for k in range(start, stop):
                scale, ssq = _accumulate_scaled(xi[k] - yj[k], scale, ssq)
        elif code >= SEGMENT_SPD2:  # log-eigenvalues are at most ~745: no overflow
            spd = math.sqrt(spd_squared_distance(xi, yj, start, spd_size(code)))
            scale, ssq = _accumulate_scaled(spd, scale, ssq)
        else:
            dot = 0.0
            for k in range(start, stop):
                dot += xi[k] * yj[k]
            perp_scale, perp_ssq = 0.0, 1.0
            for k in range(start, stop):
                perp_scale, perp_ssq = _accumulate_scaled(
                    yj[k] - dot * xi[k], perp_scale, perp_ssq
                )
            angle = math.atan2(
                perp_scale * math.sqrt(perp_ssq),
                abs(dot) if code == SEGMENT_SIGN_INVARIANT_SPHERE else dot,
            )
            scale, ssq = _accumulate_scaled(angle, scale, ssq)
    return scale * math.sqrt(ssq)


#: Sums of squares outside [TINY, HUGE] lost precision to underflow or overflow.
_TINY, _HUGE = 1e-290, 1e290


@njit(cache=True, nogil=True, inline="always")
def _cost_row(x, y, i, ny, segments, squared, row):
    """Row ``i`` of the cost matrix: point costs between ``x[i]`` and ``y[:ny]``."""
    xi = x[i]
    n_segments = segments.shape[0]
    if n_segments == 1 and segments[0, 2] == SEGMENT_EUCLIDEAN and segments[0, 1] == 1:
        a = xi[0]  # univariate: |a - b| exactly, at any magnitude
        for j in range(ny):
            diff = abs(a - y[j, 0])
            row[j] = diff * diff if squared else diff
        return
    for j in range(ny):
        row[j] = 0.0
    for s in range(n_segments):
        start, stop, code = segments[s, 0], segments[s, 1], segments[s, 2]
        if code == SEGMENT_EUCLIDEAN:
            for j in range(ny):
                sq = 0.0
                for k in range(start, stop):
                    diff = xi[k] - y[j, k]
                    sq += diff * diff
                row[j] += sq
        elif code >= SEGMENT_SPD2:
            for j in range(ny):
                row[j] += spd_squared_distance(xi, y[j], start, spd_size(code))
        else:
            for j in range(ny):
                dot = 0.0
                for k in range(start, stop):
                    dot += xi[k] * y[j, k]
                perp = 0.0
                for k in range(start, stop):
                    r = y[j, k] - dot * xi[k]
                    perp += r * r
                angle = math.atan2(
                    math.sqrt(perp), abs(dot) if code == SEGMENT_SIGN_INVARIANT_SPHERE else dot
                )
                row[j] += angle * angle
    if not squared:
        for j in range(ny):
            sq = row[j]
            if sq < _TINY or sq > _HUGE:  # recompute without under- or overflow
                row[j] = _robust_distance(xi, y[j], segments)
            else:
                row[j] = math.sqrt(sq)


@njit(cache=True, nogil=True)
def segment_cost_matrix(x, y, nx, ny, segments, squared, out):
    """Cost matrix of flattened series ``x`` (Tx, p) and ``y`` (Ty, p) into ``out``."""
    for i in range(nx):
        _cost_row(x, y, i, ny, segments, squared, out[i])


@njit(cache=True, nogil=True)
def path_cost(x, y, path, segments, squared):
    """The cost of a warping path ``(P, 2)`` between flattened series, summed along it
    in order: the value the DTW recursion gives that path, bit for bit (the same point
    costs, added in the same order)."""
    total = 0.0
    cost = np.empty(1)
    for k in range(path.shape[0]):
        j = path[k, 1]
        _cost_row(x, y[j : j + 1], path[k, 0], 1, segments, squared, cost)
        total = cost[0] + total
    return total


#: Point costs of a pruned row are computed this many columns at a time (vectorised as in
#: :func:`_cost_row`); a row that stops early wastes at most this many.
PRUNE_CHUNK = 32


@njit(cache=True, nogil=True, inline="always")
def _pruned_row(x, y, i, prev, cur, costs, lo, hi, reach, bound, segments, squared):
    """Row ``i`` of the accumulated cost into ``cur`` (padded as in :func:`_accumulate_row`)
    from column ``lo`` on, skipping what cannot beat ``bound`` (PrunedDTW: Silva and
    Batista, 2016). ``costs`` is a scratch row of at least ``hi`` entries.

    A cell is "kept" when its accumulated cost is at most ``bound``. ``reach`` is the last
    kept column of the row above plus one: past it the cells above and above-left exceed
    the bound, so the first cell there that exceeds it ends the row (every cell to its
    right would too). Returns the first and last kept columns (-1 if none) and the last
    column written.
    """
    if bound == _INF:  # nothing to skip: the plain recursion
        _cost_row(x, y[lo:hi], i, hi - lo, segments, squared, costs[lo:hi])
        _band_row(costs, prev, cur, lo, hi)
        return lo, hi - 1, hi - 1
    left = _INF
    first, last = -1, -1
    for chunk in range(lo, hi, PRUNE_CHUNK):
        stop = min(hi, chunk + PRUNE_CHUNK)
        _cost_row(x, y[chunk:stop], i, stop - chunk, segments, squared, costs[chunk:stop])
        for j in range(chunk, stop):
            left = _cell(prev, left, j, costs[j])
            cur[j + 1] = left
            if left <= bound:
                if first < 0:
                    first = j
                last = j
            elif j >= reach:
                return first, last, j
    return first, last, hi - 1


@njit(cache=True, nogil=True)
def accumulated_segment_cost(x, y, segments, squared, window, bound):
    """The accumulated cost of flattened series ``x`` and ``y`` where a path of cost at
    most ``bound`` can pass, stored row by row (:func:`_pruned_row`; ``inf``: every cell
    of the band).

    Every cell whose accumulated cost is at most ``bound`` holds the value of
    :func:`accumulated_cost` of :func:`segment_cost_matrix`, bit for bit; every other
    cell holds that value or more (``inf`` where skipped). So when the last cell is at
    most ``bound`` (the cost of any path inside the band bounds it), it and the optimal
    path backtracked from it are the exact ones; otherwise the bound was too low and the
    caller recomputes with ``inf``. Row ``i`` starts at the first kept column of row
    ``i - 1``: the cells computed are a band around the paths cheaper than the bound, and
    only they are stored (memory in proportion to them, not to ``T_x T_y``).

    Returns ``(values, offsets, starts)``: row ``i`` holds columns ``starts[i]`` onwards
    in ``values[offsets[i]:offsets[i + 1]]`` (:func:`ragged_value` reads a cell).
    """
    lo, hi = sakoe_chiba_rows(x.shape[0], y.shape[0], window)
    return _pruned_rows(x, y, segments, squared, lo, hi, bound, True)[:3]


@njit(cache=True, nogil=True)
def band_segment_cost(x, y, segments, squared, lo, hi):
    """:func:`accumulated_segment_cost` in any staircase band: row ``i`` holds the columns
    ``lo[i] <= j < hi[i]`` (``lo`` and ``hi`` non-decreasing, ``lo[0] = 0``,
    ``hi[-1] = len(y)``), every cell of it computed; the same ``(values, offsets,
    starts)`` rows."""
    return _pruned_rows(x, y, segments, squared, lo, hi, _INF, True)[:3]


@njit(cache=True, nogil=True)
def band_accumulated_cost(costs, lo, hi):
    """:func:`band_segment_cost` from point costs computed elsewhere: ``costs`` holds the
    band's cells row after row (row ``i``: columns ``lo[i]`` to ``hi[i] - 1``). Returns
    the same ``(values, offsets, starts)`` rows (:func:`ragged_value` reads a cell)."""
    nx, ny = lo.shape[0], hi[-1]
    prev, cur = _two_rows(ny)
    row = np.empty(ny)
    values = np.empty(costs.shape[0])
    offsets = np.zeros(nx + 1, dtype=np.int64)
    for i in range(nx):
        offsets[i + 1] = offsets[i] + hi[i] - lo[i]
        row[lo[i] : hi[i]] = costs[offsets[i] : offsets[i + 1]]
        _band_row(row, prev, cur, lo[i], hi[i])
        values[offsets[i] : offsets[i + 1]] = cur[lo[i] + 1 : hi[i] + 1]
        prev, cur = cur, prev
    return values, offsets, lo.copy()


@njit(cache=True, nogil=True)
def pruned_distance(x, y, segments, squared, window, bound):
    """The DTW distance of flattened series ``x`` and ``y`` in two rows of memory, the
    cells that cannot beat ``bound`` skipped as in :func:`accumulated_segment_cost`:
    exact when at most ``bound``, otherwise some value above it (``inf`` if the bound
    was too low)."""
    if bound == _INF:  # the plain recursion, without the pruning's bookkeeping per row
        lo, hi = sakoe_chiba_rows(x.shape[0], y.shape[0], window)
        prev, cur = _two_rows(y.shape[0])
        costs = np.empty(y.shape[0])
        for i in range(x.shape[0]):
            _cost_row(x, y[lo[i] : hi[i]], i, hi[i] - lo[i], segments, squared,
                      costs[lo[i] : hi[i]])  # fmt: skip
            _band_row(costs, prev, cur, lo[i], hi[i])
            prev, cur = cur, prev
        return prev[y.shape[0]]
    lo, hi = sakoe_chiba_rows(x.shape[0], y.shape[0], window)
    return _pruned_rows(x, y, segments, squared, lo, hi, bound, False)[3]


@njit(cache=True, nogil=True)
def _pruned_rows(x, y, segments, squared, lo, hi, bound, store):
    """Rows of the accumulated cost in two buffers, each kept in ``values`` if ``store``:
    ``(values, offsets, starts, last cell)`` (see :func:`accumulated_segment_cost`), in
    the staircase band ``[lo[i], hi[i])``."""
    nx, ny = x.shape[0], y.shape[0]
    prev, cur = _two_rows(ny)
    costs = np.empty(ny)
    rows = nx if store else 0  # a distance alone allocates nothing per row
    values = np.empty(min(nx * ny, max(1 << 16, 64 * (nx + ny))) if store else 0)
    offsets = np.zeros(rows + 1, dtype=np.int64)
    starts = np.zeros(rows, dtype=np.int64)
    start, reach = 0, 0  # row -1 keeps only its sentinel (column -1)
    prev_end, cur_end = 0, 0  # the last padded entry each buffer holds a value in
    for i in range(nx):
        a = max(lo[i], start)
        cur[a] = _INF  # column a - 1, which the next row reads and this one does not write
        first, last, written = _pruned_row(
            x, y, i, prev, cur, costs, a, hi[i], reach, bound, segments, squared
        )
        for k in range(written + 2, cur_end + 1):  # what two rows ago left further right
            cur[k] = _INF
        cur_end = max(written + 1, a)
        if store:
            n = written - a + 1
            if offsets[i] + n > values.shape[0]:  # grow by doubling
                grown = np.empty(max(2 * values.shape[0], offsets[i] + n))
                grown[: offsets[i]] = values[: offsets[i]]
                values = grown
            values[offsets[i] : offsets[i] + n] = cur[a + 1 : written + 2]
            starts[i], offsets[i + 1] = a, offsets[i] + n
        if first < 0:  # no cell of this row is kept: nor is the last cell
            if store:
                offsets[i + 2 :] = offsets[i + 1]
            return values[: offsets[rows]], offsets, starts, _INF
        start, reach = first, last + 1
        prev, cur = cur, prev
        prev_end, cur_end = cur_end, prev_end
    return values[: offsets[rows]], offsets, starts, prev[ny]


@njit(cache=True, nogil=True, inline="always")
def ragged_value(values, offsets, starts, i, j):
    """Cell ``(i, j)`` of :func:`accumulated_segment_cost`'s rows (``inf`` if not stored)."""
    k = j - starts[i]
    if k < 0 or k >= offsets[i + 1] - offsets[i]:
        return _INF
    return values[offsets[i] + k]


@njit(cache=True, nogil=True, inline="always")
def _ragged_step(values, offsets, starts, i, j):
    """The cell before ``(i, j)`` on the optimal path through stored rows."""
    if i == 0:
        return i, j - 1
    if j == 0:
        return i - 1, j
    return choose_step(
        i, j,
        ragged_value(values, offsets, starts, i - 1, j - 1),
        ragged_value(values, offsets, starts, i - 1, j),
        ragged_value(values, offsets, starts, i, j - 1),
    )  # fmt: skip


@njit(cache=True, nogil=True)
def ragged_backtrack(values, offsets, starts, ny):
    """The optimal path ``(P, 2)`` through :func:`accumulated_segment_cost`'s rows, ties
    broken as :func:`backtrack` breaks them."""
    nx = starts.shape[0]
    i, j = nx - 1, ny - 1
    path = np.empty((nx + ny - 1, 2), dtype=np.int64)
    n = 0
    path[n, 0], path[n, 1] = i, j
    while i > 0 or j > 0:
        i, j = _ragged_step(values, offsets, starts, i, j)
        n += 1
        path[n, 0], path[n, 1] = i, j
    return path[: n + 1][::-1].copy()


@njit(cache=True, nogil=True, parallel=True)
def segment_cost_stack(x, Y, nx, nys, segments, squared):
    """Cost matrices between ``x`` and each series of ``Y``, shape (len(Y), Tx, Ty)."""
    out = np.zeros((Y.shape[0], x.shape[0], Y.shape[1]))
    for k in prange(Y.shape[0]):
        segment_cost_matrix(x, Y[k], nx, nys[k], segments, squared, out[k])
    return out


@njit(cache=True, nogil=True, parallel=True)
def pairwise_segments(X, lx, Y, ly, segments, squared, window, symmetric, bounds):
    """DTW between every series of ``X`` and of ``Y``, the cost rows computed in numba.

    Each cost row is computed just before the recursion consumes it, so the cost matrix
    never leaves the cache, and only within the band: a narrow band costs its width.
    ``bounds[i, j]`` is the cost of some path between the pair (``inf``: none known); the
    cells that cannot beat it are skipped (:func:`pruned_distance`; the pair is computed
    again without it if it was too low). Returns the distances, shape ``(len(X), len(Y))``.
    """
    n, m = X.shape[0], Y.shape[0]
    values = np.zeros((n, m))
    for k in prange(n * m):
        i = k // m
        j = k - i * m
        if symmetric and j <= i:
            continue
        x, y = X[i, : lx[i]], Y[j, : ly[j]]
        value = pruned_distance(x, y, segments, squared, window, bounds[i, j])
        if not value <= bounds[i, j]:
            value = pruned_distance(x, y, segments, squared, window, _INF)
        values[i, j] = value
    if symmetric:
        for i in range(n):
            for j in range(i):
                values[i, j] = values[j, i]
    return values


@njit(cache=True, nogil=True)
def matched_positions(references, reference_lengths, X, lengths, codes, segments, squared,
                      window):  # fmt: skip
    """For every series, the mean index of its samples matched with each sample of its
    reference on their optimal DTW path (the path of :func:`accumulated_segment_cost`
    without a bound, ties broken as :func:`backtrack` breaks them).

    ``references`` ``(G, L, p)`` with ``reference_lengths``; series ``X`` ``(N, T, p)``
    with ``lengths``, series ``n`` aligned to reference ``codes[n]``. Returns ``(N, L)``:
    row ``n`` holds ``reference_lengths[codes[n]]`` values (the rest is zero). One pass,
    no path stored: every pair costs its DTW and nothing else.
    """
    n = X.shape[0]
    out = np.zeros((n, references.shape[1]))
    counts = np.zeros(references.shape[1])
    for k in range(n):
        reference = references[codes[k], : reference_lengths[codes[k]]]
        nx, ny = reference.shape[0], lengths[k]
        values, offsets, starts = accumulated_segment_cost(
            reference, X[k, :ny], segments, squared, window, _INF
        )
        counts[:nx] = 0.0
        i, j = nx - 1, ny - 1
        out[k, i], counts[i] = j, 1.0
        while i > 0 or j > 0:
            i, j = _ragged_step(values, offsets, starts, i, j)
            out[k, i] += j
            counts[i] += 1.0
        for i in range(nx):
            out[k, i] /= counts[i]
    return out
