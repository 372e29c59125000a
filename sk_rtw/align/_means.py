"""The mean of aligned series, computed in one place.

The training loss, the rounds of the DTW start and the returned ``Alignment.mean`` all
call :func:`group_mean`: the weighted Fréchet mean, at every output time, of the aligned
series of each group (paper eqs. 14-15 with weights):

``y_g[z] = argmin_y sum_{n in g} w[n, z] dist(y, x_n[z])^2``,

by Gauss–Newton steps ``y <- Exp_y(sum_n w[n, z] Log_y(x_n[z]) / sum_n w[n, z])``. On flat
manifolds one step from any start is the exact weighted average.

Two ways to differentiate it:

* ``differentiate="all"`` (the paper preset): ``iterations`` steps from the first series of
  each group, every step on the autograd graph;
* ``differentiate="last"`` (the default preset): the steps start at ``start`` (the previous
  epoch's mean), all but the last run without gradient, and the last one is
  differentiated. At a converged mean this one step has the derivative of the exact mean
  up to curvature terms of the order of the spread (exactly on flat manifolds), and the
  backward pass goes through one step instead of ``iterations``.
"""

from __future__ import annotations

import torch

from ..manifolds import Manifold
from ._layout import GroupLayout

DIFFERENTIATE = ("all", "last")


def normalised_weights(layout: GroupLayout, weights: torch.Tensor | None, like: torch.Tensor):
    """Weights (N, Z) summing to one over each group's series at every output time."""
    if weights is None:
        share = 1.0 / layout.sizes.to(like.dtype)
        return layout.expand(share.unsqueeze(-1)).expand(layout.n_series, like.shape[1])
    return weights / layout.expand(layout.sum(weights))


def _step(manifold: Manifold, points, layout, weights, mean):
    nd = manifold.point_ndim
    w = weights.reshape(*weights.shape, *([1] * nd))
    return manifold._exp(mean, layout.sum(w * manifold._log(layout.expand(mean), points)))


def first_members(layout: GroupLayout, points: torch.Tensor) -> torch.Tensor:
    """The first series of every group, (n_groups, Z, *point_shape): a Gauss–Newton start."""
    first = torch.full((layout.n_groups,), layout.n_series, device=points.device)
    first = first.scatter_reduce(
        0, layout.codes, torch.arange(layout.n_series, device=points.device), "amin"
    )
    return points.index_select(0, first)


def group_mean(
    manifold: Manifold,
    points: torch.Tensor,
    layout: GroupLayout,
    weights: torch.Tensor | None = None,
    *,
    start: torch.Tensor | None = None,
    iterations: int = 5,
    differentiate: str = "last",
) -> torch.Tensor:
    """Weighted Fréchet mean of each group's series at every output time.

    Parameters
    ----------
    manifold : Manifold
    points : torch.Tensor, shape (N, Z, *point_shape)
        Aligned series of all groups, stacked.
    layout : GroupLayout
        Group of every series.
    weights : torch.Tensor of shape (N, Z), optional
        Non-negative weight of every aligned point (each group needs a positive weight at
        every output time); default: equal weights within each group.
    start : torch.Tensor of shape (n_groups, Z, *point_shape), optional
        Gauss–Newton start; default the first series of each group.
    iterations : int, default=5
        Gauss–Newton steps (one on flat manifolds, where it is exact).
    differentiate : {"last", "all"}, default="last"
        Which steps are on the autograd graph (see the module docstring).

    Returns
    -------
    mean : torch.Tensor, shape (n_groups, Z, *point_shape)
    """
    if differentiate not in DIFFERENTIATE:
        raise ValueError(f"differentiate must be one of {DIFFERENTIATE}, got {differentiate!r}")
    w = normalised_weights(layout, weights, points)
    if manifold.is_flat:
        nd = manifold.point_ndim
        return layout.sum(w.reshape(*w.shape, *([1] * nd)) * points)
    mean = first_members(layout, points) if start is None else start
    if differentiate == "last":
        with torch.no_grad():
            for _ in range(iterations - 1):
                mean = _step(manifold, points.detach(), layout, w.detach(), mean.detach())
        return _step(manifold, points, layout, w, mean.detach())
    for _ in range(iterations):
        mean = _step(manifold, points, layout, w, mean)
    return mean


def converged_group_mean(
    manifold: Manifold,
    points: torch.Tensor,
    layout: GroupLayout,
    weights: torch.Tensor | None = None,
    *,
    start: torch.Tensor | None = None,
    max_iter: int = 64,
    tol: float = 1e-10,
) -> torch.Tensor:
    """:func:`group_mean` iterated until the Gauss–Newton step is below ``tol`` (no gradient).

    The returned means of an alignment are computed this way.
    """
    with torch.no_grad():
        w = normalised_weights(layout, weights, points)
        if manifold.is_flat:
            return group_mean(manifold, points, layout, w)
        mean = first_members(layout, points) if start is None else start
        running = torch.ones(layout.n_groups, dtype=torch.bool, device=points.device)
        shape = (-1, *([1] * (mean.ndim - 1)))
        for _ in range(max_iter):
            step = _step(manifold, points, layout, w, mean)
            # each group stops on its own, as it would alone
            moved = manifold._dist(mean, step).reshape(layout.n_groups, -1).amax(-1)
            mean = torch.where(running.view(shape), step, mean)
            running = running & (moved >= tol)
            if not bool(running.any()):
                break
        return mean
