"""Nearest references by DTW, with lower bounds and early abandoning.

A nearest-centroid classifier with many centroids, 1-NN DTW, and the leave-one-out
scores of the ``"auto"`` choice all ask the same question: for every query series, the
DTW distance to the nearest reference of every class. The exhaustive answer computes
every pair; :func:`nearest_by_class` computes the same values with far fewer cells
(Keogh and Ratanamahatana 2005; Rakthanmanon et al. 2012, the "UCR suite"):

1. **LB_Keogh** of every pair: the envelope of the query over the Sakoe-Chiba band (for
   every column ``j`` of the reference, the coordinate-wise least and greatest value of
   the query samples that may be matched with it), and the distance of every reference
   sample to that envelope. Every column is on the warping path, and a point's cost to
   any query sample of its band is at least its distance to the envelope, so the sum
   bounds DTW from below. Each segment of a point turns its gap to the envelope into a
   bound on its own distance (the manifolds' table,
   :func:`~sk_rtw.manifolds._point_kernels.box_squared_bound`); segments combine their
   bounds as their distances are combined.
2. References are visited in increasing order of their bound; one whose bound exceeds
   the best distance found so far for its class is skipped, and the search stops once
   no bound left can beat any class. When only the nearest class is wanted (an argmin:
   ``predict``; whether another class is nearer than a series' own), the best distance
   over all classes is the threshold, and far classes are never searched to their end.
3. **Early abandoning**: the DTW of a visited reference is computed with that threshold
   as a bound (:func:`~sk_rtw.dtw._pruned.pruned_distance`, PrunedDTW): cells that
   cannot beat it are skipped, and the pair stops as soon as no path can. Where the
   diagonal path lies in the band (equal lengths, or no band), its cost
   (:func:`~sk_rtw.dtw._point_costs.diagonal_cost`, plus amerced DTW's penalty for the
   steps off the diagonal of unequal lengths) bounds the pair's distance from above and
   becomes the bound when it is lower: the first reference of a query is pruned too
   (measured on the proximity forest's searches: 10-25 % less time on ArrowHead and
   Lightning7, the same on GunPoint and ECG200). A cumulative bound per row (the UCR
   suite's, each later row against the reference's box in its band) was measured too
   and did not pay: its O(T) per pair cost what it saved.
4. **Amerced DTW** of equal lengths without a band: a path through a cell ``d`` columns
   off the diagonal pays at least ``2 d`` penalties, so only the band of radius
   ``bound / (2 penalty)`` can beat the bound (:func:`_amerced_band`): the pair is
   computed in it, and skipped when that band's LB_Keogh already exceeds the bound
   (7 % less time for a forest on Lightning2's 637 samples, none on short series).

The distances returned are those of the exhaustive search bit for bit: a reference that
is skipped cannot be nearer than the best so far (nor tie with it), and a distance that
is computed is the plain recursion's value whenever it can matter. A relative slack of
:data:`LB_SLACK` keeps a rounding difference between the bound and the distance from
skipping a tie.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit, prange

from .._numba import numba_threads, serial_build
from ..manifolds import Manifold
from ..manifolds._point_kernels import box_squared_bound, outside
from ..utils import SeriesCollection, check_series_collection
from . import _kernels, _point_costs, _pruned
from ._dtw import check_warp_penalty, check_window, dtw_pairwise_distance
from ._kernels import sakoe_chiba_rows

_INF = np.inf

#: A reference is skipped when its bound exceeds the best distance so far by this
#: relative margin or more (the bound and the distance are rounded differently).
LB_SLACK = 1e-12
#: Queries are searched in at most this many blocks, each allocating its buffers once.
QUERY_BLOCKS = 64
#: Up to this many references are ordered by insertion sort (no allocation).
SMALL_SORT = 32


@njit(cache=True, nogil=True)
def query_envelope(x, ny, window, lower, upper):
    """The envelope of query ``x`` (``(T_x, p)``) seen from a reference of ``ny`` samples.

    Column ``j`` of an ``T_x x ny`` DTW matrix may be matched with the query rows ``i``
    whose Sakoe-Chiba range holds ``j`` (:func:`~sk_rtw.dtw._kernels.sakoe_chiba_rows`):
    a contiguous run ``[a_j, b_j]`` whose ends never decrease with ``j``. ``lower[j]`` and
    ``upper[j]`` (each ``(p,)``) receive the coordinate-wise least and greatest query
    value over that run (a monotone-deque sliding minimum and maximum, ``O(T_x + ny)``
    per coordinate).
    """
    nx = x.shape[0]
    scratch = np.empty(4 * nx + 2 * ny, dtype=np.int64)
    _envelope(x, ny, window, lower, upper, scratch)


@njit(cache=True, nogil=True)
def _envelope(x, ny, window, lower, upper, scratch):
    """:func:`query_envelope` in ``scratch`` (at least ``4 T_x + 2 ny`` integers): no
    allocation, for a search that computes one envelope per reference length."""
    nx, p = x.shape
    lo, hi = _kernels.sakoe_chiba_rows(nx, ny, window)
    first = scratch[:ny]  # a_j: the first row whose range reaches j
    last = scratch[ny : 2 * ny]  # b_j: the last row whose range starts at or before j
    low_queue = scratch[2 * ny : 2 * ny + nx]
    high_queue = scratch[2 * ny + nx : 2 * ny + 2 * nx]
    i = 0
    for j in range(ny):
        while hi[i] <= j:
            i += 1
        first[j] = i
    i = nx - 1
    for j in range(ny - 1, -1, -1):
        while lo[i] > j:
            i -= 1
        last[j] = i
    for k in range(p):
        low_head, low_tail, high_head, high_tail = 0, 0, 0, 0
        pushed = 0  # rows [0, pushed) have entered the queues
        for j in range(ny):
            while pushed <= last[j]:
                value = x[pushed, k]
                while low_tail > low_head and x[low_queue[low_tail - 1], k] >= value:
                    low_tail -= 1
                low_queue[low_tail] = pushed
                low_tail += 1
                while high_tail > high_head and x[high_queue[high_tail - 1], k] <= value:
                    high_tail -= 1
                high_queue[high_tail] = pushed
                high_tail += 1
                pushed += 1
            while low_queue[low_head] < first[j]:
                low_head += 1
            while high_queue[high_head] < first[j]:
                high_head += 1
            lower[j, k] = x[low_queue[low_head], k]
            upper[j, k] = x[high_queue[high_head], k]


@njit(cache=True, nogil=True, inline="always")
def _box_cost(point, lower, upper, segments, squared, root):
    """A lower bound of the point cost between ``point`` (``(p,)``, kernel form) and any
    point whose coordinates lie in ``[lower, upper]`` (module docstring: the gap to the
    box, turned into a bound on the segment's distance; ``root``: costs are the square
    roots of the distances, an increasing function of them too)."""
    n_segments = segments.shape[0]
    if _point_costs.is_univariate(segments):
        return _point_costs.univariate_cost(outside(point[0], lower[0], upper[0]), squared, root)
    sq = 0.0
    for s in range(n_segments):
        sq += box_squared_bound(point, lower, upper, segments[s, 0], segments[s, 1],
                                segments[s, 2])  # fmt: skip
    near = sq if squared else math.sqrt(sq)
    return math.sqrt(near) if root else near


@njit(cache=True, nogil=True)
def lb_keogh(y, lower, upper, segments, squared, root=False):
    """LB_Keogh of reference ``y`` (``(T_y, p)``) against a query's envelope
    (:func:`query_envelope`), in the point cost of ``segments`` (module docstring)."""
    total = 0.0
    if _point_costs.is_univariate(segments):  # one coordinate: the gap itself, in a tight loop
        for j in range(y.shape[0]):
            gap = outside(y[j, 0], lower[j, 0], upper[j, 0])
            total += _point_costs.univariate_cost(gap, squared, root)
        return total
    for j in range(y.shape[0]):
        total += _box_cost(y[j], lower[j], upper[j], segments, squared, root)
    return total


@njit(cache=True, nogil=True, inline="always")
def _amerced_band(nx, ny, window, penalty, bound):
    """The band of an amerced DTW that only a distance within ``bound`` is wanted of.

    Between series of equal length, a path through a cell ``d`` columns off the diagonal
    takes at least ``d`` steps off it to get there and ``d`` to come back, so it costs at
    least ``2 d penalty``: the paths within ``bound`` stay in the Sakoe-Chiba band of
    radius ``bound / (2 penalty)``, which gives them the same values (and any other
    distance stays above the bound). Returns that band's window where it is narrower
    than ``window`` (else ``window``)."""
    if penalty <= 0.0 or nx != ny or bound == _INF:
        return window
    radius = math.floor(bound / (2.0 * penalty) * (1.0 + 1e-9))
    if radius >= nx - 1:
        return window
    narrow = (radius + 0.5) / nx
    if window < 0.0 or narrow < window:
        return narrow
    return window


def _nearest_by_class(
    Q, lq, R, lr, owners, n_classes, skip_reference, skip_class, limits, every_class,
    segments, squared, window, penalty, root,
):  # fmt: skip
    """DTW distance of every query to the nearest reference of every class (module
    docstring), the values of the exhaustive search.

    ``Q`` ``(n_q, T, p)`` with lengths ``lq``; references ``R`` ``(n_r, L, p)`` with lengths
    ``lr`` and classes ``owners`` (``0..n_classes - 1``). Query ``q`` ignores reference
    ``skip_reference[q]`` and the references of class ``skip_class[q]`` (-1: none), and
    distances above ``limits[q]``. With ``every_class`` every class's nearest distance is
    computed; otherwise only the nearest class's (and those tied with it), the others
    left ``inf``. ``penalty`` is amerced DTW's (0: DTW; LB_Keogh bounds both, a penalty
    only adds to a path's cost); ``root``: the point costs are the square roots of the
    distances (``squared=False``). Returns the distances ``(n_q, n_classes)`` (``inf``
    where none was wanted or left) and the number of exact DTWs computed per query.
    """
    n_q, n_r, p = Q.shape[0], R.shape[0], Q.shape[2]
    out = np.full((n_q, n_classes), _INF)
    computed = np.zeros(n_q, dtype=np.int64)
    by_length = np.argsort(lr, kind="mergesort")  # envelopes computed once per length
    n_blocks = min(n_q, QUERY_BLOCKS)
    for block in prange(n_blocks):  # the buffers of a block's queries allocated once
        lower = np.empty((R.shape[1], p))
        upper = np.empty((R.shape[1], p))
        scratch = np.empty(4 * Q.shape[1] + 2 * R.shape[1], dtype=np.int64)
        narrow_lower = np.empty((R.shape[1] if penalty > 0.0 else 0, p))
        narrow_upper = np.empty((R.shape[1] if penalty > 0.0 else 0, p))
        candidates = np.empty(n_r, dtype=np.int64)
        bounds = np.empty(n_r)
        order = np.empty(n_r, dtype=np.int64)
        available = np.zeros(n_classes, dtype=np.bool_)
        rows = np.empty((3, R.shape[1] + 1))  # the DTW's rows
        band = np.empty((2, Q.shape[1]), dtype=np.int64)  # its band's rows, while it holds
        banded = np.array([-2.0, -1.0, -1.0])  # for this window and these lengths
        for q in range(block * n_q // n_blocks, (block + 1) * n_q // n_blocks):
            _search_query(
                q, Q[q, : lq[q]], R, lr, owners, n_classes, skip_reference, skip_class,
                limits, every_class, segments, squared, window, penalty, root, by_length,
                out[q], computed, lower, upper, scratch, narrow_lower, narrow_upper,
                candidates, bounds, order, available, rows, band, banded,
            )  # fmt: skip
    return out, computed


@njit(cache=True, nogil=True)
def _search_query(
    q, x, R, lr, owners, n_classes, skip_reference, skip_class, limits, every_class,
    segments, squared, window, penalty, root, by_length, best, computed, lower, upper,
    scratch, narrow_lower, narrow_upper, candidates, bounds, order, available, rows, band,
    banded,
):  # fmt: skip
    """:func:`_nearest_by_class` of query ``q`` (``x``) into ``best`` (its row of the
    distances, ``inf``), with buffers of the caller's (``band`` holds the Sakoe-Chiba
    rows of the window and lengths in ``banded``)."""
    enveloped, enveloped_length = -2.0, -1  # the band and length of that envelope
    available[:] = False
    n = 0
    current = -1
    for r in by_length:
        if r == skip_reference[q] or owners[r] == skip_class[q]:
            continue
        if lr[r] != current:
            current = lr[r]
            _envelope(x, current, window, lower, upper, scratch)
        candidates[n] = r
        bounds[n] = lb_keogh(R[r, : lr[r]], lower, upper, segments, squared, root)
        available[owners[r]] = True
        n += 1
    nearest = limits[q]  # the least distance found (or the limit)
    worst = limits[q] if every_class else nearest  # no class can improve above it
    _stable_order(bounds, n, order)
    for rank in range(n):
        position = order[rank]
        bound = bounds[position] * (1.0 - LB_SLACK)
        if bound > worst:
            break
        r = candidates[position]
        c = owners[r]
        threshold = min(best[c], limits[q]) if every_class else nearest
        if bound > threshold:
            continue
        y = R[r, : lr[r]]
        cut = threshold
        if (window < 0.0 or window >= 1.0 or x.shape[0] == y.shape[0]) and cut > 0.0:
            # the diagonal path lies in the band: its cost bounds this pair's distance
            diagonal = _point_costs.diagonal_cost(x, y, segments, squared, root)
            diagonal += penalty * abs(x.shape[0] - y.shape[0])
            cut = min(cut, diagonal * (1.0 + LB_SLACK))
        width = _amerced_band(x.shape[0], y.shape[0], window, penalty, cut)
        if width != window and threshold < _INF:
            # the paths that can beat the threshold lie in the narrower band: its
            # LB_Keogh may rule the pair out (the full band's seldom does); the query's
            # envelope in it changes only with the band
            narrow = _amerced_band(x.shape[0], y.shape[0], window, penalty, threshold)
            if narrow != enveloped or y.shape[0] != enveloped_length:
                _envelope(x, y.shape[0], narrow, narrow_lower, narrow_upper, scratch)
                enveloped, enveloped_length = narrow, y.shape[0]
            bound = lb_keogh(y, narrow_lower, narrow_upper, segments, squared, root)
            if bound * (1.0 - LB_SLACK) > threshold:
                continue
        lo, hi = _band_rows(x.shape[0], y.shape[0], width, band, banded)
        value = _pruned.banded_distance(x, y, segments, squared, lo, hi, cut, penalty, root,
                                        rows)  # fmt: skip
        if value > cut and cut < threshold:  # rounding beat the slack: bound it again
            width = _amerced_band(x.shape[0], y.shape[0], window, penalty, threshold)
            lo, hi = _band_rows(x.shape[0], y.shape[0], width, band, banded)
            value = _pruned.banded_distance(x, y, segments, squared, lo, hi, threshold,
                                            penalty, root, rows)  # fmt: skip
        computed[q] += 1
        if value <= threshold and value < best[c]:
            best[c] = value
            nearest = min(nearest, value)
            if every_class:
                worst = 0.0
                for k in range(n_classes):
                    if available[k] and best[k] > worst:
                        worst = best[k]
                worst = min(worst, limits[q])
            else:
                worst = nearest
    if not every_class:
        for k in range(n_classes):
            if best[k] > nearest:
                best[k] = _INF


@njit(cache=True, nogil=True, inline="always")
def _band_rows(nx, ny, window, band, banded):
    """The Sakoe-Chiba rows of an ``nx x ny`` pair in ``window``
    (:func:`~._kernels.sakoe_chiba_rows`), computed again only when the window or the
    lengths differ from those ``banded`` holds."""
    if window != banded[0] or nx != banded[1] or ny != banded[2]:
        lo, hi = sakoe_chiba_rows(nx, ny, window)
        band[0, :nx] = lo
        band[1, :nx] = hi
        banded[0], banded[1], banded[2] = window, nx, ny
    return band[0, :nx], band[1, :nx]


@njit(cache=True, nogil=True)
def _stable_order(values, n, order):
    """``order[:n]`` = ``np.argsort(values[:n], kind="stable")``, without allocating for
    the few values of a node's exemplars (insertion sort up to :data:`SMALL_SORT`)."""
    if n > SMALL_SORT:
        order[:n] = np.argsort(values[:n], kind="mergesort")
        return
    for k in range(n):
        value = values[k]
        m = k
        while m > 0 and values[order[m - 1]] > value:
            order[m] = order[m - 1]
            m -= 1
        order[m] = k


