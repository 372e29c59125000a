"""Density-weighted means: every series counts for the samples each output time covers.

The paper's mean gives every warped series one vote per output time: a series that
dwells at a point (many of its samples warped onto one output time) counts once there,
and the samples in between are skipped; DTW barycenter averaging instead averages every
sample matched to a mean sample, so such a series counts for all of them. This module
is the continuous counterpart for warps.

For series ``n`` of ``T_n`` samples with warped positions ``tau_z = w_n[z] (T_n - 1)``,
output time ``z`` covers the *stretch* ``[b_z, b_{z+1}]`` between the midpoints to its
neighbours (``b_z = (tau_{z-1} + tau_z) / 2``; ``b_0 = -1/2``, ``b_Z = T_n - 1/2``): the
stretches tile the series. Sample ``i`` is a unit of mass spread over ``[i - h, i + h]``
(``h = 1/4``); its *mass* in a stretch is the share of that interval the stretch covers.
With ``M_z`` the mass of stretch ``z``:

* the stretch's **representative** is the tangent-space average at the interpolated
  point ``x^_z`` (the aligned sample) of the samples it holds, topped up with ``x^_z``
  itself to at least one sample:
  ``v_z = Exp_{x^_z}(sum_i m_{i,z} Log_{x^_z}(x_i) / max(M_z, 1))``;
* its **weight** is ``W_z = max(M_z, 1)``: how many samples it holds, at least one.

The class mean at ``z`` is then the Fréchet mean of the representatives of all series
weighted by ``W``. A stretch of less than a sample gives back the aligned point with
weight 1 (the paper's mean); a stretch of many samples gives their average with their
count. When a DTW path matches every mean sample to its own run of samples and the warps
are read off it, the stretches are those runs, and on flat spaces the mean is exactly
DBA's update (the average of every matched sample; tests check this).

Everything is differentiable in the warps (the masses are piecewise linear in the
stretch ends) and of fixed size: at most ``T_max + Z`` (sample, stretch) pairs per series,
so the computation needs no host-device synchronisation.
"""

from __future__ import annotations

import torch

from ..manifolds import Manifold

#: Half-width, in samples, of the interval over which a sample's unit mass is spread.
HALF_WIDTH = 0.01


def stretch_bounds(warps: torch.Tensor, lengths: torch.Tensor) -> torch.Tensor:
    """Ends ``b`` (N, Z + 1) of the stretch of samples every output time covers."""
    last = (lengths - 1).to(warps.dtype).unsqueeze(-1)
    tau = warps * last
    inner = 0.5 * (tau[:, :-1] + tau[:, 1:])
    bounds = torch.cat([torch.full_like(tau[:, :1], -0.5), inner, last + 0.5], dim=1)
    return torch.cummax(bounds, dim=1).values  # monotone even for slightly decreasing warps


def density_representatives(
    manifold: Manifold,
    data: torch.Tensor,
    lengths: torch.Tensor,
    warps: torch.Tensor,
    aligned: torch.Tensor,
    half_width: float | None = None,
) -> tuple[torch.Tensor, torch.Tensor]:
    """Representatives and weights of the stretches (see the module docstring).

    Parameters
    ----------
    manifold : Manifold
    data : torch.Tensor, shape (N, T_max, *point_shape)
        The series (padded; samples beyond ``lengths`` are never read).
    lengths : torch.Tensor of int, shape (N,)
    warps : torch.Tensor, shape (N, Z)
        Warps in [0, 1].
    aligned : torch.Tensor, shape (N, Z, *point_shape)
        The series resampled along the warps (the tangent points of the averages).

    Returns
    -------
    representatives : torch.Tensor, shape (N, Z, *point_shape)
    weights : torch.Tensor, shape (N, Z)
        ``max(M_z, 1)``.
    """
    half_width = HALF_WIDTH if half_width is None else half_width
    n_series, t_max = data.shape[:2]
    z = warps.shape[1]
    point_shape = data.shape[2:]
    bounds = stretch_bounds(warps, lengths)
    last = (lengths - 1).unsqueeze(-1)
    with torch.no_grad():
        lo, hi = bounds[:, :-1], bounds[:, 1:]
        first = torch.minimum((torch.floor(lo - half_width) + 1).long().clamp_min(0), last + 1)
        final = torch.minimum((torch.ceil(hi + half_width) - 1).long(), last)
        counts = (final - first + 1).clamp_min(0)
        ends = torch.cumsum(counts, dim=1)
        slots = torch.arange(t_max + z + 1, device=data.device).expand(n_series, -1)
        stretch = torch.searchsorted(ends, slots.contiguous(), right=True)
        valid = stretch < z
        stretch = stretch.clamp_max(z - 1)
        offset = slots - (ends - counts).gather(1, stretch)
        sample = (first.gather(1, stretch) + offset).clamp_min(0)
        sample = torch.minimum(sample, last)
    left, right = bounds[:, :-1].gather(1, stretch), bounds[:, 1:].gather(1, stretch)
    position = sample.to(data.dtype)
    overlap = torch.minimum(position + half_width, right) - torch.maximum(
        position - half_width, left
    )
    mass = overlap.clamp_min(0.0) * valid.to(data.dtype) / (2.0 * half_width)
    flat = data.reshape(n_series, t_max, -1)
    samples = flat.gather(1, sample.unsqueeze(-1).expand(-1, -1, flat.shape[-1]))
    flat_aligned = aligned.reshape(n_series, z, -1)
    anchors = flat_aligned.gather(1, stretch.unsqueeze(-1).expand(-1, -1, flat.shape[-1]))
    logs = manifold._log(
        anchors.reshape(*anchors.shape[:2], *point_shape),
        samples.reshape(*samples.shape[:2], *point_shape),
    ).reshape(anchors.shape)
    index = stretch.unsqueeze(-1).expand(-1, -1, flat.shape[-1])
    sums = torch.zeros_like(flat_aligned).scatter_add(1, index, mass.unsqueeze(-1) * logs)
    masses = torch.zeros_like(warps).scatter_add(1, stretch, mass)
    weights = masses.clamp_min(1.0)
    step = (sums / weights.unsqueeze(-1)).reshape(aligned.shape)
    return manifold._exp(aligned, step), weights
