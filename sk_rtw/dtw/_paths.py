"""DTW paths between validated series (``(T, *point_shape)`` arrays on one manifold),
as index arrays or as the mean matched positions the alignment engine's start reads.
"""

from __future__ import annotations

import numpy as np

from ..manifolds import Manifold
from . import _point_costs, _pruned
from ._band import bounded_path, guide_bound
from ._costs import optimal_path, point_cost_matrix


def path_indices(
    x: np.ndarray,
    y: np.ndarray,
    manifold: Manifold,
    window: float | None = None,
    squared: bool = False,
    guide: np.ndarray | None = None,
) -> tuple[np.ndarray, float]:
    """Optimal DTW path ``(P, 2)`` between two validated series, and its cost.

    Parameters
    ----------
    x : ndarray of shape (T_x, *point_shape)
    y : ndarray of shape (T_y, *point_shape)
    manifold : Manifold
    window : float or None, default=None
        Sakoe–Chiba radius (fraction of the shorter series); None (or a negative number,
        what :func:`check_window` returns for None): no band.
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
    window = -1.0 if window is None else float(window)  # the kernels' "no band"
    if _point_costs.segment_codes(manifold) is None:
        return optimal_path(point_cost_matrix(x, y, manifold, squared), window)
    bound = guide_bound(x, y, manifold, window, squared, guide)
    return bounded_path(x, y, manifold, window, squared, bound)


def has_compiled_costs(manifold: Manifold) -> bool:
    """Whether the compiled kernels compute ``manifold``'s point costs themselves (then
    :func:`mean_matched_positions` applies)."""
    return _point_costs.segment_codes(manifold) is not None


def mean_matched_positions(
    references: np.ndarray,
    reference_lengths: np.ndarray,
    series: np.ndarray,
    lengths: np.ndarray,
    codes: np.ndarray,
    manifold: Manifold,
    window: float = -1.0,
    squared: bool = True,
) -> np.ndarray:
    """For every series, the mean index of its samples matched with each sample of its
    reference on their optimal DTW path, in one compiled pass (no path stored).

    Parameters
    ----------
    references : ndarray of shape (G, L_max, *point_shape)
        The references, each padded by repeating its last sample.
    reference_lengths : ndarray of shape (G,), int
    series : ndarray of shape (N, T_max, *point_shape)
        The series, each padded by repeating its last sample.
    lengths : ndarray of shape (N,), int
    codes : ndarray of shape (N,), int
        The reference of each series.
    manifold : Manifold
        One with compiled point costs (:func:`has_compiled_costs`).
    window : float or None, default=None
        Sakoe–Chiba radius (fraction of the shorter series); None (or a negative number,
        what :func:`check_window` returns for None): no band.
    squared : bool, default=True
        Squared geodesic point costs.

    Returns
    -------
    positions : ndarray of shape (N, L_max)
        Row ``n`` holds ``reference_lengths[codes[n]]`` values (the rest is zero); the
        paths are those of :func:`path_indices` (ties broken alike).
    """
    segments = _point_costs.segment_codes(manifold)
    if segments is None:
        raise ValueError(f"{manifold!r} has no compiled point costs")

    def form(a: np.ndarray) -> np.ndarray:
        flat = a.reshape(a.shape[0], a.shape[1], -1)
        return np.ascontiguousarray(_point_costs.kernel_points(manifold, flat))

    return _pruned.matched_positions(
        form(references), np.asarray(reference_lengths), form(series), np.asarray(lengths),
        np.asarray(codes), segments, squared, window,
    )  # fmt: skip
