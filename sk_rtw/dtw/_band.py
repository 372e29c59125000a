"""DTW paths of long series: coarse to fine, in a band around the coarser path.

An exact DTW path between series of ``T_x`` and ``T_y`` samples costs ``T_x T_y`` cells:
80 million for two robot demonstrations of 9,000 samples, and a dense accumulated-cost
matrix of that size. :func:`multiscale_path` (Salvador and Chan's FastDTW, with the
recursion of :mod:`sk_rtw.dtw._kernels`) halves both series by geodesic midpoints of
neighbouring samples until they are short, solves the coarsest pair exactly, and at each
finer level only fills the cells within ``radius`` samples of the coarser path projected
onto it: ``O((T_x + T_y) radius)`` cells per level. The path is optimal within the band;
in the rare case that the optimal path leaves the band it is a close approximation
(tests compare both with the exact path).

Band layout: row ``i`` holds the columns ``lo[i] <= j < hi[i]``, stored at ``j - lo[i]``
in an array of ``(T_x, max(hi - lo))`` values; ``lo`` and ``hi`` are non-decreasing, so
the band is a staircase that connects ``(0, 0)`` with ``(T_x - 1, T_y - 1)``.
"""

from __future__ import annotations

import numpy as np
import torch
from numba import njit

from ..manifolds import Manifold
from . import _kernels

_INF = np.inf

#: Pairs with at most this many cells get the exact path.
EXACT_CELLS = 2**20
#: Half-width of the band around the projected coarser path, in samples of each level.
RADIUS = 16

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


@njit(cache=True, nogil=True)
def band_segment_costs(x, y, lo, hi, segments, squared, width):
    """Point costs of the band cells for manifolds with kernel distances (segments)."""
    nx = x.shape[0]
    out = np.full((nx, width), _INF)
    for i in range(nx):
        _kernels._cost_row(x, y[lo[i] : hi[i]], i, hi[i] - lo[i], segments, squared, out[i])
    return out


@njit(cache=True, nogil=True)
def band_accumulate(cost, lo, hi):
    """Accumulated DTW cost of the band cells (``inf`` outside the band)."""
    nx, width = cost.shape
    D = np.full((nx, width), _INF)
    for i in range(nx):
        for j in range(lo[i], hi[i]):
            c = cost[i, j - lo[i]]
            if i == 0 and j == 0:
                D[0, 0] = c
                continue
            best = _INF
            if i > 0:
                if lo[i - 1] <= j < hi[i - 1]:
                    best = D[i - 1, j - lo[i - 1]]
                if lo[i - 1] <= j - 1 < hi[i - 1] and D[i - 1, j - 1 - lo[i - 1]] < best:
                    best = D[i - 1, j - 1 - lo[i - 1]]
            if j - 1 >= lo[i] and D[i, j - 1 - lo[i]] < best:
                best = D[i, j - 1 - lo[i]]
            D[i, j - lo[i]] = c + best
    return D


@njit(cache=True, nogil=True)
def _band_value(D, lo, hi, i, j):
    if j < lo[i] or j >= hi[i]:
        return _INF
    return D[i, j - lo[i]]


@njit(cache=True, nogil=True)
def band_backtrack(D, lo, hi):
    """Optimal path ``(P, 2)`` through a band (ties as the dense recursion breaks them)."""
    nx = D.shape[0]
    i, j = nx - 1, hi[nx - 1] - 1
    out = np.empty((nx + j + 1, 2), dtype=np.int64)
    n = 0
    out[n, 0], out[n, 1] = i, j
    n += 1
    while i > 0 or j > 0:
        if i == 0:
            j -= 1
        elif j == 0:
            i -= 1
        else:
            diag = _band_value(D, lo, hi, i - 1, j - 1)
            up = _band_value(D, lo, hi, i - 1, j)
            left = _band_value(D, lo, hi, i, j - 1)
            if diag <= up and diag <= left:
                i, j = i - 1, j - 1
            elif up <= left:
                i -= 1
            else:
                j -= 1
        out[n, 0], out[n, 1] = i, j
        n += 1
    return out[:n][::-1].copy()


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
    """Every series :func:`coarse` to at most ``length`` samples, as one collection (the
    shorter ones padded with their last sample, their lengths kept)."""
    from ..utils import SeriesCollection

    small = [coarse(s, manifold, length) for s in series]
    lengths = np.array([len(s) for s in small])
    data = np.stack(
        [np.concatenate([s, np.repeat(s[-1:], lengths.max() - len(s), 0)]) for s in small]
    )
    return SeriesCollection(data=data, lengths=lengths, manifold=manifold)


def _band_costs(x, y, lo, hi, manifold, squared) -> np.ndarray:
    width = int((hi - lo).max())
    segments = _kernels.segment_codes(manifold)
    if segments is not None:
        return band_segment_costs(_kernels.kernel_points(manifold, _flat(x)),
                                  _kernels.kernel_points(manifold, _flat(y)), lo, hi, segments,
                                  squared, width)  # fmt: skip
    rows = np.repeat(np.arange(len(x)), hi - lo)
    offsets = np.arange(rows.size) - np.repeat(np.cumsum(hi - lo) - (hi - lo), hi - lo)
    cols = lo[rows] + offsets
    cost = np.full((len(x), width), np.inf)
    with torch.no_grad():
        values = manifold._dist(torch.as_tensor(x[rows]), torch.as_tensor(y[cols])).numpy()
    cost[rows, offsets] = values * values if squared else values
    return cost


def solved_exactly(nx: int, ny: int, radius: int = RADIUS, exact_cells: int = EXACT_CELLS):
    """Whether :func:`multiscale_path` solves a pair of these lengths exactly (no band)."""
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
    from ._dtw import point_cost_matrix
    from ._paths import optimal_path

    if solved_exactly(len(x), len(y), radius, exact_cells):
        return optimal_path(point_cost_matrix(x, y, manifold, squared))
    coarse, _ = multiscale_path(halve(x, manifold), halve(y, manifold), manifold, squared,
                                radius, exact_cells)  # fmt: skip
    lo, hi = band_from_path(coarse, len(x), len(y), radius)
    D = band_accumulate(_band_costs(x, y, lo, hi, manifold, squared), lo, hi)
    return band_backtrack(D, lo, hi), float(D[-1, hi[-1] - 1 - lo[-1]])


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
    segments = _kernels.segment_codes(manifold)
    if segments is None:
        return np.inf
    if guide is None and (window < 0.0 or window >= 1.0) and len(x) * len(y) > EXACT_CELLS:
        guide = multiscale_path(x, y, manifold, squared)[0]
    if guide is None:
        return np.inf
    cost = _kernels.path_cost(
        _kernels.kernel_points(manifold, _flat(x)), _kernels.kernel_points(manifold, _flat(y)),
        np.asarray(guide, dtype=np.int64), segments, squared,
    )  # fmt: skip
    return cost * (1.0 + GUIDE_SLACK)


def _flat(x: np.ndarray) -> np.ndarray:
    """A validated series ``(T, *point_shape)`` as ``(T, prod(point_shape))``."""
    return np.ascontiguousarray(x.reshape(x.shape[0], -1))