#: :func:`_nearest_by_class` threaded over the queries, and on the calling thread alone
#: (for callers that run their own threads: the forest's trees).
nearest_by_class = njit(cache=True, nogil=True, parallel=True)(_nearest_by_class)
nearest_by_class_serial = serial_build(_nearest_by_class, cache=True, nogil=True)


def dtw_nearest_distance(
    X: Any,
    Y: Any,
    groups: Any = None,
    manifold: str | Manifold = "euclidean",
    window: float | None = None,
    squared: bool = False,
    exclude: Any = None,
    exclude_group: Any = None,
    max_distance: Any = None,
    nearest_only: bool = False,
    n_jobs: int | None = None,
    warp_penalty: float = 0.0,
) -> np.ndarray:
    """DTW distance from every series of ``X`` to the nearest series of ``Y`` in every
    group: ``dtw_pairwise_distance(X, Y)`` reduced by group, without computing every pair.

    Lower bounds (LB_Keogh) skip the series of ``Y`` that cannot be nearer than the
    best distance so far, and the exact DTWs stop early once they cannot (module
    docstring of :mod:`sk_rtw.dtw._search`); the values are those of the exhaustive
    search, bit for bit. Every shipped manifold is searched so (SPD matrices by the
    bound of their sorted log-eigenvalues, up to 12 x 12); manifolds whose point
    distances have no compiled form (yours, larger SPD matrices) take the exhaustive
    search.

    Parameters
    ----------
    X : array-like or list of array-like
        The query series: ``(n, T)``, ``(n, T, *point_shape)`` or a list.
    Y : same forms as ``X``
        The reference series.
    groups : array-like of int, shape (n_Y,), optional
        Group of every series of ``Y``, ``0..n_groups - 1`` (a class, or the class of a
        centroid); default: one group (the nearest series overall).
    manifold, window, squared
        As in :func:`~sk_rtw.dtw.dtw_distance`.
    exclude : array-like of int, shape (n_X,), optional
        For every series of ``X``, a series of ``Y`` it is not compared with (-1: none):
        ``np.arange(n)`` with ``Y`` = ``X`` gives leave-one-out nearest neighbours.
    exclude_group : array-like of int, shape (n_X,), optional
        For every series of ``X``, a group it is not compared with (-1: none); its column
        is ``inf``.
    max_distance : float or array-like of shape (n_X,), optional
        Distances above it (per series of ``X``) are not wanted: they are skipped early
        and reported as ``inf``.
    nearest_only : bool, default=False
        Only the nearest group of every series is wanted (its distance, and any group
        tied with it; ``inf`` elsewhere): all that ``argmin`` needs, and far cheaper
        when the groups are well apart, since no group but the nearest must be searched
        to its end.
    n_jobs : int, optional
        Threads over the series of ``X`` (numba); ``-1`` uses all cores. Default: 1.
    warp_penalty : float, default=0.0
        As in :func:`~sk_rtw.dtw.dtw_distance`: amerced DTW's penalty on every step off
        the diagonal (the same bounds hold: a penalty only adds to a path's cost).

    Returns
    -------
    distances : ndarray of shape (n_X, n_groups)
        ``inf`` where a group has no series left to compare with (or none was wanted).

    Examples
    --------
    >>> import numpy as np
    >>> X = np.array([[0.0, 1.0, 2.0], [5.0, 5.0, 5.0]])
    >>> Y = np.array([[0.0, 1.0, 1.0, 2.0], [9.0, 9.0, 9.0, 9.0], [5.0, 5.0, 6.0, 5.0]])
    >>> dtw_nearest_distance(X, Y, groups=[0, 1, 1])
    array([[ 0., 16.],
           [16.,  1.]])
    """
    return _nearest(X, Y, groups, manifold, window, squared, exclude, exclude_group,
                    max_distance, nearest_only, n_jobs, warp_penalty)[0]  # fmt: skip


