"""The DTW recursion with its point costs computed inside it (:func:`~._point_costs.
_cost_row`, a row at a time, so the cost matrix is never stored), pruned by a bound and
stored by rows.

Given the cost of some path (a bound), the rows skip the cells that cannot beat it and
store only what they compute (:func:`_pruned_row`): the result is the same. Rows are
stored ragged (``values``, ``offsets``, ``starts``; :func:`ragged_value` reads a cell,
:func:`ragged_backtrack` the path), in a Sakoe-Chiba band or any staircase band
(:func:`band_segment_cost`). The pairwise and matched-position kernels run many pairs in
one compiled call.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ._kernels import _band_row, _two_rows, cell_value, choose_step, sakoe_chiba_rows
from ._point_costs import _cost_row, _roots, is_univariate, univariate_cost

_INF = np.inf


#: Point costs of a pruned row are computed this many columns at a time (vectorised as in
#: :func:`_cost_row`); a row that stops early wastes at most this many.
PRUNE_CHUNK = 32
#: A cell is pruned when its cost exceeds the bound less the last cell's cost by this
#: fraction of the bound (a few rounding units: a pruned cell's path ends above the bound).
LIMIT_MARGIN = 1e-15


@njit(cache=True, nogil=True, inline="always")
def _pruned_row(x, y, i, prev, cur, costs, lo, hi, reach, bound, segments, squared, penalty,
                root):  # fmt: skip
    """Row ``i`` of the accumulated cost into ``cur`` (padded as in :func:`_accumulate_row`)
    from column ``lo`` on, skipping what cannot beat ``bound`` (PrunedDTW: Silva and
    Batista, 2016; the two phases of a row as in EAP, Herrmann and Webb, 2021).
    ``costs`` is a scratch row of at least ``hi`` entries; ``penalty`` is amerced DTW's
    (:func:`~._kernels.cell_value`: a non-negative penalty keeps every argument below); with
    ``root`` every point cost is the square root of its distance
    (:func:`~._point_costs._roots`; with ``squared=False``).

    A cell is "kept" when its accumulated cost is at most ``bound``. ``reach`` is the last
    kept column of the row above plus one: before it every cell is computed; from it on
    the cells above and above-left exceed the bound, so the first cell there that exceeds
    it ends the row (every cell to its right would too). Returns the first and last kept
    columns (-1 if none) and the last column written. Point costs are computed
    :data:`PRUNE_CHUNK` columns at a time (a row that stops early wastes at most that
    many).
    """
    if bound == _INF:  # nothing to skip: the plain recursion
        _cost_row(x, y[lo:hi], i, hi - lo, segments, squared, costs[lo:hi])
        if root:
            _roots(costs[lo:hi], hi - lo)
        _band_row(costs, prev, cur, lo, hi, penalty)
        return lo, hi - 1, hi - 1
    left = _INF
    first, last = -1, -1
    for chunk in range(lo, hi, PRUNE_CHUNK):
        stop = min(hi, chunk + PRUNE_CHUNK)
        _cost_row(x, y[chunk:stop], i, stop - chunk, segments, squared, costs[chunk:stop])
        if root:
            _roots(costs[chunk:stop], stop - chunk)
        for j in range(chunk, stop):
            left = cell_value(prev[j], prev[j + 1], left, costs[j], penalty)
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
    return _pruned_rows(x, y, segments, squared, lo, hi, bound, True, 0.0, False)[:3]


@njit(cache=True, nogil=True)
def band_segment_cost(x, y, segments, squared, lo, hi):
    """:func:`accumulated_segment_cost` in any staircase band: row ``i`` holds the columns
    ``lo[i] <= j < hi[i]`` (``lo`` and ``hi`` non-decreasing, ``lo[0] = 0``,
    ``hi[-1] = len(y)``), every cell of it computed; the same ``(values, offsets,
    starts)`` rows."""
    return _pruned_rows(x, y, segments, squared, lo, hi, _INF, True, 0.0, False)[:3]


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
        _band_row(row, prev, cur, lo[i], hi[i], 0.0)
        values[offsets[i] : offsets[i + 1]] = cur[lo[i] + 1 : hi[i] + 1]
        prev, cur = cur, prev
    return values, offsets, lo.copy()


@njit(cache=True, nogil=True)
def pruned_distance(x, y, segments, squared, window, bound, penalty=0.0, root=False):
    """The DTW distance of flattened series ``x`` and ``y`` in two rows of memory, the
    cells that cannot beat ``bound`` skipped as in :func:`accumulated_segment_cost`:
    exact when at most ``bound``, otherwise some value above it (``inf`` if the bound
    was too low). ``penalty``: amerced DTW's, on every step off the diagonal (0: DTW);
    ``root``: point costs are the square roots of the distances."""
    lo, hi = sakoe_chiba_rows(x.shape[0], y.shape[0], window)
    rows = np.empty((3, y.shape[0] + 1))
    return banded_distance(x, y, segments, squared, lo, hi, bound, penalty, root, rows)


@njit(cache=True, nogil=True)
def banded_distance(x, y, segments, squared, lo, hi, bound, penalty, root, rows):
    """:func:`pruned_distance` in the staircase band ``[lo[i], hi[i])`` with the buffer
    ``rows`` (``(3, n)``, ``n > len(y)``): what a search that computes many pairs of one
    band keeps from one pair to the next instead of allocating it each time."""
    ny = y.shape[0]
    if bound == _INF:  # the plain recursion, without the pruning's bookkeeping per row
        prev, cur = rows[0], rows[1]
        prev[: ny + 1] = _INF
        prev[0] = 0.0
        cur[: ny + 1] = _INF
        costs = rows[2]
        for i in range(x.shape[0]):
            _cost_row(x, y[lo[i] : hi[i]], i, hi[i] - lo[i], segments, squared,
                      costs[lo[i] : hi[i]])  # fmt: skip
            if root:
                _roots(costs[lo[i] : hi[i]], hi[i] - lo[i])
            _band_row(costs, prev, cur, lo[i], hi[i], penalty)
            prev, cur = cur, prev
        return prev[ny]
    if is_univariate(segments):
        return _pruned_univariate(x, y, squared, lo, hi, bound, penalty, root, rows)
    return _pruned_rows(x, y, segments, squared, lo, hi, bound, False, penalty, root)[3]


def _univariate_kernel(squared: bool, root: bool, amerced: bool):
    """:func:`pruned_distance` of one Euclidean coordinate for one point cost and measure
    (compiled with them as constants: a flag tested at every cell costs a quarter of
    the time), every point cost computed where the recursion reads it, as
    :func:`~._point_costs._cost_row` computes it.

    Rows go in pairs: row ``i`` as :func:`_pruned_row` computes it (its phases, its end
    at the first cell past ``reach`` above the bound), row ``i + 1`` one column behind
    it in the same loop from row ``i``'s first kept cell on (two chains of dependent
    additions side by side: a bounded 637 x 637 pair in 275 us against 370 us one row at
    a time), then alone
    past where row ``i`` ended, in its own phases. Cells row ``i + 1`` computes beside
    row ``i`` beyond where a row alone would have stopped are above the bound and
    change no kept cell: every kept cell, and the distance when it is at most the bound,
    are those of the plain recursion bit for bit.

    A cell is kept when its cost is at most the bound less the last cell's point cost
    (every path pays it at its end; EAP's cut, Herrmann and Webb 2021), plus
    :data:`LIMIT_MARGIN` of the bound so that no rounding prunes a path within the
    bound; the last row returns its last cell whatever it holds (the bound decides).
    A pair of Crop's 46 samples in 5-15 % less time, 0-8 % on 96-637 samples."""

    def distance(x, y, lo, hi, bound, penalty, rows):
        nx, ny = x.shape[0], y.shape[0]
        step = penalty if amerced else 0.0
        # every path ends in the last cell and pays its cost: a cell above the bound less
        # that cost (and a margin over the roundings) cannot be on a path within it
        last_cost = univariate_cost(abs(x[nx - 1, 0] - y[ny - 1, 0]), squared, root)
        limit = bound - last_cost + bound * LIMIT_MARGIN if bound < _INF else _INF
        # padded rows (column j at j + 1): the row above (row -1: zero at the sentinel),
        # then the two rows computed; the last entry of each that may be finite
        above, first_row, second_row = rows[0], rows[1], rows[2]
        above[: ny + 1] = _INF
        above[0] = 0.0
        first_row[: ny + 1] = _INF
        second_row[: ny + 1] = _INF
        above_end, first_end, second_end = 0, 0, 0
        start, reach = 0, 0  # the first kept column of the row above, its last plus one
        i = 0
        while i < nx:
            a = x[i, 0]
            paired = i + 1 < nx
            b = x[i + 1, 0] if paired else 0.0
            s1, e1 = max(lo[i], start), hi[i]
            inner = min(max(reach, s1), e1)  # row i's cells before it cannot end it
            first_row[s1] = _INF
            left1, first1, last1, written1 = _INF, -1, -1, s1 - 1
            s2, c2 = -1, 0  # row i + 1's first column (once known) and its next one
            left2, first2, last2 = _INF, -1, -1
            j = s1
            while j < e1:  # row i alone, until row i + 1 can start one column behind
                cost = univariate_cost(abs(a - y[j, 0]), squared, root)
                left1 = cell_value(above[j], above[j + 1], left1, cost, step)
                first_row[j + 1] = left1
                written1 = j
                j += 1
                if left1 <= limit:
                    if first1 < 0:
                        first1 = j - 1
                        if paired:
                            s2 = c2 = max(lo[i + 1], j - 1)
                            second_row[s2] = _INF
                    last1 = j - 1
                elif j > inner:
                    j = e1 + 1  # row i ended
                if s2 >= 0 and c2 < j:
                    break
            while j < e1:  # both rows: row i at column j, row i + 1 at column j - 1
                cost = univariate_cost(abs(a - y[j, 0]), squared, root)
                left1 = cell_value(above[j], above[j + 1], left1, cost, step)
                first_row[j + 1] = left1
                c = j - 1
                cost = univariate_cost(abs(b - y[c, 0]), squared, root)
                left2 = cell_value(first_row[c], first_row[j], left2, cost, step)
                second_row[j] = left2
                if left2 <= limit:
                    if first2 < 0:
                        first2 = c
                    last2 = c
                written1 = j
                if left1 <= limit:
                    last1 = j
                c2 = j  # row i + 1's next column
                if left1 > limit and j >= inner:
                    break
                j += 1
            for k in range(written1 + 2, first_end + 1):  # what the buffer held further right
                first_row[k] = _INF
            first_end = max(written1 + 1, s1)
            if not paired:  # the last row: its last cell, within the bound or not
                return first_row[ny]
            if first1 < 0:  # no cell of row i is kept: nor is the last cell
                return _INF
            written2 = c2 - 1
            e2, reach2 = hi[i + 1], last1 + 1
            while c2 < e2:  # row i + 1 alone, past where row i ended
                cost = univariate_cost(abs(b - y[c2, 0]), squared, root)
                left2 = cell_value(first_row[c2], first_row[c2 + 1], left2, cost, step)
                second_row[c2 + 1] = left2
                written2 = c2
                if left2 <= limit:
                    if first2 < 0:
                        first2 = c2
                    last2 = c2
                elif c2 >= reach2:
                    break
                c2 += 1
            for k in range(written2 + 2, second_end + 1):
                second_row[k] = _INF
            second_end = max(written2 + 1, s2)
            if i + 2 == nx:
                return second_row[ny]
            if first2 < 0:
                return _INF
            start, reach = first2, last2 + 1
            above, second_row = second_row, above
            above_end, second_end = second_end, above_end
            i += 2
        return above[ny]

    # a cache entry of its own for each build (numba names entries by qualified name)
    cost = "squared" if squared else "root" if root else "plain"
    distance.__qualname__ = f"_univariate_{cost}{'_amerced' if amerced else ''}"
    return njit(cache=True, nogil=True)(distance)


#: :func:`_univariate_kernel` for every point cost (squared, plain, root) and measure
#: (DTW, amerced DTW).
_UNIVARIATE = tuple(
    _univariate_kernel(squared, root, amerced)
    for squared, root in ((True, False), (False, False), (False, True))
    for amerced in (False, True)
)
_SQ, _SQ_AMERCED, _PLAIN, _PLAIN_AMERCED, _ROOT, _ROOT_AMERCED = _UNIVARIATE


@njit(cache=True, nogil=True)
def _pruned_univariate(x, y, squared, lo, hi, bound, penalty, root, rows):
    """:func:`pruned_distance` of one Euclidean coordinate (:func:`_univariate_kernel`)."""
    if squared:
        if penalty == 0.0:
            return _SQ(x, y, lo, hi, bound, penalty, rows)
        return _SQ_AMERCED(x, y, lo, hi, bound, penalty, rows)
    if root:
        if penalty == 0.0:
            return _ROOT(x, y, lo, hi, bound, penalty, rows)
        return _ROOT_AMERCED(x, y, lo, hi, bound, penalty, rows)
    if penalty == 0.0:
        return _PLAIN(x, y, lo, hi, bound, penalty, rows)
    return _PLAIN_AMERCED(x, y, lo, hi, bound, penalty, rows)


@njit(cache=True, nogil=True)
def _pruned_rows(x, y, segments, squared, lo, hi, bound, store, penalty, root):
    """Rows of the accumulated cost in two buffers, each kept in ``values`` if ``store``:
    ``(values, offsets, starts, last cell)`` (see :func:`accumulated_segment_cost`), in
    the staircase band ``[lo[i], hi[i])``, off-diagonal steps amerced by ``penalty``."""
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
            x, y, i, prev, cur, costs, a, hi[i], reach, bound, segments, squared, penalty, root
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
def pairwise_segments(X, lx, Y, ly, segments, squared, window, symmetric, bounds, penalty):
    """DTW between every series of ``X`` and of ``Y``, the cost rows computed in numba.

    Each cost row is computed just before the recursion consumes it, so the cost matrix
    never leaves the cache, and only within the band: a narrow band costs its width.
    ``bounds[i, j]`` is the cost of some path between the pair (``inf``: none known); the
    cells that cannot beat it are skipped (:func:`pruned_distance`; the pair is computed
    again without it if it was too low); ``penalty`` is amerced DTW's. Returns the
    distances, shape ``(len(X), len(Y))``.
    """
    n, m = X.shape[0], Y.shape[0]
    values = np.zeros((n, m))
    for k in prange(n * m):
        i = k // m
        j = k - i * m
        if symmetric and j <= i:
            continue
        x, y = X[i, : lx[i]], Y[j, : ly[j]]
        value = pruned_distance(x, y, segments, squared, window, bounds[i, j], penalty)
        if not value <= bounds[i, j]:
            value = pruned_distance(x, y, segments, squared, window, _INF, penalty)
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
