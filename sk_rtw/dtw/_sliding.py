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

from ._point_costs import FLAT, add_squared_distances, is_univariate, robust_distance

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


# --- windows read in place from Euclidean series ------------------------------------
#
# The forest's shapelet candidates compare one shapelet with the windows of a few series:
# gathering every window first (and z-normalising it with numpy) costs more than the
# distances. On Euclidean coordinates (the raw series of R^d, the tangent velocity of any
# manifold) the kernels below read each window from the series as they go, z-normalised
# in the kernel with numpy's arithmetic (its means and standard deviations bit for bit:
# the sums along the window in numpy's order, which depends on the memory layout numpy
# reduces: ``pairwise`` for one univariate series or shapelet, its contiguous pairwise
# summation; otherwise one term after the other).

#: numpy's block of its pairwise summation.
_PAIRWISE_BLOCK = 128


@njit(cache=True, nogil=True)
def _block_sum(values, start, n, c):
    """numpy's pairwise sum of ``values[start:start + n, c]`` for ``n`` up to its block:
    one term after the other below 8, else eight running sums."""
    if n < 8:
        total = 0.0
        for k in range(start, start + n):
            total += values[k, c]
        return total
    r0, r1 = values[start, c], values[start + 1, c]
    r2, r3 = values[start + 2, c], values[start + 3, c]
    r4, r5 = values[start + 4, c], values[start + 5, c]
    r6, r7 = values[start + 6, c], values[start + 7, c]
    k = 8
    while k < n - n % 8:
        r0 += values[start + k, c]
        r1 += values[start + k + 1, c]
        r2 += values[start + k + 2, c]
        r3 += values[start + k + 3, c]
        r4 += values[start + k + 4, c]
        r5 += values[start + k + 5, c]
        r6 += values[start + k + 6, c]
        r7 += values[start + k + 7, c]
        k += 8
    total = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while k < n:
        total += values[start + k, c]
        k += 1
    return total


@njit(cache=True, nogil=True, inline="always")
def _left_part(n):
    """The size of the first half numpy's pairwise summation splits ``n`` terms into."""
    half = n // 2
    return half - half % 8


@njit(cache=True, nogil=True)
def _pairwise_sum(values, n, c):
    """numpy's pairwise sum of ``values[:n, c]`` (``np.add.reduce`` of a contiguous
    axis): blocks of at most 128 terms, halves added (its recursion, on a stack: numba
    does not cache recursive functions)."""
    if n <= _PAIRWISE_BLOCK:
        return _block_sum(values, 0, n, c)
    starts = np.empty(64, dtype=np.int64)
    sizes = np.empty(64, dtype=np.int64)
    lefts = np.empty(64)
    right_pending = np.zeros(64, dtype=np.bool_)
    top = 0
    starts[0], sizes[0], right_pending[0] = 0, n, False
    total = 0.0
    while top >= 0:
        if sizes[top] > _PAIRWISE_BLOCK:  # descend into the first half
            half = _left_part(sizes[top])
            right_pending[top] = True
            starts[top + 1], sizes[top + 1], right_pending[top + 1] = starts[top], half, False
            top += 1
            continue
        total = _block_sum(values, starts[top], sizes[top], c)
        top -= 1
        while top >= 0:  # hand the sum up
            if right_pending[top]:  # a first half: keep it, go to the second
                lefts[top] = total
                right_pending[top] = False
                half = _left_part(sizes[top])
                starts[top + 1], sizes[top + 1] = starts[top] + half, sizes[top] - half
                right_pending[top + 1] = False
                top += 1
                break
            total = lefts[top] + total  # a second half: the frame's sum
            top -= 1
    return total


@njit(cache=True, nogil=True)
def numpy_column_sum(values, n, c):
    """``np.sum(values[:n, c])`` of a column numpy reads contiguously (a ``(n, 1)`` array,
    or a 1-D array's values), bit for bit: ``0 +`` its pairwise sum."""
    return 0.0 + _pairwise_sum(values, n, c)


@njit(cache=True, nogil=True, inline="always")
def _window_column_sum(values, length, c, pairwise):
    """``0 + values[0, c] + ... + values[length - 1, c]`` in numpy's order."""
    if pairwise:
        return 0.0 + _pairwise_sum(values, length, c)
    total = 0.0
    for k in range(length):
        total += values[k, c]
    return total