def _nearest(X, Y, groups, manifold, window, squared, exclude, exclude_group, max_distance,
             nearest_only, n_jobs, warp_penalty=0.0):  # fmt: skip
    """:func:`dtw_nearest_distance` and the number of exact DTWs it computed per series
    of ``X`` (every pair's count for the exhaustive search)."""
    w = check_window(window)
    penalty = check_warp_penalty(warp_penalty)
    cx = X if isinstance(X, SeriesCollection) else check_series_collection(
        X, manifold, name="X", min_length=1
    )
    cy = Y if isinstance(Y, SeriesCollection) else check_series_collection(
        Y, cx.manifold, name="Y", min_length=1
    )
    n, m = cx.n_series, cy.n_series
    owners = _indices(groups, m, "groups", np.zeros(m, dtype=np.int64), lowest=0)
    n_groups = int(owners.max()) + 1
    skip = _indices(exclude, n, "exclude", np.full(n, -1, dtype=np.int64), lowest=-1)
    skip_group = _indices(exclude_group, n, "exclude_group", np.full(n, -1, dtype=np.int64),
                          lowest=-1)  # fmt: skip
    if n and skip.max() >= m:
        raise ValueError(f"exclude holds {skip.max()}, but Y has {m} series")
    limit = np.asarray(np.inf if max_distance is None else max_distance)
    if limit.ndim > 1 or (limit.ndim == 1 and limit.shape != (n,)):
        raise ValueError(
            f"max_distance must be a number or {n} numbers, one per series of X; got shape "
            f"{limit.shape}"
        )
    if limit.dtype.kind not in "biuf":
        raise TypeError(f"max_distance must be numeric, got {limit.dtype}")
    limits = np.ascontiguousarray(np.broadcast_to(limit, (n,)), dtype=np.float64)
    if np.isnan(limits).any():
        raise ValueError("max_distance must not be NaN")
    segments = _point_costs.segment_codes(cx.manifold)
    if segments is None:
        distances = dtw_pairwise_distance(cx, cy, window=window, squared=squared,
                                          n_jobs=n_jobs, warp_penalty=penalty)  # fmt: skip
        rows = np.flatnonzero(skip >= 0)
        distances[rows, skip[rows]] = np.inf
        distances[skip_group[:, None] == owners[None, :]] = np.inf
        distances[distances > limits[:, None]] = np.inf
        out = np.full((n, n_groups), np.inf)
        np.minimum.at(out.T, owners, distances.T)
        if nearest_only:
            out[out > out.min(1, keepdims=True)] = np.inf
        return out, np.full(n, m, dtype=np.int64)
    with numba_threads(n_jobs):
        return nearest_by_class(
            _point_costs.kernel_series(cx), cx.lengths, _point_costs.kernel_series(cy), cy.lengths,
            owners, n_groups, skip,
            skip_group, limits, not nearest_only, segments, bool(squared), w, penalty, False,
        )  # fmt: skip


def _indices(values: Any, size: int, name: str, default: np.ndarray, lowest: int) -> np.ndarray:
    if values is None:
        return default
    array = np.asarray(values)
    if array.shape != (size,) or array.dtype.kind not in "iu":
        raise ValueError(f"{name} must be {size} integers, one per series; got {array!r:.80}")
    if size and array.min() < lowest:
        raise ValueError(f"{name} must hold integers from {lowest} up; got {array.min()}")
    return np.ascontiguousarray(array, dtype=np.int64)
