"""Dynamic time warping between series of manifold-valued points.

The point cost is the manifold's geodesic distance (or its square with ``squared=True``,
which on Euclidean data is aeon's and tslearn's convention). The returned distance is the
accumulated cost along the optimal warping path -- the paper's ``D_dtw`` -- with no
normalisation unless ``normalize="path"`` asks for the mean cost per path step.
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

from .._numba import numba_threads
from .._threads import thread_map
from ..manifolds import Manifold
from ..utils import SeriesCollection, check_series, check_series_collection
from ..utils._common_params import DTW_WINDOW, WARP_PENALTY
from . import _kernels, _lanes, _point_costs, _pruned
from ._band import EXACT_CELLS, guide_bound
from ._costs import check_costs, kernel_form, point_cost_matrix
from ._paths import path_indices

_NORMALIZE = (None, "path")


def check_window(window: float | None, name: str = "window") -> float:
    """Check a Sakoe–Chiba radius (the package's one ``dtw_window`` declaration) and
    return it in the kernels' convention.

    Parameters
    ----------
    window : float in [0, 1] or None
        Radius as a fraction of the shorter series (as in aeon); None: no band.
    name : str, default="window"
        The argument's name in error messages.

    Returns
    -------
    radius : float
        ``window`` as a float, or -1.0 for no band.
    """
    value = DTW_WINDOW.check(window, name)
    return -1.0 if value is None else float(value)


def check_warp_penalty(warp_penalty: float, normalize: str | None = None) -> float:
    """Check amerced DTW's penalty (a finite float, at least 0) and return it as a float.

    Parameters
    ----------
    warp_penalty : float
        The penalty.
    normalize : {None, "path"}, optional
        The distance's normalisation: a penalty is refused with ``"path"`` (the path's
        length is DTW's, not amerced DTW's).

    Returns
    -------
    penalty : float
    """
    value = WARP_PENALTY.check(warp_penalty)
    if value > 0 and normalize == "path":
        raise ValueError(
            'normalize="path" divides by the steps of the optimal DTW path; it is not '
            "defined for amerced DTW: use warp_penalty=0 or normalize=None"
        )
    return float(value)


def _check_normalize(normalize: str | None) -> None:
    if normalize not in _NORMALIZE:
        raise ValueError(f"normalize must be one of {_NORMALIZE}, got {normalize!r}")


def _guide_bounds(
    cx: SeriesCollection, cy: SeriesCollection, window: float, squared: bool, symmetric: bool
) -> np.ndarray:
    """:func:`~._band.guide_bound` of every pair (``inf`` where none: short
    pairs, a band; the upper triangle if ``symmetric``)."""
    bounds = np.full((cx.n_series, cy.n_series), np.inf)
    if cx.max_length * cy.max_length <= EXACT_CELLS or 0.0 <= window < 1.0:
        return bounds  # no pair gets a guide: skip the loop
    pairs = [(i, j) for i in range(cx.n_series)
             for j in range(i + 1 if symmetric else 0, cy.n_series)]  # fmt: skip

    def bound(pair: tuple[int, int]) -> float:
        return guide_bound(cx.series(pair[0]), cy.series(pair[1]), cx.manifold, window, squared)

    # on the threads the caller's n_jobs gave the kernels (numba_threads)
    values = thread_map(bound, pairs, numba.get_num_threads())
    for (i, j), value in zip(pairs, values, strict=True):
        bounds[i, j] = value
    return bounds


def _pair(x, y, manifold) -> tuple[np.ndarray, np.ndarray, Manifold]:
    x, checked = check_series(x, manifold, name="x", min_length=1)
    y, _ = check_series(y, checked, name="y", min_length=1)
    return x, y, checked


def dtw_cost_matrix(
    x: Any,
    y: Any,
    manifold: str | Manifold = "euclidean",
    window: float | None = None,
    squared: bool = False,
) -> np.ndarray:
    """Accumulated DTW cost matrix between two series.

    Parameters
    ----------
    x : array-like, shape (T_x,) or (T_x, *point_shape)
    y : array-like, shape (T_y,) or (T_y, *point_shape)
    manifold : str or Manifold, default="euclidean"
        Space of the points; a name takes its dimension from the data.
    window : float in [0, 1], optional
        Sakoe–Chiba band radius as a fraction of the shorter series (aeon's convention).
    squared : bool, default=False
        Use the squared geodesic distance as point cost.

    Returns
    -------
    D : ndarray of shape (T_x, T_y)
        ``D[i, j]`` is the cost of the best path from ``(0, 0)`` to ``(i, j)``;
        ``inf`` outside the band.
    """
    w = check_window(window)
    x, y, manifold = _pair(x, y, manifold)
    return _kernels.accumulated_cost(point_cost_matrix(x, y, manifold, squared), w)


def dtw_distance(
    x: Any,
    y: Any,
    manifold: str | Manifold = "euclidean",
    window: float | None = None,
    squared: bool = False,
    normalize: str | None = None,
    warp_penalty: float = 0.0,
) -> float:
    """DTW distance between two series on a manifold.

    Parameters
    ----------
    x : array-like, shape (T_x,) or (T_x, *point_shape)
    y : array-like, shape (T_y,) or (T_y, *point_shape)
    manifold : str or Manifold, default="euclidean"
        Space of the points; a name takes its dimension from the data.
    window : float in [0, 1], optional
        Sakoe–Chiba band radius as a fraction of the shorter series.
    squared : bool, default=False
        Use the squared geodesic distance as point cost (aeon's Euclidean convention).
    normalize : {None, "path"}, default=None
        ``"path"`` divides the accumulated cost by the number of steps of the optimal path.
    warp_penalty : float, default=0.0
        Amerced DTW (Herrmann and Webb, 2023): this penalty is added for every step of the
        path off the diagonal (a repeated sample of either series). 0 is DTW; a large
        penalty approaches the direct alignment of equal-length series. In the units of
        the point cost (squared with ``squared=True``).

    Returns
    -------
    float
        Accumulated point cost along the optimal warping path (plus its penalties).

    Examples
    --------
    >>> import numpy as np
    >>> dtw_distance(np.array([0.0, 1.0, 2.0]), np.array([0.0, 0.0, 1.0, 2.0]))
    0.0
    """
    _check_normalize(normalize)
    w = check_window(window)
    penalty = check_warp_penalty(warp_penalty, normalize)
    x, y, manifold = _pair(x, y, manifold)
    if normalize == "path":
        path, cost = path_indices(x, y, manifold, w, squared)
        return float(cost / len(path))
    segments = _point_costs.segment_codes(manifold)
    if segments is None:
        return float(_kernels.final_cost(point_cost_matrix(x, y, manifold, squared),
                                         len(x), len(y), w, penalty))  # fmt: skip
    # two rows of memory; long pairs without a band skip the cells that cannot beat their
    # coarse-to-fine path (the same value; the path's cost bounds DTW, not amerced DTW)
    bound = guide_bound(x, y, manifold, w, squared) if penalty == 0 else np.inf
    fx, fy = kernel_form(x, manifold), kernel_form(y, manifold)
    value = _pruned.pruned_distance(fx, fy, segments, squared, w, bound, penalty)
    if not value <= bound:
        value = _pruned.pruned_distance(fx, fy, segments, squared, w, np.inf, penalty)
    return float(value)


def dtw_path(
    x: Any,
    y: Any,
    manifold: str | Manifold = "euclidean",
    window: float | None = None,
    squared: bool = False,
) -> tuple[list[tuple[int, int]], float]:
    """Optimal DTW alignment path and its accumulated cost.

    Parameters
    ----------
    x : array-like, shape (T_x,) or (T_x, *point_shape)
    y : array-like, shape (T_y,) or (T_y, *point_shape)
    manifold, window, squared
        As in :func:`dtw_distance`.

    Returns
    -------
    path : list of (int, int)
        Index pairs ``(i, j)`` from ``(0, 0)`` to ``(T_x - 1, T_y - 1)``.
    distance : float
        As returned by :func:`dtw_distance`.
    """
    w = check_window(window)
    x, y, manifold = _pair(x, y, manifold)
    path, cost = path_indices(x, y, manifold, w, squared)
    return [(int(i), int(j)) for i, j in path], cost


def dtw_pairwise_distance(
    X: Any,
    Y: Any = None,
    manifold: str | Manifold = "euclidean",
    window: float | None = None,
    squared: bool = False,
    normalize: str | None = None,
    n_jobs: int | None = None,
    warp_penalty: float = 0.0,
) -> np.ndarray:
    """DTW distances between all series of ``X`` and all series of ``Y`` (or ``X``).

    Parameters
    ----------
    X : array-like or list of array-like
        ``(n, T)``, ``(n, T, *point_shape)`` or a list of unequal-length series.
    Y : same forms as ``X``, optional
        Defaults to ``X`` (then only the upper triangle is computed).
    manifold, window, squared, normalize, warp_penalty
        As in :func:`dtw_distance`.
    n_jobs : int, optional
        Threads for the pairs (numba); ``-1`` uses all cores. Default: 1.

    Returns
    -------
    distances : ndarray of shape (n_X, n_Y)

    Notes
    -----
    On Euclidean points (and products of Euclidean spaces) the series of ``Y`` that share
    a length with at least two others run 32 at a time against each series of ``X``, one
    per vector lane: the same values as one pair at a time, bit for bit, several times
    faster (``docs/benchmarks/dtw_speed.md``).
    """
    _check_normalize(normalize)
    w = check_window(window)
    penalty = check_warp_penalty(warp_penalty, normalize)
    cx = (
        X
        if isinstance(X, SeriesCollection)
        else check_series_collection(X, manifold, name="X", min_length=1)
    )
    symmetric = Y is None
    if symmetric:
        cy = cx
    else:
        cy = (
            Y
            if isinstance(Y, SeriesCollection)
            else check_series_collection(Y, cx.manifold, name="Y", min_length=1)
        )
    with numba_threads(n_jobs):
        return _pairwise(cx, cy, w, squared, symmetric, normalize == "path", penalty)


def _pairwise(
    cx: SeriesCollection, cy: SeriesCollection, window, squared, symmetric, per_step,
    penalty=0.0,
) -> np.ndarray:  # fmt: skip
    """The distances of :func:`dtw_pairwise_distance` (long pairs without a band skip the
    cells that cannot beat their coarse-to-fine path: :func:`_guide_bounds`; amerced DTW
    one pair at a time, no guide)."""
    manifold = cx.manifold
    segments = _point_costs.segment_codes(manifold)
    if segments is not None:
        flat_x = _point_costs.kernel_series(cx)
        flat_y = _point_costs.kernel_series(cy)
        if not per_step:
            if penalty == 0:
                bounds = _guide_bounds(cx, cy, window, squared, symmetric)
            else:  # a guide path's cost bounds DTW, not amerced DTW
                bounds = np.full((cx.n_series, cy.n_series), np.inf)
            n_pairs = cx.n_series * (cx.n_series - 1) // 2 if symmetric else bounds.size
            fits = _lanes.lanes_apply(segments, n_pairs, cy.max_length)
            if fits and np.isinf(bounds).all():
                return _lanes.lane_distances(flat_x, cx.lengths, flat_y, cy.lengths, segments,
                                             squared, window, symmetric, penalty)  # fmt: skip
            return _pruned.pairwise_segments(
                flat_x, cx.lengths, flat_y, cy.lengths, segments, squared, window, symmetric,
                bounds, penalty,
            )  # fmt: skip
    # Cost matrices for a block of pairs at a time (numba for the known point distances,
    # the vectorised geometry otherwise), then the parallel recursion over the block.
    n, m = cx.n_series, cy.n_series
    values = np.zeros((n, m))
    block = max(1, int(2e7 // max(1, cx.max_length * cy.max_length)))
    for i in range(n):
        js = np.arange(i + 1, m) if symmetric else np.arange(m)
        for start in range(0, len(js), block):
            chunk = js[start : start + block]
            if segments is not None:
                cost = _point_costs.segment_cost_stack(
                    flat_x[i],
                    flat_y[chunk],
                    cx.lengths[i],
                    cy.lengths[chunk],
                    segments,
                    squared,
                )
            else:
                cost = np.asarray(manifold.pairwise_dist(cx.data[i][None], cy.data[chunk]))
                finite = bool(np.isfinite(cost).all())  # then no pair needs a look
                for k, j in enumerate([] if finite else chunk):  # padding is no cost
                    check_costs(
                        cost[k, : cx.lengths[i], : cy.lengths[j]], manifold, f"X[{i}]",
                        f"Y[{j}]", (cx.series(i), cy.series(int(j))),
                    )  # fmt: skip
                if squared:
                    cost = cost * cost
            values[i, chunk] = _kernels.final_cost_batch(
                np.ascontiguousarray(cost),
                np.full(len(chunk), cx.lengths[i]),
                cy.lengths[chunk],
                window,
                per_step,
                penalty,
            )
    if symmetric:
        values = np.triu(values, 1) + np.triu(values, 1).T
    return values
