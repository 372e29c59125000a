"""MMDDTW: dynamic time warping of N series jointly on an N-dimensional grid."""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from typing import Any

import numpy as np

from .._resources import available_memory
from ..dtw import check_window, point_cost_matrix
from ..manifolds import SPD, Euclidean, Manifold
from ..utils import check_series_collection
from . import _nd_kernels
from ._result import MultipleAlignment, make_result

METRICS = ("geodesic", "cholesky")

PairCost = Callable[[int, int], np.ndarray]


def grid_bytes(lengths) -> int:
    """Bytes of the float64 accumulated-cost grid of :func:`mmddtw_align`.

    Parameters
    ----------
    lengths : sequence of int
        Lengths ``T_n`` of the N series.

    Returns
    -------
    n_bytes : int
        ``8 * prod(T_n)``: the grid has shape ``(T_1, ..., T_N)``.
    """
    return 8 * math.prod(int(t) for t in lengths)


def _check_memory(lengths, max_memory: int | None) -> None:
    if max_memory is not None and (
        isinstance(max_memory, bool)
        or not isinstance(max_memory, (int, float, np.integer, np.floating))
        or not max_memory > 0
    ):
        raise ValueError(f"max_memory must be a positive number of bytes, got {max_memory!r}")
    limit = available_memory() if max_memory is None else int(max_memory)
    need = grid_bytes(lengths)
    if need > limit:
        shape = " x ".join(str(int(t)) for t in lengths)
        raise MemoryError(
            f"joint DTW of {len(lengths)} series needs a {shape} grid of float64 "
            f"costs: {need / 2**30:.3g} GiB, more than the {limit / 2**30:.3g} GiB "
            "allowed (max_memory; default: the memory available now). The grid grows as "
            "T^N: use fewer or shorter series (e.g. subsample), pdtw_average or "
            "sk_rtw.align."
        )


def nd_dtw(
    series: list[np.ndarray],
    pair_cost: PairCost,
    window: float | None = None,
    max_memory: int | None = None,
) -> tuple[np.ndarray, float]:
    """Optimal joint path ``(L, N)`` of N series and its accumulated cost.

    ``pair_cost(a, b)`` returns the ``(T_a, T_b)`` point-cost matrix of series a and b;
    a grid cell costs the sum of its pairwise entries over all pairs ``a < b``.
    """
    lengths = np.array([len(s) for s in series], dtype=np.int64)
    _check_memory(lengths, max_memory)
    w = check_window(window)
    pairs = np.array(list(itertools.combinations(range(len(series)), 2)), dtype=np.int64)
    t_max = int(lengths.max())
    costs = np.zeros((len(pairs), t_max, t_max))
    for p, (a, b) in enumerate(pairs):
        costs[p, : lengths[a], : lengths[b]] = pair_cost(int(a), int(b))
    D = np.empty(int(np.prod(lengths)))
    _nd_kernels.accumulate(costs, pairs, lengths, w, D)
    if not np.isfinite(D[-1]):
        raise ValueError("the window is too narrow to connect the first and last samples")
    return _nd_kernels.backtrack(D, lengths), float(D[-1])


def mmddtw_align(
    X: Any,
    manifold: str | Manifold = "euclidean",
    *,
    metric: str = "geodesic",
    window: float | None = None,
    squared: bool = False,
    max_memory: int | None = None,
) -> MultipleAlignment:
    """Align N series jointly by DTW on their N-dimensional grid (MMDDTW).

    The globally optimal joint warping path is found by dynamic programming over every
    combination of sample indices, so the cost is ``O(prod T_n * 2^N)`` time and
    ``prod T_n`` float64 of memory: feasible for N = 4, T = 100 (0.8 GB) or N = 3,
    T = 200 (64 MB), not for many series.

    The cost of matching samples ``(i_1, ..., i_N)`` is the sum of the geodesic distances
    between all pairs of them, ``sum_{a<b} dist(x_a[i_a], x_b[i_b])``. This replaces the
    distance to the Fréchet mean of the matched points (a Gauss–Newton iteration per grid
    cell) by closed-form terms; with ``squared=True`` on Euclidean data the two agree
    exactly, since ``sum_{a<b} |x_a - x_b|^2 = N sum_a |x_a - mean|^2``. With N = 2 this
    is plain DTW.

    Parameters
    ----------
    X : array-like of shape (N, T, *point_shape) or list of (T_n, *point_shape) series
        Input series (at least two).
    manifold : str or Manifold, default="euclidean"
        Space of the samples.
    metric : {"geodesic", "cholesky"}, default="geodesic"
        Point distance. ``"cholesky"`` (SPD only) is ``||chol(A) - chol(B)||_F``, the
        distance between lower Cholesky factors (MMDDTW_C of the paper); the mean is then
        ``L L^T`` for the average ``L`` of the matched factors.
    window : float in [0, 1], optional
        Keep only cells with ``|i_a/(T_a-1) - i_b/(T_b-1)| <= window`` for all pairs.
    squared : bool, default=False
        Use squared distances as pairwise costs.
    max_memory : int, optional
        Largest grid allowed, in bytes. Default: the physical memory available now.

    Returns
    -------
    MultipleAlignment
        ``indices`` is the joint path (one column per step, ``L`` steps); ``mean`` is the
        Fréchet mean of the matched samples at every step; ``cost`` is the accumulated
        cost of the path.

    Raises
    ------
    MemoryError
        If the grid needs more than ``max_memory`` bytes; the message states the size.
    """
    if metric not in METRICS:
        raise ValueError(f"metric must be one of {METRICS}, got {metric!r}")
    collection = check_series_collection(X, manifold, name="X", min_length=1, min_series=2)
    M = collection.manifold
    series = [collection.series(i) for i in range(collection.n_series)]
    if metric == "cholesky":
        if not isinstance(M, SPD):
            raise ValueError(f"metric='cholesky' needs SPD matrices, got {M!r}")
        factors = [np.linalg.cholesky(s) for s in series]
        space: Manifold = Euclidean(M.dim * M.dim)
        points = [f.reshape(len(f), -1) for f in factors]
    else:
        points, space = series, M

    def pair_cost(a: int, b: int) -> np.ndarray:
        return point_cost_matrix(points[a], points[b], space, squared)

    path, cost = nd_dtw(series, pair_cost, window, max_memory)
    indices = path.T
    if metric == "cholesky":
        L = np.mean([f[i] for f, i in zip(factors, indices, strict=True)], axis=0)
        mean = L @ np.swapaxes(L, -1, -2)
    else:
        mean = M.mean(np.stack([s[i] for s, i in zip(series, indices, strict=True)]))
    return make_result(series, indices, mean, cost, M)
