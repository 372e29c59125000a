"""Rows of compiled point costs between series in the kernels' form.

The point geometry is the manifolds' (:mod:`sk_rtw.manifolds._point_kernels`, the one
table this package reads): a point's segments and their codes (:func:`segment_codes`),
its kernel form (:func:`kernel_points`), each segment's squared distance and the
overflow-safe distance. Here those distances become costs: :func:`_cost_row` computes
one row of point costs (the square root of the summed squares unless ``squared``), the
one place the recursion (:mod:`._kernels`, :mod:`._pruned`) gets them from, and the
costs of given paths and of the diagonal alignment.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numba import njit, prange

from .._numba_cache import drop_stale_caches
from ..manifolds import _point_kernels
from ..manifolds._point_kernels import (
    FLAT,
    add_squared_distances,
    kernel_points,
    robust_distance,
    segment_codes,
)

# this package's kernels inline the manifolds' point geometry and one another (the search
# inlines the pruned recursion): compiled afresh after an edit to any of them (numba
# itself watches only each kernel's own file)
drop_stale_caches(
    Path(__file__).parent,
    [*_point_kernels.compiled_sources(), *sorted(Path(__file__).parent.glob("*.py"))],
)

__all__ = [
    "FLAT",
    "kernel_point_form",
    "kernel_points",
    "kernel_series",
    "robust_distance",
    "segment_codes",
]


def kernel_point_form(manifold, points: np.ndarray) -> tuple[np.ndarray | None, np.ndarray | None]:
    """Points ``(..., *point_shape)`` of ``manifold`` in the kernels' form ``(..., q)``,
    C-contiguous, and the manifold's segment codes; ``(None, None)`` where it has no
    kernel form."""
    segments = segment_codes(manifold)
    if segments is None:
        return None, None
    lead = points.shape[: points.ndim - len(manifold.point_shape)]
    flat = np.asarray(points, dtype=np.float64).reshape(*lead, -1)
    return np.ascontiguousarray(kernel_points(manifold, flat)), segments


def kernel_series(collection) -> np.ndarray:
    """A :class:`~sk_rtw.utils.SeriesCollection`'s padded series ``(n, T, p)`` in the
    kernels' form, C-contiguous."""
    flat = collection.data.reshape(collection.n_series, collection.max_length, -1)
    return np.ascontiguousarray(kernel_points(collection.manifold, flat))


#: Sums of squares outside [TINY, HUGE] lost precision to underflow or overflow.
_TINY, _HUGE = 1e-290, 1e290


@njit(cache=True, nogil=True, inline="always")
def _roots(row, n):
    """Each of the ``n`` first point costs of ``row`` replaced by its square root: a
    geodesic distance ``d`` becomes the cost ``d ** 0.5`` (the point-cost exponent 1/2
    of Proximity Forest 2.0)."""
    for j in range(n):
        row[j] = math.sqrt(row[j])


@njit(cache=True, nogil=True, inline="always")
def is_univariate(segments):
    """Whether the point is one Euclidean coordinate (its costs are ``|a - b|``)."""
    return segments.shape[0] == 1 and segments[0, 2] == FLAT and segments[0, 1] == 1


@njit(cache=True, nogil=True, inline="always")
def univariate_cost(gap, squared, root):
    """The point cost of a univariate gap ``|a - b|`` (or a bound on one): squared, its
    square root with ``root``, or itself; bit for bit :func:`_cost_row`'s then
    :func:`_roots`'."""
    if root:
        gap = math.sqrt(gap)
    return gap * gap if squared else gap


@njit(cache=True, nogil=True, inline="always")
def _cost_row(x, y, i, ny, segments, squared, row):
    """Row ``i`` of the cost matrix: point costs between ``x[i]`` and ``y[:ny]``."""
    xi = x[i]
    n_segments = segments.shape[0]
    if is_univariate(segments):
        a = xi[0]  # |a - b| exactly, at any magnitude
        for j in range(ny):
            diff = abs(a - y[j, 0])
            row[j] = diff * diff if squared else diff
        return
    for j in range(ny):
        row[j] = 0.0
    for s in range(n_segments):
        add_squared_distances(xi, y, ny, segments[s, 0], segments[s, 1], segments[s, 2], row)
    if not squared:
        for j in range(ny):
            sq = row[j]
            if sq < _TINY or sq > _HUGE:  # recompute without under- or overflow
                row[j] = robust_distance(xi, y[j], segments)
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


@njit(cache=True, nogil=True, parallel=True)
def segment_cost_stack(x, Y, nx, nys, segments, squared):
    """Cost matrices between ``x`` and each series of ``Y``, shape (len(Y), Tx, Ty)."""
    out = np.zeros((Y.shape[0], x.shape[0], Y.shape[1]))
    for k in prange(Y.shape[0]):
        segment_cost_matrix(x, Y[k], nx, nys[k], segments, squared, out[k])
    return out



@njit(cache=True, nogil=True)
def diagonal_cost(x, y, segments, squared, root=False):
    """The cost of the direct, diagonal alignment of flattened series ``x`` and ``y``.

    Equal lengths pair sample ``t`` with sample ``t``; unequal lengths step along the
    longer series and pair its sample ``t`` with sample ``floor(t n / m)`` of the shorter
    (``n`` samples, ``m`` the longer length): a warping path of ``m`` steps, ``m - n`` of
    them off the diagonal, whose cost bounds the DTW distance from above (the costs
    summed in the recursion's order: along the diagonal of equal lengths, its value bit
    for bit). Amerced DTW scales its penalty by this cost (Herrmann and Webb, 2023).
    ``root``: point costs are the square roots of the distances (``squared=False``).
    """
    nx, ny = x.shape[0], y.shape[0]
    steps = max(nx, ny)
    total = 0.0
    if is_univariate(segments):
        if nx == ny:  # sample t with sample t (no division per sample: a third of the time)
            for t in range(steps):
                total = univariate_cost(abs(x[t, 0] - y[t, 0]), squared, root) + total
            return total
        short, long_ = (x, y) if nx < ny else (y, x)
        n, k, carried = short.shape[0], 0, 0  # k = floor(t n / steps), carried = t n - k steps
        for t in range(steps):
            # |a - b| and |b - a| are the same number: the order of the pair does not matter
            total = univariate_cost(abs(short[k, 0] - long_[t, 0]), squared, root) + total
            carried += n
            while carried >= steps:
                carried -= steps
                k += 1
        return total
    cost = np.empty(1)
    for t in range(steps):
        j = t * ny // steps
        _cost_row(x, y[j : j + 1], t * nx // steps, 1, segments, squared, cost)
        if root:
            _roots(cost, 1)
        total = cost[0] + total
    return total


@njit(cache=True, nogil=True)
def diagonal_costs(X, lengths, first, second, segments, squared, root):
    """:func:`diagonal_cost` of series ``first[k]`` and ``second[k]`` of ``X`` (``(n, L,
    p)``, kernel form), for every ``k``."""
    out = np.empty(first.shape[0])
    for k in range(first.shape[0]):
        a, b = first[k], second[k]
        out[k] = diagonal_cost(X[a, : lengths[a]], X[b, : lengths[b]], segments, squared, root)
    return out
