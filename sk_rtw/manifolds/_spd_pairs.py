"""Affine-invariant SPD distances between prepared points, for the DTW kernels: closed
forms for 2 x 2 and 3 x 3, compiled Householder and QL up to ``MAX_KERNEL_SIZE``.

``dist(A, B)^2 = sum_i log(lambda_i)^2`` over the eigenvalues of ``M = L^-1 B L^-T``
(``A = L L^T``, Cholesky), the generalized eigenvalues of ``(B, A)``: no matrix function
is needed, only eigenvalues. Each point is prepared once (:func:`spd_features`): its
log-eigenvalues, the inverse of its Cholesky factor and its own upper triangle, so a
pair costs one congruence ``L^-1 B L^-T`` and the eigenvalues of a symmetric 2 x 2
(a quadratic) or 3 x 3 matrix (the trigonometric solution of its characteristic cubic,
Smith 1961) -- no eigendecomposition, no LAPACK call per pair.

Only largest eigenvalues are taken from a formula (a sum of positive terms: no
cancellation); the smaller of two comes from the determinant (``det M = det B / det A``,
known from the log-eigenvalues), the smallest of three as the inverse of the largest of
the reverse pair ``(A, B)`` and the middle one from the determinant. Larger pairs (``k``
from 4 to ``MAX_KERNEL_SIZE``) take the eigenvalues of the same congruence from a
Householder reduction and the implicit QL iteration, compiled, one pair at a time, for
the pair and its reverse (the small eigenvalues from the reverse pair's large ones).

The sorted log-eigenvalues are also a lower bound: ``||log lambda(A) - log lambda(B)||``
is at most ``dist(A, B)`` (the sorted log-spectrum is 1-Lipschitz for the
affine-invariant metric: Bhatia, *Positive Definite Matrices*, 2007, Thm 6.1.4 with the
Hoffman-Wielandt inequality), so LB_Keogh over those coordinates bounds DTW from below.

A flat SPD(k) point is ``k * k`` row-major entries; its features are, in order, the ``k``
ascending log-eigenvalues, the ``k (k + 1) / 2`` entries of ``L^-1`` row by row (lower
triangle) and the ``k (k + 1) / 2`` entries of the point row by row (upper triangle).

The functions here are inlined into the DTW kernels (:mod:`sk_rtw.dtw._kernels` and
the modules beside it, through :mod:`._point_kernels`), whose numba cache does not follow
a change in this module by itself: :mod:`sk_rtw.dtw._point_costs` drops the DTW
package's cached kernels when this file (or the table, or the sphere's kernels) is newer
(:func:`sk_rtw._numba_cache.drop_stale_caches`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: Largest matrix size with a kernel form. Up to it, a pair's eigenvalues by Householder
#: tridiagonalisation and implicit QL in compiled code beat a batched LAPACK call per
#: pair (whose overhead dominates at this size); beyond it LAPACK's blocked code wins.
MAX_KERNEL_SIZE = 12
_TWO_THIRDS_PI = 2.0 * math.pi / 3.0


def feature_width(k: int) -> int:
    """Number of features of an SPD(k) point: ``k`` log-eigenvalues and two triangles."""
    return k * (k + 2)


@njit(cache=True, nogil=True, inline="always")
def _eigenvalues2(a, b, c):
    """Eigenvalues ``(small, large)`` of ``[[a, b], [b, c]]`` (positive definite): the
    large one from the quadratic (no cancellation), the small one from the determinant."""
    mean = 0.5 * (a + c)
    radius = math.hypot(0.5 * (a - c), b)
    large = mean + radius
    return (a * c - b * b) / large, large


@njit(cache=True, nogil=True, inline="always")
def _trigonometric3(m11, m12, m13, m22, m23, m33):
    """``(q, p, phi)`` of the trigonometric solution of the characteristic cubic of a
    symmetric 3 x 3 matrix (Smith 1961): its eigenvalues are ``q + 2 p cos(phi + 2 pi
    j / 3)``, ``j = 0, 1, 2``, the largest at ``j = 0`` (``cos(phi) >= 1/2``)."""
    q = (m11 + m22 + m33) / 3.0
    d11, d22, d33 = m11 - q, m22 - q, m33 - q
    p2 = d11 * d11 + d22 * d22 + d33 * d33 + 2.0 * (m12 * m12 + m13 * m13 + m23 * m23)
    if p2 == 0.0:  # a multiple of the identity
        return q, 0.0, 0.0
    p = math.sqrt(p2 / 6.0)
    det = (
        d11 * (d22 * d33 - m23 * m23)
        - m12 * (m12 * d33 - m23 * m13)
        + m13 * (m12 * m23 - d22 * m13)
    )
    r = min(1.0, max(-1.0, 0.5 * det / (p * p * p)))  # det((M - q I) / p) / 2
    return q, p, math.acos(r) / 3.0


@njit(cache=True, nogil=True, inline="always")
def _largest3(m11, m12, m13, m22, m23, m33):
    """Largest eigenvalue of a symmetric positive definite 3 x 3 matrix: ``q + 2 p
    cos(phi)`` of :func:`_trigonometric3`, a sum of positive terms."""
    q, p, phi = _trigonometric3(m11, m12, m13, m22, m23, m33)
    return q + 2.0 * p * math.cos(phi)


@njit(cache=True, nogil=True, inline="always")
def _congruence3(i11, i21, i22, i31, i32, i33, b11, b12, b13, b22, b23, b33):
    """Upper triangle of ``L^-1 B L^-T`` for a lower-triangular ``L^-1`` (rows) and a
    symmetric ``B``."""
    n11, n12, n13 = i11 * b11, i11 * b12, i11 * b13  # N = L^-1 B, row by row
    n21 = i21 * b11 + i22 * b12
    n22 = i21 * b12 + i22 * b22
    n23 = i21 * b13 + i22 * b23
    n31 = i31 * b11 + i32 * b12 + i33 * b13
    n32 = i31 * b12 + i32 * b22 + i33 * b23
    n33 = i31 * b13 + i32 * b23 + i33 * b33
    return (
        n11 * i11,
        n11 * i21 + n12 * i22,
        n11 * i31 + n12 * i32 + n13 * i33,
        n21 * i21 + n22 * i22,
        n21 * i31 + n22 * i32 + n23 * i33,
        n31 * i31 + n32 * i32 + n33 * i33,
    )


@njit(cache=True, nogil=True, inline="always")
def _pair_largest3(x, y, s):
    """Largest generalized eigenvalue of ``(B, A)``, ``A`` the point of ``x`` and ``B``
    the point of ``y`` whose features start at ``s``."""
    m11, m12, m13, m22, m23, m33 = _congruence3(
        x[s + 3], x[s + 4], x[s + 5], x[s + 6], x[s + 7], x[s + 8],
        y[s + 9], y[s + 10], y[s + 11], y[s + 12], y[s + 13], y[s + 14],
    )  # fmt: skip
    return _largest3(m11, m12, m13, m22, m23, m33)


@njit(cache=True, nogil=True, error_model="numpy")
def spd_features(points, k):
    """The features (module docstring) of flat SPD(k) points ``(n, k * k)``, ``2 <= k <=
    MAX_KERNEL_SIZE``; not finite for a point that is not positive definite in float64."""
    n = points.shape[0]
    out = np.empty((n, k * (k + 2)))
    if k > 3:
        _general_features(points, k, out)
        _diagonal_log_eigenvalues(points, k, out)
        return out
    for t in range(n):
        x = points[t]
        f = out[t]
        if k == 2:
            a, b, c = x[0], 0.5 * (x[1] + x[2]), x[3]
            small, large = _eigenvalues2(a, b, c)
            f[0], f[1] = math.log(small), math.log(large)
            l11 = math.sqrt(a)
            l21 = b / l11
            l22 = math.sqrt(small * large / a)  # c - b^2 / a without its cancellation
            f[2] = 1.0 / l11
            f[3] = -l21 / (l11 * l22)
            f[4] = 1.0 / l22
            f[5], f[6], f[7] = a, b, c
        else:
            a11, a22, a33 = x[0], x[4], x[8]
            a12 = 0.5 * (x[1] + x[3])
            a13 = 0.5 * (x[2] + x[6])
            a23 = 0.5 * (x[5] + x[7])
            l11 = math.sqrt(a11)
            l21 = a12 / l11
            l31 = a13 / l11
            l22 = math.sqrt(a22 - l21 * l21)
            l32 = (a23 - l31 * l21) / l22
            l33 = math.sqrt(a33 - l31 * l31 - l32 * l32)
            i11, i22, i33 = 1.0 / l11, 1.0 / l22, 1.0 / l33  # L^-1, row by row
            i21 = -l21 * i11 * i22
            i32 = -l32 * i22 * i33
            i31 = -(l31 * i11 + l32 * i21) * i33
            f[3], f[4], f[5], f[6], f[7], f[8] = i11, i21, i22, i31, i32, i33
            # the largest eigenvalue of A and of A^-1 = L^-T L^-1, the middle one from
            # the determinant
            f[2] = math.log(_largest3(a11, a12, a13, a22, a23, a33))
            f[0] = -math.log(_largest3(
                i11 * i11 + i21 * i21 + i31 * i31, i21 * i22 + i31 * i32, i31 * i33,
                i22 * i22 + i32 * i32, i32 * i33, i33 * i33,
            ))  # fmt: skip
            log_det = 2.0 * (math.log(l11) + math.log(l22) + math.log(l33))
            f[1] = log_det - f[0] - f[2]
            f[9], f[10], f[11], f[12], f[13], f[14] = a11, a12, a13, a22, a23, a33
    _diagonal_log_eigenvalues(points, k, out)
    return out


@njit(cache=True, nogil=True, error_model="numpy")
def _diagonal_log_eigenvalues(points, k, out):
    """The log-eigenvalues of diagonal points from their entries, sorted: exact at any
    spread (the formulas above square the entries, which overflows beyond 1e+-154)."""
    logs = np.empty(k)
    for t in range(points.shape[0]):
        diagonal = True
        for i in range(k):
            for j in range(k):
                if i != j and points[t, i * k + j] != 0.0:
                    diagonal = False
        if not diagonal:
            continue
        for i in range(k):
            value = points[t, i * k + i]
            logs[i] = math.log(value) if value > 0.0 else np.nan
        logs.sort()
        for i in range(k):
            out[t, i] = logs[i]


@njit(cache=True, nogil=True, inline="always")
def spd_log_eigenvalues2(x, y, s):
    """Log generalized eigenvalues ``(large, small)`` of the pair of 2 x 2 points whose
    features start at ``s`` in ``x`` and ``y``."""
    p, q, r = x[s + 2], x[s + 3], x[s + 4]
    e, f, g = y[s + 5], y[s + 6], y[s + 7]
    m11 = p * p * e
    m12 = p * (q * e + r * f)
    m22 = q * q * e + 2.0 * q * r * f + r * r * g
    half_gap = 0.5 * (m11 - m22)
    large = 0.5 * (m11 + m22) + math.sqrt(half_gap * half_gap + m12 * m12)
    log_large = math.log(large)
    log_det = (y[s] + y[s + 1]) - (x[s] + x[s + 1])
    return log_large, log_det - log_large


@njit(cache=True, nogil=True, inline="always")
def spd_log_eigenvalues3(x, y, s):
    """Log generalized eigenvalues ``(large, middle, small)`` of the pair of 3 x 3 points
    whose features start at ``s`` in ``x`` and ``y``: the largest and the smallest of
    ``(B, A)`` from one trigonometric solution, the middle one from the determinant.

    The smallest, ``q + 2 p cos(phi + 2 pi / 3)``, is a difference: it keeps its relative
    accuracy (to ``eps * large / small``) while it is above ``large / 100``; below, it is
    taken as the inverse of the largest of the reverse pair ``(A, B)`` instead (a sum).
    Where the two smaller eigenvalues nearly meet, ``phi`` carries an error of order
    ``sqrt(eps)`` that moves them in opposite directions with their product fixed: the
    squared distance changes only to second order.
    """
    m11, m12, m13, m22, m23, m33 = _congruence3(
        x[s + 3], x[s + 4], x[s + 5], x[s + 6], x[s + 7], x[s + 8],
        y[s + 9], y[s + 10], y[s + 11], y[s + 12], y[s + 13], y[s + 14],
    )  # fmt: skip
    q, p, phi = _trigonometric3(m11, m12, m13, m22, m23, m33)
    large = q + 2.0 * p * math.cos(phi)
    small = q + 2.0 * p * math.cos(phi + _TWO_THIRDS_PI)
    log_large = math.log(large)
    if small > 0.01 * large:
        log_small = math.log(small)
    else:
        log_small = -math.log(_pair_largest3(y, x, s))
    log_det = (y[s] + y[s + 1] + y[s + 2]) - (x[s] + x[s + 1] + x[s + 2])
    return log_large, log_det - log_large - log_small, log_small


@njit(cache=True, nogil=True, inline="always")
def spd_squared_distance(x, y, s, k):
    """Squared affine-invariant distance of the SPD(k) points whose features start at ``s``."""
    diagonal = _diagonal_squared_distance(x, y, s, k)
    if diagonal >= 0.0:
        return diagonal
    if k == 2:
        u, v = spd_log_eigenvalues2(x, y, s)
        return u * u + v * v
    if k == 3:
        u, v, w = spd_log_eigenvalues3(x, y, s)
        return u * u + v * v + w * w
    return _general_squared_distance(x, y, s, k)


@njit(cache=True, nogil=True, inline="always")
def _diagonal_squared_distance(x, y, s, k):
    """``sum (log y_ii - log x_ii)^2`` where both points are diagonal, else -1: the
    log-ratios of their entries without the ratios, which over- or underflow (and the
    congruence's products with them) for entries beyond 1e+-77; the same value as the
    other routes elsewhere."""
    point = s + k + k * (k + 1) // 2
    index = point
    for i in range(k):
        for _ in range(i + 1, k):
            index += 1
            if x[index] != 0.0 or y[index] != 0.0:
                return -1.0
        index += 1
    total = 0.0
    index = point
    for i in range(k):
        gap = math.log(y[index]) - math.log(x[index])
        total += gap * gap
        index += k - i
    return total


# ---------------------------------------------------------------- k = 4 .. MAX_KERNEL_SIZE
@njit(cache=True, nogil=True, error_model="numpy")
def _general_features(points, k, out):
    """:func:`spd_features` for ``k > 3``: the Cholesky factor's inverse by forward
    substitution, the log-eigenvalues by :func:`_symmetric_eigenvalues`."""
    work, A, L = np.empty((k, k)), np.empty((k, k)), np.empty((k, k))
    diagonal, off = np.empty(k), np.empty(k)
    inverse_start, point_start = k, k + k * (k + 1) // 2
    for t in range(points.shape[0]):
        f = out[t]
        for i in range(k):
            for j in range(k):
                A[i, j] = 0.5 * (points[t, i * k + j] + points[t, j * k + i])
        # Cholesky, lower triangle (the only one read); NaN when not positive definite
        for j in range(k):
            total = A[j, j]
            for m in range(j):
                total -= L[j, m] * L[j, m]
            L[j, j] = math.sqrt(total) if total > 0.0 else np.nan
            for i in range(j + 1, k):
                total = A[i, j]
                for m in range(j):
                    total -= L[i, m] * L[j, m]
                L[i, j] = total / L[j, j]
        index = inverse_start
        for i in range(k):  # row i of L^-1 (lower triangle)
            for j in range(i + 1):
                if i == j:
                    value = 1.0 / L[i, i]
                else:
                    total = 0.0
                    for m in range(j, i):
                        total += L[i, m] * f[inverse_start + m * (m + 1) // 2 + j]
                    value = -total / L[i, i]
                f[index] = value
                index += 1
        for i in range(k):
            for j in range(i + 1):
                work[i, j] = A[i, j]
        _symmetric_eigenvalues(work, k, diagonal, off)
        diagonal.sort()
        for i in range(k):
            f[i] = math.log(diagonal[i]) if diagonal[i] > 0.0 else np.nan
        index = point_start
        for i in range(k):
            for j in range(i, k):
                f[index] = A[i, j]
                index += 1


@njit(cache=True, nogil=True, error_model="numpy")
def _general_squared_distance(x, y, s, k):
    """``sum log(lambda)^2`` over the generalized eigenvalues of ``(B, A)``, each from the
    side that holds it accurately: the eigenvalues of ``L_A^-1 B L_A^-T`` carry absolute
    errors of about ``eps`` times the largest, so only its large ones are accurate; the
    reverse pair's (``L_B^-1 A L_B^-T``, the inverses) give the small ones. Each
    log-eigenvalue is taken from the side where it lies on the large half of the
    log-spectrum (the middle from the two accurate ends), as 2 x 2 and 3 x 3 take the
    smallest from the reverse pair."""
    work = np.empty(3 * k * k + 4 * k)  # one allocation per pair
    forward, reverse = work[3 * k * k + 2 * k : 3 * k * k + 3 * k], work[3 * k * k + 3 * k :]
    _congruence_eigenvalues(x, y, s, k, work, forward)
    _congruence_eigenvalues(y, x, s, k, work, reverse)
    forward.sort()
    reverse.sort()
    # log lambda_i from the forward side, or -log of the reverse side's (k - 1 - i)-th
    middle = 0.5 * (_safe_log(forward[k - 1]) - _safe_log(reverse[k - 1]))
    total = 0.0
    for i in range(k):
        value = _safe_log(forward[i])
        if value < middle:
            value = -_safe_log(reverse[k - 1 - i])
        total += value * value
    return total


@njit(cache=True, nogil=True, inline="always")
def _safe_log(value):
    """``log(value)``, -inf at or below 0 (an eigenvalue lost to rounding: the other side
    holds it)."""
    return math.log(value) if value > 0.0 else -np.inf


@njit(cache=True, nogil=True, error_model="numpy")
def _congruence_eigenvalues(x, y, s, k, work, out):
    """The eigenvalues (unordered) of ``L^-1 B L^-T`` into ``out``, ``L^-1`` from the
    features of ``x`` and ``B`` from those of ``y`` (lower triangle formed, then
    :func:`_symmetric_eigenvalues`); ``work`` holds at least ``3 k^2 + 2 k`` numbers."""
    inverse = s + k
    point = inverse + k * (k + 1) // 2
    B = work[: k * k].reshape(k, k)
    N = work[k * k : 2 * k * k].reshape(k, k)  # L^-1 B, row by row
    M = work[2 * k * k : 3 * k * k].reshape(k, k)  # the lower triangle of N L^-T
    off = work[3 * k * k : 3 * k * k + k]
    index = point
    for i in range(k):
        for j in range(i, k):
            B[i, j] = y[index]
            B[j, i] = y[index]
            index += 1
    for i in range(k):
        row = inverse + i * (i + 1) // 2
        for j in range(k):
            total = 0.0
            for m in range(i + 1):
                total += x[row + m] * B[m, j]
            N[i, j] = total
    for i in range(k):
        for j in range(i + 1):
            row = inverse + j * (j + 1) // 2
            total = 0.0
            for m in range(j + 1):
                total += N[i, m] * x[row + m]
            M[i, j] = total
    _symmetric_eigenvalues(M, k, out, off)


@njit(cache=True, nogil=True, error_model="numpy")
def _symmetric_eigenvalues(a, n, d, e):
    """The eigenvalues, into ``d`` (unordered), of the symmetric matrix whose lower triangle is
    ``a`` (overwritten; ``e`` is scratch): Householder reduction to tridiagonal form and
    the implicit QL iteration with Wilkinson shifts (eigenvalues only: Press et al.,
    *Numerical Recipes*, 3rd ed., sections 11.3-11.4, ``tred2`` and ``tqli``)."""
    for i in range(n - 1, 0, -1):
        last = i - 1
        h = 0.0
        if last > 0:
            scale = 0.0
            for m in range(last + 1):
                scale += abs(a[i, m])
            if scale == 0.0:
                e[i] = a[i, last]
            else:
                for m in range(last + 1):
                    a[i, m] /= scale
                    h += a[i, m] * a[i, m]
                f = a[i, last]
                g = -math.sqrt(h) if f >= 0.0 else math.sqrt(h)
                e[i] = scale * g
                h -= f * g
                a[i, last] = f - g
                f = 0.0
                for j in range(last + 1):
                    g = 0.0
                    for m in range(j + 1):
                        g += a[j, m] * a[i, m]
                    for m in range(j + 1, last + 1):
                        g += a[m, j] * a[i, m]
                    e[j] = g / h
                    f += e[j] * a[i, j]
                hh = f / (h + h)
                for j in range(last + 1):
                    f = a[i, j]
                    g = e[j] - hh * f
                    e[j] = g
                    for m in range(j + 1):
                        a[j, m] -= f * e[m] + g * a[i, m]
        else:
            e[i] = a[i, last]
    for i in range(n):
        d[i] = a[i, i]
    for i in range(1, n):
        e[i - 1] = e[i]
    e[n - 1] = 0.0
    for start in range(n):
        for _ in range(64):
            m = start
            while m < n - 1:
                dd = abs(d[m]) + abs(d[m + 1])
                if abs(e[m]) <= 2.220446049250313e-16 * dd:
                    break
                m += 1
            if m == start:
                break
            g = (d[start + 1] - d[start]) / (2.0 * e[start])
            r = math.sqrt(g * g + 1.0)
            g = d[m] - d[start] + e[start] / (g + (r if g >= 0.0 else -r))
            s, c, p = 1.0, 1.0, 0.0
            i = m - 1
            deflated = False
            while i >= start:
                f = s * e[i]
                b = c * e[i]
                r = math.sqrt(f * f + g * g)
                e[i + 1] = r
                if r == 0.0:
                    d[i + 1] -= p
                    e[m] = 0.0
                    deflated = True
                    break
                s = f / r
                c = g / r
                g = d[i + 1] - p
                r = (d[i] - g) * s + 2.0 * c * b
                p = s * r
                d[i + 1] = g + p
                g = c * r - b
                i -= 1
            if deflated:
                continue
            d[start] -= p
            e[start] = g
            e[m] = 0.0
