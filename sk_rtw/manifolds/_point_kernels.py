"""The manifolds' compiled point geometry, as the DTW kernels read it: one table.

Every manifold describes its distance by "segments" of a flattened point
(:attr:`~sk_rtw.manifolds.Manifold.distance_segments`: ``(start, stop, kind)``); a
product space is several segments, its distance ``sqrt(sum d_s^2)``. This module is
where a kind becomes compiled geometry, and the only place :mod:`sk_rtw.dtw` learns
about one: the DTW package runs recursions over rows of point costs and names no
manifold. For every kind it holds

- its kernel code (:func:`segment_codes`; :data:`FLAT` for squared coordinate
  differences, the Euclidean factors, which the DTW kernels may vectorise);
- the kernel form of its points (:func:`kernel_points`): the coordinates as they are,
  except an SPD(k) block, which becomes its features (:mod:`._spd_pairs`: prepared once
  per point, so that a pair costs no eigendecomposition);
- the squared distance of a pair (:func:`add_squared_distances`, a segment's share of a
  row of point costs), and its overflow-safe form (:func:`robust_distance`);
- a lower bound of the distance between a point and any point inside a box of
  coordinates (:func:`box_squared_bound`, LB_Keogh's envelope gap): on a sphere the
  bound on the chord is turned into one on the angle (``2 asin(c / 2)``, increasing);
  on quaternions the smaller of the bounds of ``q`` and ``-q`` is taken; on SPD matrices
  the bound is that of the sorted log-eigenvalues, a 1-Lipschitz map of the
  affine-invariant distance (:mod:`._spd_pairs`), shrunk by :data:`SPD_BOUND_SHRINK`.

The formulas themselves live with their manifold: the sphere's angle in
:mod:`._sphere_kernels` (which its compiled ``dist`` calls too), the SPD pairs in
:mod:`._spd_pairs`. A new kind is a code here, its formula in its manifold's kernel
module and a branch in the three functions below; a manifold without a kernel kind
(``distance_segments`` None) is measured by its own ``pairwise_dist``.
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np
from numba import njit

from . import _spd_pairs, _sphere_kernels
from ._base import Manifold
from ._spd_pairs import MAX_KERNEL_SIZE, feature_width, spd_features, spd_squared_distance
from ._sphere_kernels import angle

#: The kernel codes of the distance kinds.
FLAT = 0
SPHERE = 1
SIGN_INVARIANT_SPHERE = 2
#: SPD(k) blocks, 2 <= k <= MAX_KERNEL_SIZE, have the code ``SPD2 + k - 2``.
SPD2 = 3
KIND_CODES = {"euclidean": FLAT, "sphere": SPHERE, "sign-invariant sphere": SIGN_INVARIANT_SPHERE}
#: SPD(k) blocks with a kernel form: their size ``k * k``, their code and ``k``.
_SPD_BLOCKS = {k * k: (SPD2 + k - 2, k) for k in range(2, MAX_KERNEL_SIZE + 1)}
#: An SPD block's bound (its points' log-eigenvalues, each computed to a relative
#: accuracy of about 1e-16 times the condition number) is shrunk by this factor.
SPD_BOUND_SHRINK = 1.0 - 1e-6


def compiled_sources() -> list[str]:
    """The files whose compiled code the DTW kernels inline: this table and the kernel
    modules of the manifolds it reads (their caches follow an edit of any of them)."""
    return [__file__, _spd_pairs.__file__, _sphere_kernels.__file__]


@njit(cache=True, nogil=True, inline="always")
def _spd_size(code):
    """The matrix size ``k`` of an SPD segment's code."""
    return code - SPD2 + 2


def _layout(manifold: Manifold) -> tuple[tuple[int, int, int, int, int], ...] | None:
    """Every segment as ``(start, stop, kernel start, kernel stop, code)``: where it lies
    in the flat point and in its kernel form; None if one has no kernel distance. Kept
    per value for instances of a frozen dataclass (the library's manifolds: immutable,
    compared by value; a subclass that is not itself one does not qualify), worked out
    at every call for any other manifold."""
    params = type(manifold).__dict__.get("__dataclass_params__")
    if params is not None and params.frozen:
        return _kept_layout(manifold)
    return _work_out_layout(manifold)


@functools.lru_cache(maxsize=128)
def _kept_layout(manifold: Manifold) -> tuple[tuple[int, int, int, int, int], ...] | None:
    return _work_out_layout(manifold)


def _work_out_layout(manifold: Manifold) -> tuple[tuple[int, int, int, int, int], ...] | None:
    segments = manifold.distance_segments
    if segments is None:
        return None
    _check_tiling(manifold, segments)
    rows, offset = [], 0
    for start, stop, kind in segments:
        if kind == "spd" and stop - start in _SPD_BLOCKS:
            code, k = _SPD_BLOCKS[stop - start]
            width = feature_width(k)
        elif kind in KIND_CODES:
            code, width = KIND_CODES[kind], stop - start
        else:
            return None
        rows.append((start, stop, offset, offset + width, code))
        offset += width
    return tuple(rows)


