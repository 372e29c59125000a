"""Sliding geodesic distances between a shapelet and every window of a series, compiled
once: what the shapelet transform and the forest's shapelet splits both compute.

A window is ``l`` points of a series ``(x_t, x_{t+d}, ..., x_{t+(l-1)d})`` (``d`` the
dilation), in the kernels' form (:func:`~._point_costs.kernel_series`), possibly
normalised first (the manifold's z-normalisation). The distance between a shapelet
``S`` and a window ``W`` is ``sum_k dist(S_k, W_k)``, the geodesic distance summed over
the window (on R^1, the Manhattan distance of random dilated shapelets). The kernels
take windows already gathered, ``(n, n_windows, l, q)``, so raw and normalised windows
share them.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._point_costs import FLAT, add_squared_distances, robust_distance

#: Sums of squares outside [TINY, HUGE] are recomputed without under- or overflow.
_TINY, _HUGE = 1e-290, 1e290


@njit(cache=True, nogil=True, inline="always")
def _point_distance(a, window, k, segments, row):
    """The geodesic distance between the point ``a`` and point ``k`` of ``window``."""
    if segments.shape[0] == 1 and segments[0, 2] == FLAT and segments[0, 1] == 1:
        return abs(a[0] - window[k, 0])
    row[0] = 0.0
    b = window[k : k + 1]
    for s in range(segments.shape[0]):
        add_squared_distances(a, b, 1, segments[s, 0], segments[s, 1], segments[s, 2], row)
    sq = row[0]
    if sq < _TINY or sq > _HUGE:
        return robust_distance(a, window[k], segments)
    return math.sqrt(sq)


@njit(cache=True, nogil=True)
def window_distances(windows, n_windows, shapelet, segments, out):
    """``out[t]``: the distance between ``shapelet`` ``(l, q)`` and ``windows[t]`` for
    ``t < n_windows`` (``windows``: ``(P, l, q)``)."""
    row = np.empty(1)
    flat = segments.shape[0] == 1 and segments[0, 2] == FLAT
    for t in range(n_windows):
        out[t] = _window_sum(shapelet, windows[t], segments, flat, row, np.inf)


@njit(cache=True, nogil=True, inline="always")
def _window_sum(shapelet, window, segments, flat, row, cutoff):
    """``sum_k dist(shapelet[k], window[k])``, abandoned (returned as it stands) once
    above ``cutoff``."""
    length, q = shapelet.shape
    total = 0.0
    if flat and q == 1:
        # eight terms between checks (the same additions in the same order: a sum past
        # the cutoff stays past it, and only sums under it are read)
        k = 0
        while k + 8 <= length:
            for m in range(k, k + 8):
                total += abs(shapelet[m, 0] - window[m, 0])
            if total > cutoff:
                return total
            k += 8
        while k < length:
            total += abs(shapelet[k, 0] - window[k, 0])
            k += 1
        return total
    for k in range(length):
        if flat:
            sq = 0.0
            for c in range(q):
                diff = shapelet[k, c] - window[k, c]
                sq += diff * diff
            if sq < _TINY or sq > _HUGE:
                total += robust_distance(shapelet[k], window[k], segments)
            else:
                total += math.sqrt(sq)
        else:
            total += _point_distance(shapelet[k], window, k, segments, row)
        if total > cutoff:
            return total
    return total


@njit(cache=True, nogil=True)
def shapelet_features(windows, n_windows, shapelets, thresholds, segments, out):
    """For every series ``i`` and shapelet ``j``: ``out[i, j]`` = (the smallest window
    distance, the first window where it occurs, how many windows lie closer than
    ``thresholds[j]``).

    ``windows`` is ``(n, P, l, q)`` with ``n_windows[i]`` valid windows of series ``i``;
    ``shapelets`` is ``(g, l, q)``. A sum is abandoned once above both the threshold and
    the smallest distance so far: the three features are those of the full sums.
    """
    row = np.empty(1)
    flat = segments.shape[0] == 1 and segments[0, 2] == FLAT
    for i in range(windows.shape[0]):
        series = windows[i]
        for j in range(shapelets.shape[0]):
            shapelet = shapelets[j]
            threshold = thresholds[j]
            best, where, count = np.inf, -1, 0
            for t in range(n_windows[i]):
                total = _window_sum(shapelet, series[t], segments, flat, row,
                                    max(best, threshold))  # fmt: skip
                if total < threshold:
                    count += 1
                if total < best:
                    best, where = total, t
            out[i, j, 0] = best
            out[i, j, 1] = where
            out[i, j, 2] = count


@njit(cache=True, nogil=True)
def window_profiles(windows, n_windows, rows, shapelets, segments, out):
    """``out[j, t]``: the distance between ``shapelets[j]`` and window ``t`` of series
    ``rows[j]`` of ``windows`` (``(m, P, l, q)``); NaN past that series' windows."""
    row = np.empty(1)
    flat = segments.shape[0] == 1 and segments[0, 2] == FLAT
    for j in range(shapelets.shape[0]):
        series = windows[rows[j]]
        count = n_windows[rows[j]]
        for t in range(out.shape[1]):
            if t < count:
                out[j, t] = _window_sum(shapelets[j], series[t], segments, flat, row, np.inf)
            else:
                out[j, t] = np.nan
