"""CPU kernels of the SPD(2) closed forms (:mod:`sk_rtw.manifolds._spd2`): ``Log_P(X)``,
``Exp_P(V)`` and ``dist(P, X)`` in one compiled pass per batch, and their gradients in
another, so that a training epoch records one autograd node per map instead of some sixty
elementwise ones.

Points and tangent vectors travel as ``(n, 2, 2)`` arrays, read as their three entries
``(a, b, c)`` of ``[[a, b], [b, c]]`` (``b`` from the symmetric part). Every map is a
function of the mean eigenvalue ``m`` and the determinant ``delta`` of ``M = P^-1 X``, and
of ``P`` and ``X`` themselves (``f(M) = a I + b M``, so ``P f(M) = a P + b X``), with the
same branches, series and deflations as the torch formulas, which stay the reference and
the path on other devices and dtypes. The gradients are the chain rule through ``(m, delta)``:

- ``m = tr(P^-1 X) / 2``, ``delta = det X / det P``, whose partial derivatives in the six
  entries are rational in them;
- the coefficients ``F = f_mean`` and ``B = b`` of the map as functions of
  ``(m, q = m^2 - delta)``: ``B_m = -1 / delta`` for ``f = log`` and ``B_m = B`` for
  ``f = exp``, and ``B_q``, which the kernels evaluate from its series where ``q`` is
  small against ``m^2`` (``log``) or ``1`` (``exp``), where the direct formula cancels.

The saved quantities per row are ``(a, B, m, delta, B_q)`` (the distance saves its own
partial derivatives); the backward kernels recompute the rest from the entries. A second
derivative (``create_graph=True``) differentiates the torch formulas instead
(:class:`sk_rtw.manifolds._spd2._KernelMap`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from .._numba import launch_rows, row_builds

_EPS = 2.220446049250313e-16
#: The torch formulas' series threshold (values): below it the even functions of ``r``
#: are evaluated from their series.
_SERIES_BELOW = 1e-6
#: Below this ``q / m^2`` (``log``) or ``q`` (``exp``) ``B_q`` is taken from its series
#: (four or five terms: error under 1e-15 relative); above it the direct formula loses at most
#: three digits to cancellation.
_GRADIENT_SERIES_BELOW = 1e-3
#: Rows from which the multi-threaded builds are used (fewer: threads cost more than they
#: save and compete with torch's own pool during an epoch).
PARALLEL_ROWS = 200_000
#: Saved quantities per row: ``a, B, m, delta, B_q``.
N_SAVED = 5

_OPTIONS = {"cache": True, "nogil": True, "error_model": "numpy"}


@njit(inline="always", **_OPTIONS)
def _congruence(pa, pb, pc, xa, xb, xc):  # pragma: no cover
    """``(m, q, xb, det P)``: mean eigenvalue and half-gap squared of ``P^-1 X``, from the
    congruence ``W = L^-1 X L^-T`` (``P = L L^T``) written out without its square roots
    (``w00 = xa / pa``, ``w11 = (pb^2 xa / pa - 2 pb xb + pa xc) / det P``,
    ``w01^2 = (xb - pb xa / pa)^2 / det P``), with :func:`_spd2._congruence`'s deflations:
    a rounding-level off-diagonal entry (``xb`` replaced by ``b/a xa``), a rounding-level
    gap (``q`` from the off-diagonal part only)."""
    det_p = pa * pc - pb * pb
    ratio = pb / pa
    w00 = xa / pa
    w11 = (ratio * pb * xa - 2.0 * pb * xb + pa * xc) / det_p
    off = xb - ratio * xa
    w01_squared = off * off / det_p
    if w01_squared <= _EPS * _EPS * abs(w00 * w11):
        w01_squared = 0.0
        xb = ratio * xa
    mean = 0.5 * (w00 + w11)
    half_gap = 0.5 * (w00 - w11)
    if abs(half_gap) <= _EPS * abs(mean):
        half_gap = 0.0
    return mean, half_gap * half_gap + w01_squared, xb, det_p


@njit(inline="always", **_OPTIONS)
def _log_slope(m, q, log_det, delta):  # pragma: no cover
    """``(B, B_q)`` of ``f = log``: ``B = atanh(r / m) / r`` and its ``q``-derivative."""
    x = q / (m * m)
    if x < _SERIES_BELOW:
        slope = (1.0 + x * (1.0 / 3.0 + x / 5.0)) / m
        r = 0.0
        ratio = 0.0
    else:
        r = math.sqrt(q)
        y = r / m
        ratio = math.log(m + r) - 0.5 * log_det if y >= 0.5 else math.atanh(y)
        slope = ratio / r
    if x < _GRADIENT_SERIES_BELOW:
        series = 1.0 / 3.0 + x * (2.0 / 5.0 + x * (3.0 / 7.0 + x * (4.0 / 9.0 + x * 5.0 / 11.0)))
        slope_q = series / (m * m * m)
    else:
        slope_q = (r * m / delta - ratio) / (2.0 * q * r)
    return slope, slope_q


@njit(inline="always", **_OPTIONS)
def _exp_coefficients(m, q):  # pragma: no cover
    """``(F, B, B_q)`` of ``f = exp``: ``e^m cosh r``, ``e^m sinh(r) / r``, and ``B``'s
    ``q``-derivative ``e^m (r cosh r - sinh r) / (2 r^3)``."""
    scale = math.exp(m)
    if q < _SERIES_BELOW:
        cosh = 1.0 + q * (0.5 + q / 24.0)
        sinhc = 1.0 + q * (1.0 / 6.0 + q / 120.0)
    else:
        r = math.sqrt(q)
        cosh = math.cosh(r)
        sinhc = math.sinh(r) / r
    if q < _GRADIENT_SERIES_BELOW:
        series = 1.0 / 3.0 + q * (1.0 / 30.0 + q * (1.0 / 840.0 + q / 45360.0))
    else:
        series = (cosh - sinhc) / q  # (r cosh r - sinh r) / r^3
    return scale * cosh, scale * sinhc, 0.5 * scale * series


@njit(inline="always", **_OPTIONS)
def _entries(S, i):  # pragma: no cover
    """``a, b, c`` of matrix ``i`` (``b`` from its symmetric part)."""
    return S[i, 0, 0], 0.5 * (S[i, 0, 1] + S[i, 1, 0]), S[i, 1, 1]


@njit(inline="always", **_OPTIONS)
def _store(out, i, a, b, c):  # pragma: no cover
    out[i, 0, 0] = a
    out[i, 0, 1] = b
    out[i, 1, 0] = b
    out[i, 1, 1] = c


@njit(inline="always", **_OPTIONS)
def _log_terms(P, X, i):  # pragma: no cover
    """What ``Log`` and the distance of pair ``i`` share: the entries (``xb`` deflated),
    ``m``, ``q``, ``delta``, ``log(delta)``, ``B`` and ``B_q``, in one flat tuple (numba's
    parallel array analysis fails on a nested one unpacked inside a ``prange`` loop)."""
    pa, pb, pc = _entries(P, i)
    xa, xb, xc = _entries(X, i)
    m, q, xb, det_p = _congruence(pa, pb, pc, xa, xb, xc)
    delta = (xa * xc - xb * xb) / det_p
    log_det = math.log(delta)
    slope, slope_q = _log_slope(m, q, log_det, delta)
    return pa, pb, pc, xa, xb, xc, m, q, delta, log_det, slope, slope_q


def _log_rows(P, X, out, saved, save):  # pragma: no cover
    for i in prange(P.shape[0]):
        pa, pb, pc, xa, xb, xc, m, _, delta, log_det, slope, slope_q = _log_terms(P, X, i)
        a = 0.5 * log_det - slope * m
        _store(out, i, a * pa + slope * xa, a * pb + slope * xb, a * pc + slope * xc)
        if save:
            saved[i, 0], saved[i, 1], saved[i, 2] = a, slope, m
            saved[i, 3], saved[i, 4] = delta, slope_q


def _exp_rows(P, V, out, saved, save):  # pragma: no cover
    for i in prange(P.shape[0]):
        pa, pb, pc = _entries(P, i)
        va, vb, vc = _entries(V, i)
        m, q, vb, det_p = _congruence(pa, pb, pc, va, vb, vc)
        mean_value, slope, slope_q = _exp_coefficients(m, q)
        a = mean_value - slope * m
        _store(out, i, a * pa + slope * va, a * pb + slope * vb, a * pc + slope * vc)
        if save:
            saved[i, 0], saved[i, 1], saved[i, 2] = a, slope, m
            saved[i, 3] = (va * vc - vb * vb) / det_p
            saved[i, 4] = slope_q


def _dist_rows(P, X, out, saved, save):  # pragma: no cover
    """The distance; ``saved`` holds ``(d^2 / dm, d^2 / ddelta, m, delta, 1 / (2 d))``."""
    for i in prange(P.shape[0]):
        _, _, _, _, _, _, m, q, delta, log_det, slope, slope_q = _log_terms(P, X, i)
        x = q / (m * m)
        if x < _SERIES_BELOW:
            ratio2 = x * (1.0 + x * (2.0 / 3.0 + x * 23.0 / 45.0))  # atanh(sqrt(x))^2
        else:
            ratio = slope * math.sqrt(q)
            ratio2 = ratio * ratio
        squared = 0.5 * log_det * log_det + 2.0 * ratio2
        distance = math.sqrt(squared) if squared > 0.0 else squared * 0.0
        out[i] = distance
        if save:
            # A^2 = q B^2 (A = atanh(r / m)): dA^2/dq = B^2 + 2 q B B_q, dA^2/dm = -2 q B / delta
            ratio2_q = slope * slope + 2.0 * q * slope * slope_q
            saved[i, 0] = 2.0 * (-2.0 * q * slope / delta + 2.0 * m * ratio2_q)
            saved[i, 1] = log_det / delta - 2.0 * ratio2_q
            saved[i, 2], saved[i, 3] = m, delta
            saved[i, 4] = 0.5 / distance if squared > 0.0 else 0.0


@njit(inline="always", **_OPTIONS)
def _chain(i, P, X, m, delta, coef_m, coef_delta, direct_p, direct_x, gp, gx):  # pragma: no cover
    """Write the entry gradients of row ``i``: ``coef_m dm + coef_delta ddelta`` plus the
    direct parts ``direct_p`` and ``direct_x`` (each ``(a, b, c)``), ``b``'s split over the
    two off-diagonal entries."""
    pa, pb, pc = _entries(P, i)
    xa, xb, xc = _entries(X, i)
    inverse = 1.0 / (pa * pc - pb * pb)
    m_delta = m * coef_m
    _store(gx, i,
           direct_x[0] + inverse * (0.5 * pc * coef_m + xc * coef_delta),
           0.5 * (direct_x[1] - inverse * (pb * coef_m + 2.0 * xb * coef_delta)),
           direct_x[2] + inverse * (0.5 * pa * coef_m + xa * coef_delta))  # fmt: skip
    p_delta = delta * coef_delta
    _store(gp, i,
           direct_p[0] + inverse * (0.5 * xc * coef_m - (m_delta + p_delta) * pc),
           0.5 * (direct_p[1] + inverse * (2.0 * (m_delta + p_delta) * pb - xb * coef_m)),
           direct_p[2] + inverse * (0.5 * xa * coef_m - (m_delta + p_delta) * pa))  # fmt: skip


def _map_backward_rows(P, X, saved, grad, gp, gx, is_exp):  # pragma: no cover
    """Gradients of ``L = a P + B X`` (``a = F - B m``) in the entries of ``P`` and ``X``."""
    for i in prange(P.shape[0]):
        pa, pb, pc = _entries(P, i)
        xa, xb, xc = _entries(X, i)
        a, slope, m, delta, slope_q = (saved[i, 0], saved[i, 1], saved[i, 2], saved[i, 3],
                                       saved[i, 4])  # fmt: skip
        ga, gb, gc = grad[i, 0, 0], grad[i, 0, 1] + grad[i, 1, 0], grad[i, 1, 1]
        along_p = ga * pa + gb * pb + gc * pc
        along_x = ga * xa + gb * xb + gc * xc
        k = along_x - m * along_p
        if is_exp:  # F_m = F + m B, F_delta = -B / 2, B_m = B + 2 m B_q (at fixed delta)
            mean_value = a + slope * m
            coef_m = along_p * (mean_value + m * slope - slope) + k * (slope + 2.0 * m * slope_q)
            coef_delta = -0.5 * along_p * slope - k * slope_q
        else:  # F = log(delta) / 2; B_m = -1 / delta + 2 m B_q
            coef_m = -slope * along_p + k * (2.0 * m * slope_q - 1.0 / delta)
            coef_delta = 0.5 * along_p / delta - k * slope_q
        _chain(i, P, X, m, delta, coef_m, coef_delta, (a * ga, a * gb, a * gc),
               (slope * ga, slope * gb, slope * gc), gp, gx)  # fmt: skip


def _dist_backward_rows(P, X, saved, grad, gp, gx):  # pragma: no cover
    for i in prange(P.shape[0]):
        scale = grad[i] * saved[i, 4]
        _chain(i, P, X, saved[i, 2], saved[i, 3], scale * saved[i, 0], scale * saved[i, 1],
               (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), gp, gx)  # fmt: skip


_KERNELS = row_builds(
    {
        "log": _log_rows,
        "exp": _exp_rows,
        "dist": _dist_rows,
        "map_backward": _map_backward_rows,
        "dist_backward": _dist_backward_rows,
    },
    **_OPTIONS,
)


def run(name: str, *arrays) -> None:
    """Launch kernel ``name`` on its arrays (rows first), threaded from
    :data:`PARALLEL_ROWS` rows when the fit allows more than one thread."""
    launch_rows(_KERNELS, name, PARALLEL_ROWS, *arrays)


def empty_saved(n: int, save: bool) -> np.ndarray:
    """The saved-quantities array of ``n`` rows (one dummy row when nothing is saved)."""
    return np.empty((n if save else 1, N_SAVED))
