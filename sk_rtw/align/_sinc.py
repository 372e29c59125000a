"""Windowed sinc interpolation of manifold-valued series in local tangent spaces.

For signal ``n`` and output index ``z`` with warp value ``w = w_n[z]`` in [0, 1], the
continuous position in the signal is ``tau = w (T_n - 1)`` (0-based: ``w = 0`` is the first
sample, ``w = 1`` the last, so the boundary constraint maps ends onto ends). The samples
``m = floor(tau) - nu, ..., floor(tau) + nu`` (indices clamped to ``[0, T_n - 1]``, i.e. the
signal is extended by its end values) are mapped to the tangent space at a tangent point
``p``, combined with the weights ``sinc(m - tau)`` and mapped back with ``Exp_p`` (paper,
eqs. 11-12). The tangent point starts at ``x_n[floor(tau)]`` and is refined by
Gauss–Newton steps ``p <- Exp_p(sum_m s_m Log_p(x_n[m]))``, which converge to the weighted
Fréchet mean of the window.

The truncated kernel is normalised to unit sum. Without that, ``p + sum_m s_m (x_m - p)``
would depend on the tangent point even in flat space; with it, Euclidean data give exactly
the (normalised) windowed sinc interpolation ``sum_m s_m x_m``, constant signals are
reproduced exactly on every manifold, and at integer positions the sample itself is
returned.

``window=None`` uses every sample of the signal (the full, unwindowed sinc of NTW).
"""

from __future__ import annotations

import math

import torch

from ..manifolds import Manifold


def shifted_sinc(offsets: torch.Tensor, parity: torch.Tensor, frac: torch.Tensor) -> torch.Tensor:
    """``sinc(k - frac)`` for integer offsets ``k`` (last axis) and ``frac`` in [0, 1).

    Uses ``sin(pi (k - f)) = -(-1)^k sin(pi f)``, so the sine is evaluated once per
    position instead of once per tap, and each tap costs one division. ``parity`` is
    ``(-1)^k``, broadcastable to ``offsets``.
    """
    distance = offsets - frac.unsqueeze(-1)
    at_sample = distance == 0
    sine = torch.sin(math.pi * frac).unsqueeze(-1)
    safe = torch.where(at_sample, torch.ones_like(distance), distance)
    return torch.where(at_sample, torch.ones_like(distance), -parity * sine / (math.pi * safe))


def _parity(k: torch.Tensor) -> torch.Tensor:
    return 1.0 - 2.0 * torch.remainder(k, 2).to(torch.float64)


def tangent_sinc_interpolate(
    manifold: Manifold,
    data: torch.Tensor,
    lengths: torch.Tensor,
    warps: torch.Tensor,
    window: int | None = 10,
    refinements: int = 2,
) -> torch.Tensor:
    """Resample every series at its warped positions, in the tangent spaces.

    Parameters
    ----------
    manifold : Manifold
    data : torch.Tensor, shape (N, T_max, *point_shape)
        Series padded to ``T_max`` (padding is ignored: indices are clamped per series).
    lengths : torch.Tensor of int, shape (N,)
        True length ``T_n`` of each series.
    warps : torch.Tensor, shape (N, Z)
        Warp values in [0, 1].
    window : int or None, default=10
        Half-width ``nu`` of the sinc window; None for the full sinc over all samples.
    refinements : int, default=2
        Gauss–Newton refinements of the tangent point (skipped on flat manifolds, where
        the result does not depend on it).

    Returns
    -------
    torch.Tensor, shape (N, Z, *point_shape)
    """
    n_series, t_max = data.shape[:2]
    point_ndim = manifold.point_ndim
    last = (lengths - 1).to(warps.dtype).unsqueeze(-1)  # (N, 1)
    tau = warps * last  # (N, Z)
    base = torch.floor(tau).detach()
    frac = tau - base
    base = base.long()
    rows = torch.arange(n_series, device=data.device).view(-1, 1, 1)
    if window is None:
        samples = torch.arange(t_max, device=data.device)
        # weights for every sample m: sinc(m - tau) = sinc((m - floor(tau)) - frac);
        # samples beyond T_n get weight zero
        offsets = (samples - base.unsqueeze(-1)).to(warps.dtype)  # (N, Z, T)
        parity = _parity(samples).to(warps.dtype) * _parity(base).to(warps.dtype).unsqueeze(-1)
        weights = shifted_sinc(offsets, parity, frac)
        valid = samples.unsqueeze(0) < lengths.unsqueeze(-1)  # (N, T)
        weights = weights * valid.unsqueeze(1).to(warps.dtype)
        weights = weights / weights.sum(-1, keepdim=True)
        window_points = data.unsqueeze(1)  # (N, 1, T, *ps)
    else:
        offsets = torch.arange(-window, window + 1, device=data.device)
        index = base.unsqueeze(-1) + offsets  # (N, Z, K)
        index = torch.minimum(index.clamp_min(0), (lengths - 1).view(-1, 1, 1))
        k = offsets.to(warps.dtype)
        weights = shifted_sinc(k, _parity(offsets).to(warps.dtype), frac)
        weights = weights / weights.sum(-1, keepdim=True)
        window_points = data[rows, index]  # (N, Z, K, *ps)
    if manifold.is_flat:
        # Log/Exp are subtraction/addition and the weights sum to one, so the result is
        # the weighted sum of the samples whatever the tangent point: one contraction
        # (a batched matrix product for the full sinc) instead of (N, Z, K) tangent vectors.
        flat = window_points.reshape(*window_points.shape[:3], -1)
        if window is None:
            out = torch.einsum("nzt,ntp->nzp", weights, flat[:, 0])
        else:
            out = torch.einsum("nzk,nzkp->nzp", weights, flat)
        return out.reshape(*out.shape[:2], *manifold.point_shape)
    centre = torch.minimum(base.clamp_min(0), (lengths - 1).view(-1, 1))
    tangent_point = data[rows[..., 0], centre]  # (N, Z, *ps)
    weights = weights.reshape(*weights.shape, *([1] * point_ndim))
    if refinements > 0:
        # The tangent point is a choice of chart: refine it without recording gradients
        # (at the fixed point the result depends on it only to second order).
        with torch.no_grad():
            fixed_weights = weights.detach()
            for _ in range(refinements):
                vectors = manifold._log(tangent_point.unsqueeze(2), window_points)
                tangent_point = manifold._exp(tangent_point, (fixed_weights * vectors).sum(2))
    vectors = manifold._log(tangent_point.unsqueeze(2), window_points)
    return manifold._exp(tangent_point, (weights * vectors).sum(2))
