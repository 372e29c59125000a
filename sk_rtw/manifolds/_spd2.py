"""The affine-invariant geometry of SPD(2) in closed form: no matrix square root, no
eigendecomposition, elementwise operations over the whole batch (any device).

For ``2 x 2`` matrices every function of ``M = P^-1 X`` is ``f(M) = a I + b M``
(Cayley-Hamilton), with ``b`` the divided difference of ``f`` over the two eigenvalues
``m -+ r`` of ``M`` and ``a = f_mean - b m``, ``f_mean = (f(m - r) + f(m + r)) / 2``. So

- ``Log_P(X) = P logm(P^-1 X) = a P + b X`` with ``f = log``,
- ``Exp_P(V) = P expm(P^-1 V) = a P + b V`` with ``f = exp``,
- ``dist(P, X)^2 = log(m - r)^2 + log(m + r)^2 = log(det M)^2 / 2 + 2 atanh(r / m)^2``.

``f_mean`` and ``b`` are even in ``r``: they are evaluated as functions of ``r^2`` (short
series where ``r`` is small), so their gradients stay finite where the two eigenvalues
meet (``X = P``, ``V`` a multiple of ``P``). ``m`` and ``r^2`` come from the congruence
``L^-1 X L^-T`` (``P = L L^T``, Cholesky), a symmetric matrix with the eigenvalues of
``M``: ``r^2`` is a sum of squares there, free of cancellation.

On the CPU in float64, :func:`log`, :func:`exp` and :func:`dist` run the same formulas
compiled, with their gradients in closed form (:mod:`sk_rtw.manifolds._spd2_kernels`):
one autograd node per call instead of some sixty elementwise ones. The torch formulas
below are the path on other devices and dtypes, and the tests' reference.
"""

from __future__ import annotations

from typing import NamedTuple, TypeGuard

import numpy as np
import torch

from .._backend import safe_sqrt
from . import _spd2_kernels as kernels
from ._compiled import compiled_enabled
from ._symmetric import distinct

#: Below this ``r^2`` (``exp``) or ``(r / m)^2`` (``log``, distance) the even functions of
#: ``r`` are evaluated from their series (three terms: error under 1e-18).
_SERIES_BELOW = 1e-6
_EPS = torch.finfo(torch.float64).eps


def _entries(S: torch.Tensor):
    """``a, b, c`` of ``[[a, b], [b, c]]`` (``b`` from the symmetric part); one ``unbind``,
    whose gradient is one ``stack`` (four ``select`` would write four zero matrices)."""
    a, upper, lower, c = S.reshape(*S.shape[:-2], 4).unbind(-1)
    return a, 0.5 * (upper + lower), c


class Chart(NamedTuple):
    """What the formulas need of a base point ``P = [[a, b], [b, c]]``, computed once per
    distinct ``P``: its entries, ``L^-1 = [[i11, 0], [i21, i22]]`` (``P = L L^T``),
    ``b / a`` and ``log det P``."""

    a: torch.Tensor
    b: torch.Tensor
    c: torch.Tensor
    i11: torch.Tensor
    i21: torch.Tensor
    i22: torch.Tensor
    b_over_a: torch.Tensor
    log_det: torch.Tensor
    #: ``w = L^-1 X L^-T`` has ``w00 = s00 xa``, ``w11 = s11a xa + s11b xb + s11c xc``
    s00: torch.Tensor
    s11a: torch.Tensor
    s11b: torch.Tensor
    s11c: torch.Tensor


def chart(p: torch.Tensor) -> Chart:
    """The :class:`Chart` of SPD(2) points ``p`` (..., 2, 2); broadcast copies of a point
    (``expand``) are prepared once."""
    p = distinct(p)
    a, b, c = _entries(p)
    det = a * c - b * b
    i22 = torch.sqrt(a / det)
    i11, i21 = torch.rsqrt(a), -b * i22 / a
    return Chart(
        a, b, c, i11, i21, i22, b / a, torch.log(det),
        1.0 / a, i21 * i21, 2.0 * i21 * i22, i22 * i22,
    )  # fmt: skip


def group_chart(charts: Chart, select) -> Chart:
    """``select`` (a gather along the first axis) applied to every field."""
    return Chart(*(select(field) for field in charts))


