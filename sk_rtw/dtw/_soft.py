"""Soft-DTW (Cuturi and Blondel, ICML 2017) over a cost matrix, with its gradient.

``R[i, j] = C[i, j] + softmin_gamma(R[i-1, j-1], R[i-1, j], R[i, j-1])`` with
``softmin_gamma(a) = -gamma log sum exp(-a / gamma)``; the value is ``R[m-1, n-1]`` and
``E = dR[m-1, n-1] / dC``, the soft alignment: every row of ``E`` sums to at least one,
and as ``gamma -> 0`` ``E`` becomes the indicator of the hard DTW path (ties split).
Cells outside a Sakoe-Chiba band (the hard kernels' :func:`sakoe_chiba_rows`) are
excluded from both passes.

Soft-DTW is concave in ``C`` (a soft minimum of linear functions), so
``sdtw(C') <= sdtw(C) + <E(C), C' - C>``: the linearisation at the current cost matrix
majorises the objective, which is what the barycentre refinement
(:mod:`sk_rtw.align._refine`) minimises.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ._kernels import sakoe_chiba_rows

_INF = np.inf


@njit(cache=True, nogil=True, inline="always")
def _softmin3(a, b, c, gamma):
    m = min(a, b, c)
    if m == _INF:
        return _INF
    total = math.exp((m - a) / gamma) + math.exp((m - b) / gamma) + math.exp((m - c) / gamma)
    return m - gamma * math.log(total)


@njit(cache=True, nogil=True)
def soft_dtw(cost: np.ndarray, gamma: float, window: float):
    """Value and soft alignment ``E`` (same shape as ``cost``) of one cost matrix."""
    m, n = cost.shape
    lo, hi = sakoe_chiba_rows(m, n, window)
    R = np.full((m + 2, n + 2), _INF)
    R[0, 0] = 0.0
    for i in range(1, m + 1):
        for j in range(lo[i - 1] + 1, hi[i - 1] + 1):
            R[i, j] = cost[i - 1, j - 1] + _softmin3(
                R[i - 1, j - 1], R[i - 1, j], R[i, j - 1], gamma
            )
    value = R[m, n]
    E = np.zeros((m + 2, n + 2))
    # the backward pass reads neighbours beyond the last row and column: never chosen,
    # except the end cell, whose derivative is one
    for i in range(m + 2):
        R[i, n + 1] = -_INF
    for j in range(n + 2):
        R[m + 1, j] = -_INF
    R[m + 1, n + 1] = R[m, n]
    E[m + 1, n + 1] = 1.0
    for i in range(m, 0, -1):
        for j in range(hi[i - 1], lo[i - 1], -1):
            r = R[i, j]
            below = cost[i, j - 1] if i < m else 0.0
            right = cost[i - 1, j] if j < n else 0.0
            diagonal = cost[i, j] if (i < m and j < n) else 0.0
            total = 0.0
            if E[i + 1, j] > 0.0 and R[i + 1, j] > -_INF:
                total += E[i + 1, j] * math.exp((R[i + 1, j] - r - below) / gamma)
            if E[i, j + 1] > 0.0 and R[i, j + 1] > -_INF:
                total += E[i, j + 1] * math.exp((R[i, j + 1] - r - right) / gamma)
            if E[i + 1, j + 1] > 0.0 and R[i + 1, j + 1] > -_INF:
                total += E[i + 1, j + 1] * math.exp((R[i + 1, j + 1] - r - diagonal) / gamma)
            E[i, j] = total
    return value, E[1 : m + 1, 1 : n + 1].copy()


@njit(cache=True, nogil=True, parallel=True)
def soft_dtw_batch(costs, nxs, nys, gamma, window):
    """Soft-DTW values and expected alignments of a stack of padded cost matrices.

    Parameters
    ----------
    costs : ndarray of shape (K, m_max, n_max)
        Point costs; matrix ``k`` is its top-left ``nxs[k] x nys[k]`` block.
    nxs, nys : ndarray of shape (K,), int
    gamma : float
        Smoothing (> 0); small values approach the hard DTW.
    window : float
        Sakoe–Chiba radius as a fraction of the shorter series; negative: no band.

    Returns
    -------
    values : ndarray of shape (K,)
        The soft-minimum path costs.
    E : ndarray of shape (K, m_max, n_max)
        The expected alignment matrices (the gradients of the values with respect to
        the costs), zero in the padding.
    """
    k_total = costs.shape[0]
    values = np.empty(k_total)
    E = np.zeros_like(costs)
    for k in prange(k_total):
        value, e = soft_dtw(costs[k, : nxs[k], : nys[k]], gamma, window)
        values[k] = value
        E[k, : nxs[k], : nys[k]] = e
    return values, E