def _check_tiling(manifold: Manifold, segments: Any) -> None:
    """The segments must cover the flat point once, in order: ``(0, a), (a, b), ...,
    (c, size)``; otherwise the kernels would read past a point or skip coordinates."""
    size = int(np.prod(manifold.point_shape))
    expected = 0
    for segment in segments:
        start, stop, _ = segment
        if start != expected or stop <= start or stop > size:
            raise ValueError(
                f"{manifold!r}.distance_segments = {tuple(segments)!r} do not cover its "
                f"points' {size} coordinates once, in order: each segment (start, stop, "
                f"kind) must start where the previous one stopped (the first at 0) and the "
                f"last stop at {size}; segment {tuple(segment)!r} breaks that"
            )
        expected = stop
    if expected != size:
        raise ValueError(
            f"{manifold!r}.distance_segments = {tuple(segments)!r} cover coordinates 0 to "
            f"{expected} of its points' {size}: the distance would ignore the rest"
        )


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
    if rows is None or all(code < SPD2 for *_, code in rows):
        return flat
    lead = flat.shape[:-1]
    points = np.ascontiguousarray(flat, dtype=np.float64).reshape(-1, flat.shape[-1])
    out = np.empty((points.shape[0], rows[-1][3]))
    for start, stop, a, b, code in rows:
        if code >= SPD2:
            k = int(_spd_size(code))
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


@njit(cache=True, nogil=True, inline="always")
def add_squared_distances(xi, y, ny, start, stop, code, row):
    """Add one segment's squared distance between ``xi`` and each of ``y[:ny]`` (kernel
    form) to ``row[:ny]``."""
    if code == FLAT:
        for j in range(ny):
            sq = 0.0
            for k in range(start, stop):
                diff = xi[k] - y[j, k]
                sq += diff * diff
            row[j] += sq
    elif code >= SPD2:
        for j in range(ny):
            row[j] += spd_squared_distance(xi, y[j], start, _spd_size(code))
    else:
        for j in range(ny):
            a = angle(xi, y, j, start, stop, code == SIGN_INVARIANT_SPHERE)
            row[j] += a * a


@njit(cache=True, nogil=True, inline="always")
def accumulate_scaled(value, scale, ssq):
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
def robust_distance(xi, yj, segments):
    """``sqrt(sum_s d_s^2)`` without overflow or underflow (for extreme magnitudes)."""
    scale, ssq = 0.0, 1.0
    for s in range(segments.shape[0]):
        start, stop, code = segments[s, 0], segments[s, 1], segments[s, 2]
        if code == FLAT:
            for k in range(start, stop):
                scale, ssq = accumulate_scaled(xi[k] - yj[k], scale, ssq)
        elif code >= SPD2:  # log-eigenvalues are at most ~745: no overflow
            spd = math.sqrt(spd_squared_distance(xi, yj, start, _spd_size(code)))
            scale, ssq = accumulate_scaled(spd, scale, ssq)
        else:  # the angle with its perpendicular part summed without underflow
            dot = 0.0
            for k in range(start, stop):
                dot += xi[k] * yj[k]
            perp_scale, perp_ssq = 0.0, 1.0
            for k in range(start, stop):
                perp_scale, perp_ssq = accumulate_scaled(
                    yj[k] - dot * xi[k], perp_scale, perp_ssq
                )
            between = math.atan2(
                perp_scale * math.sqrt(perp_ssq),
                abs(dot) if code == SIGN_INVARIANT_SPHERE else dot,
            )
            scale, ssq = accumulate_scaled(between, scale, ssq)
    return scale * math.sqrt(ssq)


@njit(cache=True, nogil=True, inline="always")
def outside(value, low, high):
    """Distance of ``value`` to the interval ``[low, high]`` (an envelope gap)."""
    if value > high:
        return value - high
    if value < low:
        return low - value
    return 0.0


@njit(cache=True, nogil=True, inline="always")
def box_squared_bound(point, lower, upper, start, stop, code):
    """A lower bound of one segment's squared distance between ``point`` (kernel form)
    and any point whose coordinates lie in ``[lower, upper]`` (module docstring)."""
    near = 0.0
    if code >= SPD2:  # the sorted log-eigenvalues
        stop = start + _spd_size(code)
    for k in range(start, stop):
        gap = outside(point[k], lower[k], upper[k])
        near += gap * gap
    if code == FLAT:
        return near
    if code >= SPD2:
        return near * SPD_BOUND_SHRINK
    if code == SIGN_INVARIANT_SPHERE:
        flipped = 0.0  # the envelope of -x is [-upper, -lower]
        for k in range(start, stop):
            gap = outside(point[k], -upper[k], -lower[k])
            flipped += gap * gap
        near = min(near, flipped)
    chord = 2.0 * math.asin(min(1.0, 0.5 * math.sqrt(near)))
    return chord * chord