@njit(cache=True, nogil=True, inline="always")
def read_window(series, start, length, dilation, normalise, pairwise, floor, out, squares):
    """``out[k] = series[start + k * dilation]`` (the last row past the end: the
    padding), z-normalised per coordinate if ``normalise`` as
    ``(w - w.mean(-2)) / where(w.std(-2) > floor, w.std(-2), 1)`` is, bit for bit
    (``squares``: scratch of ``out``'s shape)."""
    last = series.shape[0] - 1
    q = series.shape[1]
    for k in range(length):
        t = min(start + k * dilation, last)
        for c in range(q):
            out[k, c] = series[t, c]
    if not normalise:
        return
    for c in range(q):
        mean = _window_column_sum(out, length, c, pairwise) / length
        for k in range(length):
            centred = out[k, c] - mean
            squares[k, c] = centred * centred
        std = math.sqrt(_window_column_sum(squares, length, c, pairwise) / length)
        scale = std if std > floor else 1.0
        for k in range(length):
            out[k, c] = (out[k, c] - mean) / scale


@njit(cache=True, nogil=True, inline="always")
def _distance_in_place(shapelet, series, t, dilation, normalise, pairwise, univariate, floor,
                       segments, flat, window, squares, row, cutoff):  # fmt: skip
    """The distance between ``shapelet`` and window ``t`` of ``series`` read in place
    (:func:`read_window` then :func:`_window_sum`, the same arithmetic), abandoned once
    above ``cutoff``; ``univariate``: one Euclidean coordinate (callers pass it, and
    ``normalise``, as constants: each combination compiles to its own loop)."""
    length = shapelet.shape[0]
    if not univariate:
        read_window(series, t, length, dilation, normalise, pairwise, floor, window, squares)
        return _window_sum(shapelet, window, segments, flat, row, cutoff)
    last = series.shape[0] - 1
    for k in range(length):
        window[k, 0] = series[min(t + k * dilation, last), 0]
    if normalise:
        mean = _window_column_sum(window, length, 0, pairwise) / length
        for k in range(length):
            centred = window[k, 0] - mean
            squares[k, 0] = centred * centred
        std = math.sqrt(_window_column_sum(squares, length, 0, pairwise) / length)
        scale = std if std > floor else 1.0
        for k in range(length):
            window[k, 0] = (window[k, 0] - mean) / scale
    # _window_sum's univariate sum: eight terms between checks
    total = 0.0
    k = 0
    while k < length:
        stop = min(k + 8, length)
        for m in range(k, stop):
            total += abs(shapelet[m, 0] - window[m, 0])
        if stop - k == 8 and total > cutoff:
            return total
        k = stop
    return total


@njit(cache=True, nogil=True, inline="always")
def _profile_in_place(series, n_windows, shapelet, dilation, normalise, pairwise, univariate,
                      floor, segments, out):  # fmt: skip
    length, q = shapelet.shape
    window = np.empty((length, q))
    squares = np.empty((length, q))
    row = np.empty(1)
    flat = segments.shape[0] == 1 and segments[0, 2] == FLAT
    for t in range(n_windows):
        out[t] = _distance_in_place(shapelet, series, t, dilation, normalise, pairwise,
                                    univariate, floor, segments, flat, window, squares, row,
                                    np.inf)  # fmt: skip


@njit(cache=True, nogil=True)
def series_window_profile(series, n_windows, shapelet, dilation, normalise, pairwise, floor,
                          segments, out):  # fmt: skip
    """``out[t]``: the distance between ``shapelet`` ``(l, q)`` and window ``t`` of
    ``series`` ``(T, q)`` read in place, ``t < n_windows``."""
    if is_univariate(segments) and shapelet.shape[1] == 1:
        if normalise:
            _profile_in_place(series, n_windows, shapelet, dilation, True, pairwise, True,
                              floor, segments, out)  # fmt: skip
        else:
            _profile_in_place(series, n_windows, shapelet, dilation, False, pairwise, True,
                              floor, segments, out)  # fmt: skip
    else:
        _profile_in_place(series, n_windows, shapelet, dilation, normalise, pairwise, False,
                          floor, segments, out)  # fmt: skip


@njit(cache=True, nogil=True, inline="always")
def _feature_value(feature, best, where, count):
    """Feature ``feature`` of :func:`shapelet_features` (0 the smallest distance, 1 the
    first window where it lies, 2 the occurrences) from a series' running values."""
    if feature == 0:
        return best
    if feature == 1:
        return float(where)
    return float(count)


@njit(cache=True, nogil=True, inline="always")
def _batch_window_stats(values, n_windows, length, dilation, floor, means, scales):
    """Mean and scale of the z-normalisation of every window of a univariate series
    ``values``, summed as numpy sums a batch (one term after the other), all windows at
    once (the running sums of neighbouring windows are independent)."""
    last = values.shape[0] - 1
    inside = n_windows - 1 + (length - 1) * dilation <= last
    for t in range(n_windows):
        means[t] = 0.0
        scales[t] = 0.0
    for k in range(length):
        offset = k * dilation
        if inside:
            for t in range(n_windows):
                means[t] += values[t + offset]
        else:
            for t in range(n_windows):
                means[t] += values[min(t + offset, last)]
    for t in range(n_windows):
        means[t] /= length
    for k in range(length):
        offset = k * dilation
        for t in range(n_windows):
            centred = values[min(t + offset, last)] - means[t]
            scales[t] += centred * centred
    for t in range(n_windows):
        std = math.sqrt(scales[t] / length)
        scales[t] = std if std > floor else 1.0


