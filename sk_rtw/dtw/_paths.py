"""DTW paths as index arrays, and the DTW medoid of a collection.

Helpers shared by the DTW-family baselines and the engine's DTW start: they take series
that are already validated (``(T, *point_shape)`` arrays on one manifold).
"""

from __future__ import annotations

import numpy as np

from ..manifolds import Manifold
from ..utils import SeriesCollection
from . import _kernels
from ._band import _flat, guide_bound
from ._dtw import dtw_pairwise_distance, point_cost_matrix


def optimal_path(cost: np.ndarray, window: float = -1.0) -> tuple[np.ndarray, float]:
    """Optimal DTW path through a point-cost matrix, and its accumulated cost.

    Parameters
    ----------
    cost : ndarray of shape (T_x, T_y)
        Point costs.
    window : float, default=-1
        Sakoe–Chiba radius as a fraction of the shorter series; negative: no band.

    Returns
    -------
    path : ndarray of shape (P, 2), int
        Index pairs ``(i, j)`` from ``(0, 0)`` to ``(T_x - 1, T_y - 1)``.
    cost : float
    """
    D = _kernels.accumulated_cost(cost, window)
    if not np.isfinite(D[-1, -1]):
        if window < 0.0 or not np.isfinite(cost).all():
            raise ValueError(f"the DTW cost is {D[-1, -1]}: the point costs are not finite")
        raise ValueError("the Sakoe–Chiba window is too narrow to connect the series ends")
    return np.asarray(_kernels.backtrack(D), dtype=np.int64).reshape(-1, 2), float(D[-1, -1])


def path_indices(
    x: np.ndarray,
    y: np.ndarray,
    manifold: Manifold,
    window: float = -1.0,
    squared: bool = False,
    guide: np.ndarray | None = None,
) -> tuple[np.ndarray, float]:
    """Optimal DTW path ``(P, 2)`` between two validated series, and its cost.

    Parameters
    ----------
    x : ndarray of shape (T_x, *point_shape)
    y : ndarray of shape (T_y, *point_shape)
    manifold : Manifold
    window : float, default=-1
        Sakoe–Chiba radius (fraction of the shorter series); negative: no band.
    squared : bool, default=False
        Squared geodesic point costs.
    guide : ndarray of shape (P', 2), int, optional
        Any warping path between ``x`` and ``y`` inside the band, close to the optimal
        one (an earlier iteration's path): its cost bounds the search, and the cells that
        cannot beat it are skipped. The result does not depend on it (a poor guide only
        saves less). Default: for pairs of more than ``2**20`` cells without a band, the
        coarse-to-fine path (:func:`~sk_rtw.dtw.multiscale_path`); otherwise none.

    Returns
    -------
    path : ndarray of shape (P, 2), int
    cost : float
    """
    segments = _kernels.segment_codes(manifold)
    if segments is None:
        return optimal_path(point_cost_matrix(x, y, manifold, squared), window)
    # the point costs are computed inside the accumulation (the T_x x T_y cost matrix is
    # never stored) and only where a path could still beat the guide's cost
    fx = _kernels.kernel_points(manifold, _flat(x))
    fy = _kernels.kernel_points(manifold, _flat(y))
    bound = guide_bound(x, y, manifold, window, squared, guide)
    rows = _kernels.accumulated_segment_cost(fx, fy, segments, squared, window, bound)
    cost = _kernels.ragged_value(*rows, len(x) - 1, len(y) - 1)
    if not cost <= bound:  # the guide left the band, or a cost is not finite
        rows = _kernels.accumulated_segment_cost(fx, fy, segments, squared, window, np.inf)
        cost = _kernels.ragged_value(*rows, len(x) - 1, len(y) - 1)
    if not np.isfinite(cost):  # the full cost matrix says why
        return optimal_path(point_cost_matrix(x, y, manifold, squared), window)
    return _kernels.ragged_backtrack(*rows, len(y)), float(cost)


def medoid_index(
    collection: SeriesCollection,
    candidates: np.ndarray | None = None,
    window: float | None = None,
    squared: bool = True,
) -> int:
    """Index of the series with the smallest summed DTW cost to the others.

    Parameters
    ----------
    collection : SeriesCollection
    candidates : ndarray of int, optional
        Only these series take part (both as candidates and as the others); default all.
    window : float in [0, 1], optional
        Sakoe–Chiba band.
    squared : bool, default=True
        Squared geodesic point costs.

    Returns
    -------
    index : int
        Index into ``collection``.
    """
    index = np.arange(collection.n_series) if candidates is None else np.asarray(candidates)
    D = dtw_pairwise_distance(collection.subset(index), window=window, squared=squared)
    return int(index[np.argmin(D.sum(1))])
