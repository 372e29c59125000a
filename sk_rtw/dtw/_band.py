"""DTW paths of long series: coarse to fine, in a band around the coarser path.

An exact DTW path between series of ``T_x`` and ``T_y`` samples costs ``T_x T_y`` cells:
80 million for two robot demonstrations of 9,000 samples, and a dense accumulated-cost
matrix of that size. :func:`multiscale_path` (Salvador and Chan's FastDTW, with the
recursion of :mod:`sk_rtw.dtw._kernels`) halves both series by geodesic midpoints of
neighbouring samples until they are short, solves the coarsest pair exactly (skipping,
as the exact DTW does, the cells that cannot beat a still coarser path), and at each
finer level only fills the cells within ``radius`` samples of the coarser path projected
onto it: ``O((T_x + T_y) radius)`` cells per level. The path is optimal within the band;
in the rare case that the optimal path leaves the band it is a close approximation
(tests compare both with the exact path).

Band layout: row ``i`` holds the columns ``lo[i] <= j < hi[i]``; ``lo`` and ``hi`` are
non-decreasing, so the band is a staircase that connects ``(0, 0)`` with
``(T_x - 1, T_y - 1)``. The recursion, its storage by rows and the tie rule on the way
back are the kernels' (:func:`~._pruned.band_segment_cost`,
:func:`~._pruned.ragged_backtrack`), as for every other DTW path of the package.
"""

from __future__ import annotations

import numpy as np
import torch
from numba import njit

from ..manifolds import Manifold
from ..utils import SeriesCollection
from . import _point_costs, _pruned
from ._costs import kernel_form, optimal_path, point_cost_matrix

#: Pairs with at most this many cells get the exact path.
EXACT_CELLS = 2**20
#: Half-width of the band around the projected coarser path, in samples of each level.
RADIUS = 16

#: Exact pairs of more cells are solved with the cells that cannot beat a guide path
#: skipped (:func:`_guided_path`), the guide coarse to fine down to
#: :data:`GUIDE_EXACT_CELLS`: the coarsest level of every long pair was a full matrix of
#: up to :data:`EXACT_CELLS` cells (1.4 of 6.4 s of RTW's start on 8 quaternion series of
#: 16,000 samples).
GUIDED_CELLS = 2**16
GUIDE_EXACT_CELLS = 2**14

#: Relative margin on a guide path's cost: the recursion adds the same point costs in
#: the same order (no margin needed in exact arithmetic); this one covers a last-bit
#: difference between two compiled copies of the point cost.
GUIDE_SLACK = 1e-9


@njit(cache=True, nogil=True)
def band_from_path(path, nx, ny, radius):
    """Rows ``[lo, hi)`` covering the cells of a path of the half-length problem, dilated."""
    lo = np.full(nx, ny, dtype=np.int64)
    hi = np.zeros(nx, dtype=np.int64)
    for k in range(path.shape[0]):
        i0 = max(0, 2 * path[k, 0] - radius)
        i1 = min(nx, 2 * path[k, 0] + 2 + radius)
        j0 = max(0, 2 * path[k, 1] - radius)
        j1 = min(ny, 2 * path[k, 1] + 2 + radius)
        for i in range(i0, i1):
            if j0 < lo[i]:
                lo[i] = j0
            if j1 > hi[i]:
                hi[i] = j1
    lo[0] = 0
    hi[nx - 1] = ny
    for i in range(nx - 2, -1, -1):  # a staircase: lo and hi non-decreasing
        if lo[i + 1] < lo[i]:
            lo[i] = lo[i + 1]
    for i in range(1, nx):
        if hi[i - 1] > hi[i]:
            hi[i] = hi[i - 1]
    return lo, hi


def halve(series: np.ndarray, manifold: Manifold) -> np.ndarray:
    """Geodesic midpoints of samples ``2k`` and ``2k + 1`` (an odd last sample is kept)."""
    n = len(series)
    pairs = n // 2
    a = torch.as_tensor(series[0 : 2 * pairs : 2])
    b = torch.as_tensor(series[1 : 2 * pairs : 2])
    mid = manifold._exp(a, 0.5 * manifold._log(a, b)).numpy()
    if n % 2:
        mid = np.concatenate([mid, series[-1:]])
    return mid


def coarse(series: np.ndarray, manifold: Manifold, length: int) -> np.ndarray:
    """``series`` halved by geodesic midpoints until it has at most ``length`` samples."""
    while len(series) > length:
        series = halve(series, manifold)
    return series


def coarse_collection(series: list[np.ndarray], manifold: Manifold, length: int):
    """Series halved by geodesic midpoints of neighbouring samples until each has at most
    ``length`` samples, as one collection.

    Parameters
    ----------
    series : list of ndarray of shape (T_i, *point_shape)
        Validated series on ``manifold``.
    manifold : Manifold
    length : int
        The most samples a coarse series keeps.

    Returns
    -------
    SeriesCollection
        The coarse series, the shorter ones padded with their last sample (their lengths
        kept).
    """
    small = [coarse(s, manifold, length) for s in series]
    lengths = np.array([len(s) for s in small])
    data = np.stack(
        [np.concatenate([s, np.repeat(s[-1:], lengths.max() - len(s), 0)]) for s in small]
    )
    return SeriesCollection(data=data, lengths=lengths, manifold=manifold)


