"""CPU kernels of the sphere's closed forms (:mod:`sk_rtw.manifolds._sphere`): ``Log_p(x)``,
``Exp_p(v)`` and ``dist(p, x)`` of ``S^d`` and of the unit quaternions, one compiled pass
per batch, and their gradients in another, so that a training epoch records one autograd
node per map instead of some fifteen elementwise ones (each a pass over ``N Z (d + 1)``
doubles: on long demonstrations the maps were two fifths of an epoch).

Rows are ``(n, k)`` float64 arrays (``k = d + 1``). The formulas, branches and series are
those of the torch functions, which stay the reference and the path on other devices and
dtypes; the gradients are their chain rule written out. With ``c = <p, x>``,
``u = x - c p``, ``s = |u|`` and a scalar function ``f(s, c)`` of the map, every gradient
has the form

- ``grad_x = h + beta p`` and ``grad_p = -c h + beta x``, where ``h`` is the coefficient
  of ``du`` and ``beta = alpha - <h, p>`` that of ``dc = <x, dp> + <p, dx>``,

from ``du = dx - c dp - p dc``. ``Log``: ``v = f u`` with ``f = atan2(s, c) / s`` (``1 +
s^2 / 6`` below the series threshold, where ``c > 0``); at the cut locus (``s`` at the
threshold's level and ``c < 0``) the fixed direction of :func:`_sphere._antipodal_direction`,
whose gradient in ``p`` is written out too. The quaternion's sign-invariant maps read ``x``
in the hemisphere of ``p`` (``x -> -x`` where ``c < 0``, ``grad_x`` signed back).
"""

from __future__ import annotations

import math

from numba import njit, prange

from .._numba import launch_rows, row_builds

#: The torch formulas' series threshold on squared norms.
_TAYLOR_SQ = 1e-12
#: The torch formulas' floor on ``s^2`` before its square root (``Log``).
_SQ_FLOOR = 1e-300
#: Rows from which the multi-threaded builds are used (fewer: threads cost more than they
#: save and compete with torch's own pool during an epoch).
PARALLEL_ROWS = 200_000

_OPTIONS = {"cache": True, "nogil": True, "error_model": "numpy"}


@njit(inline="always", **_OPTIONS)
def _dot(a, b, i):  # pragma: no cover
    total = 0.0
    for j in range(a.shape[1]):
        total += a[i, j] * b[i, j]
    return total


@njit(inline="always", **_OPTIONS)
def _tangent(P, X, i, sign_invariant):  # pragma: no cover
    """``(c, sign, s^2)``: ``c = <p, sign x>``, the sign that puts ``x`` in the hemisphere
    of ``p`` (1 unless ``sign_invariant``) and the squared norm of ``sign x - c p``."""
    c = _dot(P, X, i)
    sign = 1.0
    if sign_invariant and c < 0.0:
        sign, c = -1.0, -c
    sq = 0.0
    for j in range(P.shape[1]):
        u = sign * X[i, j] - c * P[i, j]
        sq += u * u
    return c, sign, sq


@njit(inline="always", **_OPTIONS)
def _least_axis(P, i):  # pragma: no cover
    """Index of the coordinate of ``p`` smallest in magnitude (the first of equals, as
    ``torch.argmin``), the axis of the cut-locus direction."""
    best, axis = abs(P[i, 0]), 0
    for j in range(1, P.shape[1]):
        if abs(P[i, j]) < best:
            best, axis = abs(P[i, j]), j
    return axis


def _log_rows(P, X, out, sign_invariant):  # pragma: no cover
    for i in prange(P.shape[0]):
        c, sign, sq = _tangent(P, X, i, sign_invariant)
        if sq < _TAYLOR_SQ and c < 0.0:  # cut locus: pi along the fixed direction
            axis = _least_axis(P, i)
            pj = P[i, axis]
            norm = math.sqrt(max(1.0 - 2.0 * pj * pj + pj * pj * _dot(P, P, i), 0.0))
            for j in range(P.shape[1]):
                out[i, j] = -math.pi * pj * P[i, j] / norm
            out[i, axis] += math.pi / norm
            continue
        if sq < _TAYLOR_SQ and c > 0.0:
            factor = 1.0 + sq / 6.0
        else:
            s = math.sqrt(max(sq, _SQ_FLOOR))
            factor = math.atan2(s, c) / s
        for j in range(P.shape[1]):
            out[i, j] = factor * (sign * X[i, j] - c * P[i, j])


def _log_backward_rows(P, X, grad, gp, gx, sign_invariant):  # pragma: no cover
    k = P.shape[1]
    for i in prange(P.shape[0]):
        c, sign, sq = _tangent(P, X, i, sign_invariant)
        if sq < _TAYLOR_SQ and c < 0.0:  # d = a / |a|, a = e_axis - p_axis p: only p moves
            axis = _least_axis(P, i)
            pj = P[i, axis]
            norm = math.sqrt(max(1.0 - 2.0 * pj * pj + pj * pj * _dot(P, P, i), 0.0))
            along = -pj * _dot(grad, P, i) + grad[i, axis]  # <g, a>
            # w = (g - <d, g> d) / |a|; grad_p = pi (-p_axis w - <w, p> e_axis)
            w_dot_p = 0.0
            for j in range(k):
                a = -pj * P[i, j] + (1.0 if j == axis else 0.0)
                w = (grad[i, j] - along * a / (norm * norm)) / norm
                gp[i, j] = -math.pi * pj * w
                w_dot_p += w * P[i, j]
                gx[i, j] = 0.0
            gp[i, axis] -= math.pi * w_dot_p
            continue
        g_u = 0.0  # <g, u>
        for j in range(k):
            g_u += grad[i, j] * (sign * X[i, j] - c * P[i, j])
        if sq < _TAYLOR_SQ and c > 0.0:
            factor, u_coef, alpha = 1.0 + sq / 6.0, g_u / 3.0, 0.0
        else:
            s2 = max(sq, _SQ_FLOOR)
            s = math.sqrt(s2)
            theta = math.atan2(s, c)
            r2 = s2 + c * c
            factor = theta / s
            # f_s / s with f = theta / s (zero where the floor holds s^2 fixed)
            u_coef = g_u * (c / (r2 * s) - theta / s2) / s if sq > _SQ_FLOOR else 0.0
            alpha = -g_u / r2
        h_p = 0.0  # <h, p>, h = u_coef u + factor g
        for j in range(k):
            h_p += (u_coef * (sign * X[i, j] - c * P[i, j]) + factor * grad[i, j]) * P[i, j]
        beta = alpha - h_p
        for j in range(k):
            h = u_coef * (sign * X[i, j] - c * P[i, j]) + factor * grad[i, j]
            gx[i, j] = sign * (h + beta * P[i, j])
            gp[i, j] = -c * h + beta * sign * X[i, j]


