"""Alignment losses: Gaussian-weighted window loss and monotonicity penalty.

Window loss (paper eq. 9): with offsets ``k = -kappa..kappa``, indices
``v = clamp(z + k rho, 1, Z)`` and normalised Gaussian weights
``g_k = exp(-(k rho)^2 / (2 sigma^2)) / sum_i exp(-(i rho)^2 / (2 sigma^2))``,
``sigma = kappa rho / 3 + eps``::

    D = 1 / (N Z) sum_n sum_z sum_k g_k dist(x_n[v], y[v]).

Summing over ``z`` first shows this equals ``1 / (N Z) sum_n sum_v c_v dist(x_n[v], y[v])``
with per-index weights ``c_v = sum_k g_k #{z : clamp(z + k rho) = v}``, which are computed
once; the loss then costs O(N Z) whatever the window. Away from the ends (``kappa rho``
indices from either end) ``c_v = 1``: the window only re-weights the first and last
indices, where clamping piles the weight of the out-of-range taps onto the end points.
``kappa = 0`` gives the pointwise loss of TTW and NTW.
"""

from __future__ import annotations

import torch

SIGMA_EPS = 1e-6


def window_weights(
    n_points: int, window: int, step: int, dtype=torch.float64, device=None
) -> torch.Tensor:
    """Per-index weights ``c_v`` of the Gaussian-weighted window loss, shape (Z,)."""
    if window < 0 or step < 1:
        raise ValueError(f"loss window must be >= 0 and step >= 1, got {window}, {step}")
    k = torch.arange(-window, window + 1, dtype=dtype, device=device)
    sigma = window * step / 3.0 + SIGMA_EPS
    g = torch.exp(-((k * step) ** 2) / (2.0 * sigma**2))
    g = g / g.sum()
    z = torch.arange(n_points, device=device)
    v = (z.unsqueeze(-1) + (k.long() * step)).clamp(0, n_points - 1)  # (Z, K)
    c = torch.zeros(n_points, dtype=dtype, device=device)
    c.index_add_(0, v.reshape(-1), g.expand(n_points, -1).reshape(-1))
    return c


def window_loss(distances: torch.Tensor, weights: torch.Tensor) -> torch.Tensor:
    """``1 / (N Z) sum_n sum_v c_v d[n, v]`` for distances (N, Z) and weights (Z,)."""
    return (distances * weights).mean()


def monotonicity_penalty(raw_warps: torch.Tensor) -> torch.Tensor:
    """``sum_n sum_z max(w_n[z] - w_n[z+1], 0)`` (paper eq. 8)."""
    return torch.relu(raw_warps[..., :-1] - raw_warps[..., 1:]).sum()