def _band_rows(x, y, lo, hi, manifold, squared):
    """The accumulated cost of the band's cells, stored by rows (the kernels'
    ``(values, offsets, starts)``)."""
    segments = _point_costs.segment_codes(manifold)
    if segments is not None:
        return _pruned.band_segment_cost(kernel_form(x, manifold), kernel_form(y, manifold),
                                          segments, squared, lo, hi)  # fmt: skip
    rows = np.repeat(np.arange(len(x)), hi - lo)
    cols = lo[rows] + np.arange(rows.size) - np.repeat(np.cumsum(hi - lo) - (hi - lo), hi - lo)
    with torch.no_grad():
        values = manifold._dist(torch.as_tensor(x[rows]), torch.as_tensor(y[cols])).numpy()
    return _pruned.band_accumulated_cost(values * values if squared else values, lo, hi)


def solved_exactly(nx: int, ny: int, radius: int = RADIUS, exact_cells: int = EXACT_CELLS):
    """Whether :func:`multiscale_path` solves a pair of these lengths exactly (no band).

    Parameters
    ----------
    nx, ny : int
        The two series' lengths.
    radius, exact_cells : int
        As in :func:`multiscale_path`.

    Returns
    -------
    bool
    """
    return nx * ny <= exact_cells or min(nx, ny) <= 2 * radius + 2


def multiscale_path(
    x: np.ndarray,
    y: np.ndarray,
    manifold: Manifold,
    squared: bool = False,
    radius: int = RADIUS,
    exact_cells: int = EXACT_CELLS,
) -> tuple[np.ndarray, float]:
    """DTW path between two validated series, coarse to fine in a band (module docstring).

    Parameters
    ----------
    x : ndarray of shape (T_x, *point_shape)
    y : ndarray of shape (T_y, *point_shape)
    manifold : Manifold
    squared : bool, default=False
        Squared geodesic point costs.
    radius : int, default=16
        Band half-width around the projected coarser path.
    exact_cells : int, default=2**20
        Problems of at most this many cells (and the coarsest level) are solved exactly.

    Returns
    -------
    path : ndarray of shape (P, 2), int
        ``(i, j)`` pairs from ``(0, 0)`` to ``(T_x - 1, T_y - 1)``.
    cost : float
        Accumulated cost along the path.
    """
    if solved_exactly(len(x), len(y), radius, exact_cells):
        if (
            len(x) * len(y) > GUIDED_CELLS
            and min(len(x), len(y)) > 2 * radius + 2
            and _point_costs.segment_codes(manifold) is not None  # else no pruning
        ):
            return _guided_path(x, y, manifold, squared, radius)
        return optimal_path(point_cost_matrix(x, y, manifold, squared))
    coarse, _ = multiscale_path(halve(x, manifold), halve(y, manifold), manifold, squared,
                                radius, exact_cells)  # fmt: skip
    lo, hi = band_from_path(coarse, len(x), len(y), radius)
    rows = _band_rows(x, y, lo, hi, manifold, squared)
    cost = _pruned.ragged_value(*rows, len(x) - 1, len(y) - 1)
    return _pruned.ragged_backtrack(*rows, len(y)), float(cost)


def _guided_path(x, y, manifold, squared, radius):
    """The exact path of a pair :func:`multiscale_path` solves exactly, the cells that
    cannot beat a coarse-to-fine path (exact below :data:`GUIDE_EXACT_CELLS`) skipped:
    the same path and cost, bit for bit, as the full matrix's."""
    guide, _ = multiscale_path(x, y, manifold, squared, radius, GUIDE_EXACT_CELLS)
    bound = guide_bound(x, y, manifold, -1.0, squared, guide)
    return bounded_path(x, y, manifold, -1.0, squared, bound)


def bounded_path(
    x: np.ndarray, y: np.ndarray, manifold: Manifold, window: float, squared: bool, bound: float
) -> tuple[np.ndarray, float]:
    """Optimal DTW path and cost of two validated series on a manifold with compiled point
    costs, the cells that cannot beat ``bound`` skipped: the full matrix's path and cost,
    bit for bit (a bound below the optimum only costs a second pass without it)."""
    segments = _point_costs.segment_codes(manifold)
    # the point costs are computed inside the accumulation (the T_x x T_y cost matrix is
    # never stored) and only where a path could still beat the bound
    fx, fy = kernel_form(x, manifold), kernel_form(y, manifold)
    rows = _pruned.accumulated_segment_cost(fx, fy, segments, squared, window, bound)
    cost = _pruned.ragged_value(*rows, len(x) - 1, len(y) - 1)
    if not cost <= bound:  # the guide left the band, or a cost is not finite
        rows = _pruned.accumulated_segment_cost(fx, fy, segments, squared, window, np.inf)
        cost = _pruned.ragged_value(*rows, len(x) - 1, len(y) - 1)
    if not np.isfinite(cost):  # the full cost matrix says why
        return optimal_path(point_cost_matrix(x, y, manifold, squared), window)
    return _pruned.ragged_backtrack(*rows, len(y)), float(cost)


def guide_bound(
    x: np.ndarray,
    y: np.ndarray,
    manifold: Manifold,
    window: float,
    squared: bool,
    guide: np.ndarray | None = None,
) -> float:
    """The cost of ``guide``, a warping path between two validated series (default: their
    :func:`multiscale_path` if they are long, over :data:`EXACT_CELLS` cells, and have no
    band): a bound that lets the exact DTW skip most cells. ``inf`` without a guide or a
    kernel distance."""
    segments = _point_costs.segment_codes(manifold)
    if segments is None:
        return np.inf
    if guide is None and (window < 0.0 or window >= 1.0) and len(x) * len(y) > EXACT_CELLS:
        guide = multiscale_path(x, y, manifold, squared)[0]
    if guide is None:
        return np.inf
    cost = _point_costs.path_cost(kernel_form(x, manifold), kernel_form(y, manifold),
                              np.asarray(guide, dtype=np.int64), segments, squared)  # fmt: skip
    return cost * (1.0 + GUIDE_SLACK)