@njit(cache=True, nogil=True, inline="always")
def _normalised_distance(shapelet, values, t, length, dilation, mean, scale, cutoff):
    """:func:`_window_sum`'s univariate sum against window ``t`` of ``values``
    normalised by ``mean`` and ``scale`` as it is read."""
    last = values.shape[0] - 1
    total = 0.0
    k = 0
    while k < length:
        stop = min(k + 8, length)
        for m in range(k, stop):
            total += abs(shapelet[m, 0] - (values[min(t + m * dilation, last)] - mean) / scale)
        if stop - k == 8 and total > cutoff:
            return total
        k = stop
    return total


@njit(cache=True, nogil=True)
def _normalised_univariate_feature(data, rows, n_windows, shapelet, dilation, floor,
                                   threshold, feature, out):  # fmt: skip
    """:func:`series_window_feature` of normalised windows of univariate series."""
    length = shapelet.shape[0]
    size = 1
    for i in range(rows.shape[0]):
        size = max(size, n_windows[i])
    means = np.empty(size)
    scales = np.empty(size)
    for i in range(rows.shape[0]):
        values = data[rows[i], :, 0]
        _batch_window_stats(values, n_windows[i], length, dilation, floor, means, scales)
        best, where, count = np.inf, -1, 0
        for t in range(n_windows[i]):
            cutoff = threshold if feature == 2 else best
            total = _normalised_distance(shapelet, values, t, length, dilation, means[t],
                                         scales[t], cutoff)  # fmt: skip
            if total < threshold:
                count += 1
            if total < best:
                best, where = total, t
        out[i] = _feature_value(feature, best, where, count)


@njit(cache=True, nogil=True, inline="always")
def _feature_in_place(data, rows, n_windows, shapelet, dilation, normalise, univariate, floor,
                      threshold, feature, segments, out):  # fmt: skip
    length, q = shapelet.shape
    window = np.empty((length, q))
    squares = np.empty((length, q))
    row = np.empty(1)
    flat = segments.shape[0] == 1 and segments[0, 2] == FLAT
    for i in range(rows.shape[0]):
        series = data[rows[i]]
        best, where, count = np.inf, -1, 0
        for t in range(n_windows[i]):
            cutoff = threshold if feature == 2 else best
            total = _distance_in_place(shapelet, series, t, dilation, normalise, False,
                                       univariate, floor, segments, flat, window, squares,
                                       row, cutoff)  # fmt: skip
            if total < threshold:
                count += 1
            if total < best:
                best, where = total, t
        out[i] = _feature_value(feature, best, where, count)


@njit(cache=True, nogil=True)
def series_window_feature(data, rows, n_windows, shapelet, dilation, normalise, floor,
                          threshold, feature, segments, out):  # fmt: skip
    """One feature of :func:`shapelet_features` for series ``data[rows[i]]`` (windows
    read in place, ``n_windows[i]`` of them, a batch's arithmetic: ``pairwise`` off):
    ``feature`` 0 the smallest distance, 1 the first window where it lies, 2 how many
    windows lie closer than ``threshold``. Each sum is abandoned once above what that
    feature reads (the smallest so far, or the threshold)."""
    if is_univariate(segments) and shapelet.shape[1] == 1:
        if normalise:
            _normalised_univariate_feature(data, rows, n_windows, shapelet, dilation, floor,
                                           threshold, feature, out)  # fmt: skip
        else:
            _feature_in_place(data, rows, n_windows, shapelet, dilation, False, True, floor,
                              threshold, feature, segments, out)  # fmt: skip
    else:
        _feature_in_place(data, rows, n_windows, shapelet, dilation, normalise, False, floor,
                          threshold, feature, segments, out)  # fmt: skip


@njit(cache=True, nogil=True)
def linear_percentiles(values, n, percentiles, out):
    """``np.percentile(values[:n], percentiles)`` (its default linear interpolation) bit
    for bit, sorting a copy."""
    ordered = np.sort(values[:n])
    for j in range(percentiles.shape[0]):
        virtual = (n - 1) * (percentiles[j] / 100.0)
        if virtual >= n - 1:  # numpy's index -1: the largest
            below, above, gamma = n - 1, n - 1, virtual + 1.0
        elif virtual < 0:
            below, above, gamma = 0, 0, virtual
        else:
            below = math.floor(virtual)
            above, gamma = below + 1, virtual - below
        a, b = ordered[below], ordered[above]
        diff = b - a
        if gamma >= 0.5:
            out[j] = b - diff * (1.0 - gamma)
        else:
            out[j] = a + diff * gamma
