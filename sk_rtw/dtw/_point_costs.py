"""The kernels' form of a point and the compiled point costs between two such points.

Point distances that numba computes itself are described by "segments" ``(start, stop,
code)`` of a flattened point, translated by :func:`segment_codes` from the manifold's
:attr:`~sk_rtw.manifolds.Manifold.distance_segments`: code 0 Euclidean, 1 great-circle on
a sphere, 2 sign-invariant great circle (quaternions), ``k + 1`` affine-invariant SPD(k)
for ``2 <= k <= MAX_KERNEL_SIZE`` (:mod:`~sk_rtw.dtw._spd_kernels`); a product space is
several segments, combined as ``sqrt(sum d_s^2)``. The kernels read points in their kernel
form (:func:`kernel_points`): the coordinates as they are, except an SPD block, which
becomes its features (prepared once per point, so that a pair costs no
eigendecomposition). :func:`_cost_row` computes one row of point costs, the one place the
recursion (:mod:`._kernels`, :mod:`._pruned`) gets them from.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ..manifolds import Manifold
from ._spd_kernels import MAX_KERNEL_SIZE, feature_width, spd_features, spd_squared_distance

#: The kernel's codes of the manifolds' distance kinds.
SEGMENT_EUCLIDEAN = 0
SEGMENT_SPHERE = 1
SEGMENT_SIGN_INVARIANT_SPHERE = 2
#: SPD(k) blocks, 2 <= k <= MAX_KERNEL_SIZE, have the code ``SEGMENT_SPD2 + k - 2``.
SEGMENT_SPD2 = 3
SEGMENT_CODES = {
    "euclidean": SEGMENT_EUCLIDEAN,
    "sphere": SEGMENT_SPHERE,
    "sign-invariant sphere": SEGMENT_SIGN_INVARIANT_SPHERE,
}
#: SPD(k) blocks with a kernel form: their size ``k * k``, their code and ``k``.
_SPD_BLOCKS = {k * k: (SEGMENT_SPD2 + k - 2, k) for k in range(2, MAX_KERNEL_SIZE + 1)}


@njit(cache=True, nogil=True, inline="always")
def spd_size(code):
    """The matrix size ``k`` of an SPD segment's code."""
    return code - SEGMENT_SPD2 + 2


def _layout(manifold: Manifold) -> list[tuple[int, int, int, int, int]] | None:
    """Every segment as ``(start, stop, kernel start, kernel stop, code)``: where it lies
    in the flat point and in its kernel form; None if one has no kernel distance."""
    segments = manifold.distance_segments
    if segments is None:
        return None
    rows, offset = [], 0
    for start, stop, kind in segments:
        if kind == "spd" and stop - start in _SPD_BLOCKS:
            code, k = _SPD_BLOCKS[stop - start]
            width = feature_width(k)
        elif kind in SEGMENT_CODES:
            code, width = SEGMENT_CODES[kind], stop - start
        else:
            return None
        rows.append((start, stop, offset, offset + width, code))
        offset += width
    return rows


def segment_codes(manifold: Manifold) -> np.ndarray | None:
    """``(n_segments, 3)`` int64 ``(start, stop, code)`` rows of the kernel form of a point
    (:func:`kernel_points`), or None (no kernel form: the manifold's ``pairwise_dist``)."""
    rows = _layout(manifold)
    if rows is None:
        return None
    return np.array([(a, b, code) for _, _, a, b, code in rows], dtype=np.int64)