def _congruence(p: Chart, x: torch.Tensor):
    """Mean eigenvalue ``m`` and half-gap squared ``r^2`` of ``P^-1 X``, and the entries
    of ``X`` with a negligible off-diagonal of ``L^-1 X L^-T`` set to zero (the gradients
    those deflations leave are the undeflated ones).

    An off-diagonal entry below ``eps sqrt(|w00 w11|)`` of the congruence is rounding-level;
    it is deflated as LAPACK's symmetric eigensolvers do, so that a diagonal ``P`` and an
    ``X`` diagonal to rounding give an exactly diagonal result (a diagonal matrix of any
    conditioning is a valid point; a nearly diagonal one beyond ``MAX_CONDITION`` is not).
    """
    xa, xb, xc = _entries(x)
    w00 = p.s00 * xa
    w01 = p.i11 * (p.i21 * xa + p.i22 * xb)
    w11 = p.s11a * xa + p.s11b * xb + p.s11c * xc
    negligible = w01.abs() <= _EPS * (w00 * w11).abs().sqrt()
    # values deflated, gradients kept; on a GPU without asking whether any is (a sync)
    if x.device.type != "cpu" or bool(negligible.any()):
        w01 = w01 - torch.where(negligible, w01, torch.zeros_like(w01)).detach()
        shift = torch.where(negligible, p.b_over_a * xa - xb, torch.zeros_like(xb))
        xb = xb + shift.detach()
    mean = 0.5 * (w00 + w11)
    half_gap = 0.5 * (w00 - w11)
    # likewise a rounding-level gap: X = P gives r = 0 and a distance of exactly zero
    tiny_gap = half_gap.abs() <= _EPS * mean.abs()
    half_gap = half_gap - torch.where(tiny_gap, half_gap, torch.zeros_like(half_gap)).detach()
    return mean, half_gap * half_gap + w01 * w01, (xa, xb, xc)


def _where_small(small: torch.Tensor, value: torch.Tensor) -> torch.Tensor:
    """``value`` where the series branch is not taken, a harmless 1 where it is (so that the
    other branch's gradient is not NaN)."""
    return torch.where(small, torch.ones_like(value), value)


def _log_coefficients(m, r2, log_det):
    """``(f_mean, b)`` of ``f = log`` over the eigenvalues ``m -+ r`` (``m > r >= 0``)."""
    x = r2 / (m * m)
    small = x < _SERIES_BELOW
    atanh_over_r = _atanh_ratio(m, r2, x, small, log_det) / _where_small(small, r2).sqrt()
    series = (1.0 + x * (1.0 / 3.0 + x / 5.0)) / m
    return 0.5 * log_det, torch.where(small, series, atanh_over_r)


def _atanh_ratio(m, r2, x, small, log_det):
    """``atanh(r / m)`` off the series branch: directly while ``r / m < 1/2``, else as
    ``log(m + r) - log(det) / 2`` (``= log(large / small) / 2``, exact near ``r = m``)."""
    r = _where_small(small, r2).sqrt()
    y = r / m
    near_one = y >= 0.5
    direct = torch.atanh(torch.where(near_one, torch.zeros_like(y), y))
    through_logs = torch.log(m + r) - 0.5 * log_det
    return torch.where(near_one, through_logs, direct)


def _exp_coefficients(m, r2):
    """``(f_mean, b)`` of ``f = exp`` over the eigenvalues ``m -+ r``: ``e^m cosh r`` and
    ``e^m sinh(r) / r``."""
    small = r2 < _SERIES_BELOW
    r = _where_small(small, r2).sqrt()
    cosh = torch.where(small, 1.0 + r2 * (0.5 + r2 / 24.0), torch.cosh(r))
    sinhc = torch.where(small, 1.0 + r2 * (1.0 / 6.0 + r2 / 120.0), torch.sinh(r) / r)
    scale = torch.exp(m)
    return scale * cosh, scale * sinhc


def _combine(mean_value, slope, m, p: Chart, x) -> torch.Tensor:
    """``a P + b X`` with ``a = f_mean - b m``, from the entries of ``P`` and ``X``: a
    symmetric result (the symmetric parts of the inputs)."""
    a = mean_value - slope * m
    xa, xb, xc = x
    diagonal = a * p.a + slope * xa
    off = a * p.b + slope * xb
    last = a * p.c + slope * xc
    return torch.stack((diagonal, off, off, last), -1).unflatten(-1, (2, 2))


def _log_det_ratio(p: Chart, x) -> torch.Tensor:
    xa, xb, xc = x
    return torch.log(xa * xc - xb * xb) - p.log_det


def log(p: torch.Tensor | Chart, x: torch.Tensor) -> torch.Tensor:
    """``Log_P(X)`` for SPD(2) points ``p`` (or their :class:`Chart`) and ``x`` (broadcast,
    ``(..., 2, 2)``)."""
    if compiled(p, x):
        return _compiled_map("log", p, x)
    return _torch_log(p, x)


def _torch_log(p: torch.Tensor | Chart, x: torch.Tensor) -> torch.Tensor:
    base = p if isinstance(p, Chart) else chart(p)
    m, r2, entries = _congruence(base, x)
    mean_value, slope = _log_coefficients(m, r2, _log_det_ratio(base, entries))
    return _combine(mean_value, slope, m, base, entries)


