"""The floor every DTW routine stands on: point costs between two validated series and
the optimal path through a matrix of them.

Nothing here imports another module of the package but the kernels: the band, the
paths, the distances and the searches build on these.
"""

from __future__ import annotations

import numpy as np

from ..manifolds import Manifold
from . import _kernels, _point_costs


def flat_points(x: np.ndarray) -> np.ndarray:
    """A validated series ``(T, *point_shape)`` as ``(T, prod(point_shape))``."""
    return np.ascontiguousarray(x.reshape(x.shape[0], -1))


def kernel_form(x: np.ndarray, manifold: Manifold) -> np.ndarray:
    """A validated series in the kernels' form (:func:`~._point_costs.kernel_points`)."""
    return _point_costs.kernel_points(manifold, flat_points(x))


def point_cost_matrix(
    x: np.ndarray, y: np.ndarray, manifold: Manifold, squared: bool = False
) -> np.ndarray:
    """Cost matrix ``C[i, j] = dist(x[i], y[j])`` (or its square) of two validated series.

    Parameters
    ----------
    x : ndarray of shape (T_x, *point_shape)
    y : ndarray of shape (T_y, *point_shape)
    manifold : Manifold
    squared : bool, default=False

    Returns
    -------
    C : ndarray of shape (T_x, T_y)
    """
    segments = _point_costs.segment_codes(manifold)
    if segments is not None:
        out = np.empty((len(x), len(y)))
        _point_costs.segment_cost_matrix(kernel_form(x, manifold), kernel_form(y, manifold),
                                     len(x), len(y), segments, squared, out)  # fmt: skip
        return out
    cost = np.asarray(manifold.pairwise_dist(x, y))
    check_costs(cost, manifold, points=(x, y))
    return cost * cost if squared else cost


def check_costs(
    cost: np.ndarray, manifold: Manifold, x: str = "x", y: str = "y", points: tuple = ()
) -> None:
    """Refuse non-finite point costs (a manifold's ``dist`` that fails far from a point,
    or geodesics that float64 cannot follow): DTW would return NaN, or a path that is not
    optimal, without saying so.

    ``cost`` is ``(T_x, T_y)``; ``x`` and ``y`` name the two series in the message, whose
    samples ``points`` (the two series, optional; read only on failure) let the manifold
    say what their range is.
    """
    bad = ~np.isfinite(cost)
    if not bad.any():
        return
    i, j = (int(k) for k in np.argwhere(bad)[0])
    note = manifold.spread_note(np.concatenate(points)) if points else ""
    raise ValueError(
        f"{manifold!r} gives the distance {cost[i, j]} between {x} at time {i} and {y} at "
        f"time {j}, and {int(bad.sum())} non-finite point costs in all"
        + (f" ({note})" if note else "")
        + ": DTW needs finite distances between every pair of samples. Rescale the data, "
        "or check the manifold's log and dist far from a point with "
        "sk_rtw.check_manifold(manifold, points)"
    )


def optimal_path(cost: np.ndarray, window: float | None = None) -> tuple[np.ndarray, float]:
    """Optimal DTW path through a point-cost matrix, and its accumulated cost.

    Parameters
    ----------
    cost : ndarray of shape (T_x, T_y)
        Point costs.
    window : float or None, default=None
        Sakoe–Chiba radius as a fraction of the shorter series; None (or a negative
        number, what :func:`check_window` returns for None): no band.

    Returns
    -------
    path : ndarray of shape (P, 2), int
        Index pairs ``(i, j)`` from ``(0, 0)`` to ``(T_x - 1, T_y - 1)``.
    cost : float
    """
    window = -1.0 if window is None else float(window)
    D = _kernels.accumulated_cost(cost, window)
    if not np.isfinite(D[-1, -1]):
        if window < 0.0 or not np.isfinite(cost).all():
            raise ValueError(f"the DTW cost is {D[-1, -1]}: the point costs are not finite")
        raise ValueError("the Sakoe–Chiba window is too narrow to connect the series ends")
    return np.asarray(_kernels.backtrack(D), dtype=np.int64).reshape(-1, 2), float(D[-1, -1])