def kernel_points(manifold: Manifold, flat: np.ndarray) -> np.ndarray:
    """Flat points ``(..., p)`` (validated) in the kernels' form: unchanged (the same
    array) unless the manifold has SPD blocks, which become their features."""
    rows = _layout(manifold)
    if rows is None or all(code < SEGMENT_SPD2 for *_, code in rows):
        return flat
    lead = flat.shape[:-1]
    points = np.ascontiguousarray(flat, dtype=np.float64).reshape(-1, flat.shape[-1])
    out = np.empty((points.shape[0], rows[-1][3]))
    for start, stop, a, b, code in rows:
        if code >= SEGMENT_SPD2:
            k = spd_size(code)
            features = spd_features(np.ascontiguousarray(points[:, start:stop]), k)
            bad = ~np.isfinite(features).all(1)
            if bad.any():
                point = points[int(np.argmax(bad)), start:stop].reshape(k, k)
                largest = float(np.abs(point).max())
                if largest > 1e150 or largest < 1e-150:
                    raise ValueError(
                        f"the SPD({k}) point {point.tolist()} has entries of magnitude "
                        f"{largest:.3g}: the DTW kernels square them, beyond float64's range "
                        "from 1e+-154; rescale the series (the affine-invariant distance does "
                        "not change when every point is multiplied by one number)"
                    )
                raise ValueError(
                    f"the SPD({k}) point {point.tolist()} has no Cholesky factor in float64 "
                    "(it is not positive definite, or too close to singular); regularise "
                    "it (add a multiple of the identity)"
                )
            out[:, a:b] = features
        else:
            out[:, a:b] = points[:, start:stop]
    return out.reshape(*lead, out.shape[-1])


def kernel_series(collection) -> np.ndarray:
    """A :class:`~sk_rtw.utils.SeriesCollection`'s padded series ``(n, T, p)`` in the
    kernels' form, C-contiguous."""
    flat = collection.data.reshape(collection.n_series, collection.max_length, -1)
    return np.ascontiguousarray(kernel_points(collection.manifold, flat))


@njit(cache=True, nogil=True, inline="always")
def _accumulate_scaled(value, scale, ssq):
    """One step of the overflow-free sum of squares ``scale^2 ssq`` (as LAPACK's nrm2)."""
    magnitude = abs(value)
    if magnitude > 0.0:
        if scale < magnitude:
            ssq = 1.0 + ssq * (scale / magnitude) ** 2
            scale = magnitude
        else:
            ssq += (magnitude / scale) ** 2
    return scale, ssq


@njit(cache=True, nogil=True)
def _robust_distance(xi, yj, segments):
    """``sqrt(sum_s d_s^2)`` without overflow or underflow (for extreme magnitudes)."""
    scale, ssq = 0.0, 1.0
    for s in range(segments.shape[0]):
        start, stop, code = segments[s, 0], segments[s, 1], segments[s, 2]
        if code == SEGMENT_EUCLIDEAN:
            for k in range(start, stop):
                scale, ssq = _accumulate_scaled(xi[k] - yj[k], scale, ssq)
        elif code >= SEGMENT_SPD2:  # log-eigenvalues are at most ~745: no overflow
            spd = math.sqrt(spd_squared_distance(xi, yj, start, spd_size(code)))
            scale, ssq = _accumulate_scaled(spd, scale, ssq)
        else:
            dot = 0.0
            for k in range(start, stop):
                dot += xi[k] * yj[k]
            perp_scale, perp_ssq = 0.0, 1.0
            for k in range(start, stop):
                perp_scale, perp_ssq = _accumulate_scaled(
                    yj[k] - dot * xi[k], perp_scale, perp_ssq
                )
            angle = math.atan2(
                perp_scale * math.sqrt(perp_ssq),
                abs(dot) if code == SEGMENT_SIGN_INVARIANT_SPHERE else dot,
            )
            scale, ssq = _accumulate_scaled(angle, scale, ssq)
    return scale * math.sqrt(ssq)


#: Sums of squares outside [TINY, HUGE] lost precision to underflow or overflow.
_TINY, _HUGE = 1e-290, 1e290


@njit(cache=True, nogil=True, inline="always")
def _roots(row, n):
    """Each of the ``n`` first point costs of ``row`` replaced by its square root: a
    geodesic distance ``d`` becomes the cost ``d ** 0.5`` (the point-cost exponent 1/2
    of Proximity Forest 2.0)."""
    for j in range(n):
        row[j] = math.sqrt(row[j])