def exp(p: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
    """``Exp_P(V)`` for an SPD(2) point ``p`` and a symmetric tangent vector ``v``."""
    if compiled(p, v):
        return _compiled_map("exp", p, v)
    return _torch_exp(p, v)


def _torch_exp(p: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
    base = chart(p)
    m, r2, entries = _congruence(base, v)
    mean_value, slope = _exp_coefficients(m, r2)
    return _combine(mean_value, slope, m, base, entries)


def squared_dist(p: torch.Tensor, x: torch.Tensor) -> torch.Tensor:
    """``dist(P, X)^2 = log(det M)^2 / 2 + 2 atanh(r / m)^2`` (``M = P^-1 X``)."""
    base = chart(p)
    m, r2, entries = _congruence(base, x)
    log_det = _log_det_ratio(base, entries)
    x2 = r2 / (m * m)
    small = x2 < _SERIES_BELOW
    atanh = _atanh_ratio(m, r2, x2, small, log_det)
    series = x2 * (1.0 + x2 * (2.0 / 3.0 + x2 * 23.0 / 45.0))  # atanh(sqrt(x))^2
    return 0.5 * log_det * log_det + 2.0 * torch.where(small, series, atanh * atanh)


def dist(p: torch.Tensor, x: torch.Tensor) -> torch.Tensor:
    """Affine-invariant distance; its gradient at ``X = P`` is zero, not NaN."""
    if compiled(p, x):
        return _compiled_map("dist", p, x)
    return _torch_dist(p, x)


def _torch_dist(p: torch.Tensor, x: torch.Tensor) -> torch.Tensor:
    return safe_sqrt(squared_dist(p, x))


# ----------------------------------------------------------------- compiled (CPU, float64)
def compiled(p: torch.Tensor | Chart, x: torch.Tensor) -> TypeGuard[torch.Tensor]:
    """Whether :func:`log`, :func:`exp` and :func:`dist` of these arguments run compiled:
    point tensors (not a :class:`Chart`), both float64 on the CPU."""
    return (
        compiled_enabled() and not isinstance(p, Chart)
        and all(t.device.type == "cpu" and t.dtype == torch.float64 for t in (p, x))
    )  # fmt: skip


def _compiled_map(name: str, p: torch.Tensor, x: torch.Tensor) -> torch.Tensor:
    """``log``, ``exp`` (``(..., 2, 2)``) or ``dist`` (``(...)``) by the kernels; one
    autograd node when a gradient is recorded (broadcasting is torch's, so its gradient
    sums over the broadcast axes)."""
    shape = torch.broadcast_shapes(p.shape, x.shape)
    P = p.expand(shape).reshape(-1, 2, 2).contiguous()
    X = x.expand(shape).reshape(-1, 2, 2).contiguous()
    if torch.is_grad_enabled() and (P.requires_grad or X.requires_grad):
        out = _KernelMap.apply(name, P, X)
    else:
        out, _ = _forward(name, P, X, save=False)
    return out.reshape(shape[:-2] if name == "dist" else shape)


def _forward(name: str, P: torch.Tensor, X: torch.Tensor, save: bool):
    p, x = P.detach().numpy(), X.detach().numpy()
    out = np.empty(p.shape[0]) if name == "dist" else np.empty_like(p)
    saved = kernels.empty_saved(p.shape[0], save)
    kernels.run(name, p, x, out, saved, save)
    return torch.from_numpy(out), torch.from_numpy(saved)


class _KernelMap(torch.autograd.Function):
    """A compiled map of ``(n, 2, 2)`` matrices with its closed-form gradient."""

    @staticmethod
    def forward(ctx, name, P, X):
        out, saved = _forward(name, P, X, save=True)
        ctx.name = name
        ctx.save_for_backward(P, X, saved)
        return out

    @staticmethod
    def backward(ctx, grad):
        P, X, saved = ctx.saved_tensors
        if torch.is_grad_enabled():  # create_graph: a differentiable backward, the torch one
            return None, *_torch_vjp(ctx.name, P, X, grad)
        P, X = P.detach(), X.detach()
        gp, gx = torch.empty_like(P), torch.empty_like(X)
        g = grad.contiguous().numpy()
        if ctx.name == "dist":
            kernels.run("dist_backward", P.numpy(), X.numpy(), saved.numpy(), g, gp.numpy(),
                        gx.numpy())  # fmt: skip
        else:
            kernels.run("map_backward", P.numpy(), X.numpy(), saved.numpy(), g, gp.numpy(),
                        gx.numpy(), ctx.name == "exp")  # fmt: skip
        return None, gp, gx


_TORCH_MAPS = {"log": _torch_log, "exp": _torch_exp, "dist": _torch_dist}


def _torch_vjp(name: str, P: torch.Tensor, X: torch.Tensor, grad: torch.Tensor):
    """The gradients of the torch formulas, with their graph (higher derivatives)."""
    inputs = [t for t in (P, X) if t.requires_grad]
    grads = iter(torch.autograd.grad(_TORCH_MAPS[name](P, X), inputs, grad, create_graph=True))
    return tuple(next(grads) if t.requires_grad else None for t in (P, X))