@njit(inline="always", **_OPTIONS)
def _exp_coefficients(sq):  # pragma: no cover
    """``(cos |v|, sin |v| / |v|)`` and the derivatives of both in ``<v, dv>``."""
    if sq < _TAYLOR_SQ:
        cos = 1.0 - sq / 2.0 + sq * sq / 24.0
        sinc = 1.0 - sq / 6.0 + sq * sq / 120.0
        return cos, sinc, -1.0 + sq / 6.0, -1.0 / 3.0 + sq / 30.0
    n = math.sqrt(sq)
    cos = math.cos(n)
    sinc = math.sin(n) / n
    return cos, sinc, -sinc, (cos - sinc) / sq


def _exp_rows(P, V, out):  # pragma: no cover
    for i in prange(P.shape[0]):
        cos, sinc, _, _ = _exp_coefficients(_dot(V, V, i))
        for j in range(P.shape[1]):
            out[i, j] = cos * P[i, j] + sinc * V[i, j]


def _exp_backward_rows(P, V, grad, gp, gv):  # pragma: no cover
    for i in prange(P.shape[0]):
        cos, sinc, cos_v, sinc_v = _exp_coefficients(_dot(V, V, i))
        coef = _dot(grad, P, i) * cos_v + _dot(grad, V, i) * sinc_v
        for j in range(P.shape[1]):
            gp[i, j] = cos * grad[i, j]
            gv[i, j] = sinc * grad[i, j] + coef * V[i, j]


@njit(cache=True, nogil=True, inline="always")
def angle(p, X, j, start, stop, sign_invariant):  # pragma: no cover
    """The geodesic distance between the unit vectors ``p[start:stop]`` (a 1-D array)
    and ``x = X[j, start:stop]`` (a row of a 2-D array, read in place):
    ``atan2(|x - c p|, c)`` with ``c = <p, x>`` (``|c|`` for the sign-invariant distance
    of unit quaternions), the torch formula's. The one compiled form of the sphere's
    distance: :func:`_dist_rows` and the DTW point costs (:mod:`._point_kernels`) both
    call it."""
    c = 0.0
    for k in range(start, stop):
        c += p[k] * X[j, k]
    sq = 0.0
    for k in range(start, stop):
        u = X[j, k] - c * p[k]
        sq += u * u
    return math.atan2(math.sqrt(sq), abs(c) if sign_invariant else c)


@njit(inline="always", **_OPTIONS)
def _dist_terms(P, X, i, sign_invariant):  # pragma: no cover
    """``(c, |c| or c, s^2)`` of the torch formula (``u`` with the signed ``c``)."""
    c = _dot(P, X, i)
    sq = 0.0
    for j in range(P.shape[1]):
        u = X[i, j] - c * P[i, j]
        sq += u * u
    return c, (abs(c) if sign_invariant else c), sq


def _dist_rows(P, X, out, sign_invariant):  # pragma: no cover
    k = P.shape[1]
    for i in prange(P.shape[0]):
        out[i] = angle(P[i], X, i, 0, k, sign_invariant)


def _dist_backward_rows(P, X, grad, gp, gx, sign_invariant):  # pragma: no cover
    k = P.shape[1]
    for i in prange(P.shape[0]):
        c, cc, sq = _dist_terms(P, X, i, sign_invariant)
        s = math.sqrt(sq) if sq > 0.0 else sq * 0.0
        r2 = sq + cc * cc
        u_coef = grad[i] * cc / (r2 * s) if sq > 0.0 else 0.0
        slope = 1.0
        if sign_invariant:
            slope = 1.0 if c > 0.0 else (-1.0 if c < 0.0 else 0.0)
        alpha = -grad[i] * s * slope / r2
        h_p = 0.0
        for j in range(k):
            h_p += u_coef * (X[i, j] - c * P[i, j]) * P[i, j]
        beta = alpha - h_p
        for j in range(k):
            h = u_coef * (X[i, j] - c * P[i, j])
            gx[i, j] = h + beta * P[i, j]
            gp[i, j] = -c * h + beta * X[i, j]


_KERNELS = row_builds(
    {
        "log": _log_rows,
        "exp": _exp_rows,
        "dist": _dist_rows,
        "log_backward": _log_backward_rows,
        "exp_backward": _exp_backward_rows,
        "dist_backward": _dist_backward_rows,
    },
    **_OPTIONS,
)


def run(name: str, *arrays) -> None:
    """Launch kernel ``name`` on its arguments (row arrays first), threaded from
    :data:`PARALLEL_ROWS` rows when the fit allows more than one thread."""
    launch_rows(_KERNELS, name, PARALLEL_ROWS, *arrays)