@njit(cache=True, nogil=True, inline="always")
def _cost_row(x, y, i, ny, segments, squared, row):
    """Row ``i`` of the cost matrix: point costs between ``x[i]`` and ``y[:ny]``."""
    xi = x[i]
    n_segments = segments.shape[0]
    if n_segments == 1 and segments[0, 2] == SEGMENT_EUCLIDEAN and segments[0, 1] == 1:
        a = xi[0]  # univariate: |a - b| exactly, at any magnitude
        for j in range(ny):
            diff = abs(a - y[j, 0])
            row[j] = diff * diff if squared else diff
        return
    for j in range(ny):
        row[j] = 0.0
    for s in range(n_segments):
        start, stop, code = segments[s, 0], segments[s, 1], segments[s, 2]
        if code == SEGMENT_EUCLIDEAN:
            for j in range(ny):
                sq = 0.0
                for k in range(start, stop):
                    diff = xi[k] - y[j, k]
                    sq += diff * diff
                row[j] += sq
        elif code >= SEGMENT_SPD2:
            for j in range(ny):
                row[j] += spd_squared_distance(xi, y[j], start, spd_size(code))
        else:
            for j in range(ny):
                dot = 0.0
                for k in range(start, stop):
                    dot += xi[k] * y[j, k]
                perp = 0.0
                for k in range(start, stop):
                    r = y[j, k] - dot * xi[k]
                    perp += r * r
                angle = math.atan2(
                    math.sqrt(perp), abs(dot) if code == SEGMENT_SIGN_INVARIANT_SPHERE else dot
                )
                row[j] += angle * angle
    if not squared:
        for j in range(ny):
            sq = row[j]
            if sq < _TINY or sq > _HUGE:  # recompute without under- or overflow
                row[j] = _robust_distance(xi, y[j], segments)
            else:
                row[j] = math.sqrt(sq)


@njit(cache=True, nogil=True)
def segment_cost_matrix(x, y, nx, ny, segments, squared, out):
    """Cost matrix of flattened series ``x`` (Tx, p) and ``y`` (Ty, p) into ``out``."""
    for i in range(nx):
        _cost_row(x, y, i, ny, segments, squared, out[i])


@njit(cache=True, nogil=True)
def path_cost(x, y, path, segments, squared):
    """The cost of a warping path ``(P, 2)`` between flattened series, summed along it
    in order: the value the DTW recursion gives that path, bit for bit (the same point
    costs, added in the same order)."""
    total = 0.0
    cost = np.empty(1)
    for k in range(path.shape[0]):
        j = path[k, 1]
        _cost_row(x, y[j : j + 1], path[k, 0], 1, segments, squared, cost)
        total = cost[0] + total
    return total


@njit(cache=True, nogil=True, parallel=True)
def segment_cost_stack(x, Y, nx, nys, segments, squared):
    """Cost matrices between ``x`` and each series of ``Y``, shape (len(Y), Tx, Ty)."""
    out = np.zeros((Y.shape[0], x.shape[0], Y.shape[1]))
    for k in prange(Y.shape[0]):
        segment_cost_matrix(x, Y[k], nx, nys[k], segments, squared, out[k])
    return out



@njit(cache=True, nogil=True)
def diagonal_cost(x, y, segments, squared, root=False):
    """The cost of the direct, diagonal alignment of flattened series ``x`` and ``y``.

    Equal lengths pair sample ``t`` with sample ``t``; unequal lengths step along the
    longer series and pair its sample ``t`` with sample ``floor(t n / m)`` of the shorter
    (``n`` samples, ``m`` the longer length): a warping path of ``m`` steps, ``m - n`` of
    them off the diagonal, whose cost bounds the DTW distance from above (the costs
    summed in the recursion's order: along the diagonal of equal lengths, its value bit
    for bit). Amerced DTW scales its penalty by this cost (Herrmann and Webb, 2023).
    ``root``: point costs are the square roots of the distances (``squared=False``).
    """
    nx, ny = x.shape[0], y.shape[0]
    steps = max(nx, ny)
    cost = np.empty(1)
    total = 0.0
    for t in range(steps):
        j = t * ny // steps
        _cost_row(x, y[j : j + 1], t * nx // steps, 1, segments, squared, cost)
        if root:
            _roots(cost, 1)
        total = cost[0] + total
    return total


@njit(cache=True, nogil=True)
def diagonal_costs(X, lengths, first, second, segments, squared, root):
    """:func:`diagonal_cost` of series ``first[k]`` and ``second[k]`` of ``X`` (``(n, L,
    p)``, kernel form), for every ``k``."""
    out = np.empty(first.shape[0])
    for k in range(first.shape[0]):
        a, b = first[k], second[k]
        out[k] = diagonal_cost(X[a, : lengths[a]], X[b, : lengths[b]], segments, squared, root)
    return out
