"""The weighted Fréchet mean, batched over groups: the one implementation in the package.

For points ``x_n`` (each with leading axes, e.g. the output times of aligned series) in
groups ``g(n)`` with non-negative weights ``w_n``, the mean of every group (at every
leading index) is

``y_g = argmin_y sum_{n in g} w_n dist(y, x_n)^2``,

found by Gauss–Newton steps ``y <- Exp_y(sum_{n in g} w_n Log_y(x_n) / sum_{n in g} w_n)``
(paper eqs. 14-15 with weights) from the first point of each group or a given start.
On flat spaces one step is the exact weighted average.

One stopping rule: a group stops when no mean of it moves by ``tol`` or more (geodesic
distance of the step); with ``tol=0`` exactly ``max_iter`` steps are taken (a fixed
budget, as DBA and the training loss use). The full Gauss–Newton step cycles where the
points lie far apart (SPD matrices whose log-eigenvalues differ by several units): the
means still moving after ``max_iter`` steps go on by at most ``max_iter`` line-searched
steps (the best of a few fractions of the Gauss–Newton step, :func:`_descend`), which
leaves every mean that converged as it was. A group still moving after those raises
one ``ConvergenceWarning``. Groups never interact: a group gets bitwise the same
mean alone as in a batch (sums run in stacking order whatever the number of groups; the
fallback, which computes only the leading indices still moving, to rounding).

Three ways to differentiate, for torch tensors: ``"all"`` keeps every step on the
autograd graph; ``"last"`` runs all but the last step without gradient and
differentiates the last one (from a close start its derivative is the exact mean's up to
curvature terms of the order of the spread, and exactly on flat spaces); ``"none"``
records nothing.

:meth:`sk_rtw.manifolds.Manifold.mean` (numpy or torch), the alignment engine (its loss,
its DTW start, the returned means), DBA and the statistics of an aligned set all call
:func:`frechet_mean`.
"""

from __future__ import annotations

import contextlib
import math
import warnings
from typing import TYPE_CHECKING

import torch
from sklearn.exceptions import ConvergenceWarning

if TYPE_CHECKING:
    from ._base import Manifold

#: Default stopping rule of every Fréchet mean.
MEAN_TOL = 1e-10
MEAN_MAX_ITER = 64
DIFFERENTIATE = ("all", "last", "none")


def group_sum(values: torch.Tensor, codes: torch.Tensor, n_groups: int) -> torch.Tensor:
    """Per-group sums of per-point ``values`` (N, ...) -> (n_groups, ...), in stacking order."""
    return values.new_zeros(n_groups, *values.shape[1:]).index_add(0, codes, values)


def group_expand(values: torch.Tensor, codes: torch.Tensor) -> torch.Tensor:
    """Per-group ``values`` (n_groups, ...) broadcast to their points -> (N, ...)."""
    if values.shape[0] == 1:
        return values.expand(codes.numel(), *values.shape[1:])
    return values.index_select(0, codes)


def first_members(points: torch.Tensor, codes: torch.Tensor, n_groups: int) -> torch.Tensor:
    """The first point of every group, (n_groups, ...): the default Gauss–Newton start."""
    n = codes.numel()
    first = torch.full((n_groups,), n, device=points.device)
    first = first.scatter_reduce(0, codes, torch.arange(n, device=points.device), "amin")
    return points.index_select(0, first)


def normalised_weights(
    weights: torch.Tensor | None,
    codes: torch.Tensor,
    sizes: torch.Tensor,
    like: torch.Tensor,
    n_lead: int,
) -> torch.Tensor:
    """Weights summing to one over each group, shaped ``(N, *leading)`` of ``like``."""
    n_groups = sizes.numel()
    lead = like.shape[1 : 1 + n_lead]
    if weights is None:
        share = (1.0 / sizes.to(like.dtype)).reshape(n_groups, *([1] * n_lead))
        return group_expand(share, codes).expand(codes.numel(), *lead)
    weights = weights.to(dtype=like.dtype, device=like.device)
    weights = weights.reshape(*weights.shape, *([1] * (1 + n_lead - weights.ndim)))
    return weights / group_expand(group_sum(weights, codes, n_groups), codes)


def _direction(manifold: Manifold, points, codes, weights, mean, n_groups):
    """The Gauss–Newton step of every mean: the weighted average of the points' logs
    there (``weights`` (N, *leading))."""
    w = weights.reshape(*weights.shape, *([1] * manifold.point_ndim))
    return group_sum(w * manifold._group_log(mean, codes, points), codes, n_groups)


def _step(manifold: Manifold, points, codes, weights, mean, n_groups):
    return manifold._exp(mean, _direction(manifold, points, codes, weights, mean, n_groups))


def frechet_mean(
    manifold: Manifold,
    points: torch.Tensor,
    weights: torch.Tensor | None = None,
    codes: torch.Tensor | None = None,
    *,
    start: torch.Tensor | None = None,
    max_iter: int = MEAN_MAX_ITER,
    tol: float = MEAN_TOL,
    differentiate: str = "all",
    warn: bool = True,
    sizes: torch.Tensor | None = None,
) -> torch.Tensor:
    """Weighted Fréchet mean of each group, at every leading index (module docstring).

    Parameters
    ----------
    manifold : Manifold
    points : torch.Tensor of shape (N, *leading, *point_shape)
    weights : torch.Tensor of shape (N,) or (N, *leading), optional
        Non-negative; every group needs a positive total (not checked here). Default:
        equal weights within each group.
    codes : torch.Tensor of int64, shape (N,), optional
        Group of every point, ``0..n_groups - 1``, none empty. Default: one group.
    start : torch.Tensor of shape (n_groups, *leading, *point_shape), optional
        Gauss–Newton start (default: the first point of each group).
    max_iter : int, default=64
    tol : float, default=1e-10
        Stop a group when its means move by less than this; 0: exactly ``max_iter`` steps.
    differentiate : {"all", "last", "none"}, default="all"
    warn : bool, default=True
        ``ConvergenceWarning`` when a group is still moving after ``max_iter`` steps and
        as many line-searched ones (module docstring).
    sizes : torch.Tensor of int64, shape (n_groups,), optional
        Points per group, when known (saves a device synchronisation on a GPU).

    Returns
    -------
    torch.Tensor of shape (n_groups, *leading, *point_shape)
    """
    if differentiate not in DIFFERENTIATE:
        raise ValueError(f"differentiate must be one of {DIFFERENTIATE}, got {differentiate!r}")
    if codes is None:
        codes = torch.zeros(points.shape[0], dtype=torch.long, device=points.device)
    sizes = torch.bincount(codes) if sizes is None else sizes
    try:
        return _frechet_mean(manifold, points, codes, sizes, weights, start, max_iter, tol,
                             differentiate, warn)  # fmt: skip
    except torch.linalg.LinAlgError as error:  # a step beyond float64's reach
        raise ValueError(
            f"the Fréchet mean of these points of {manifold!r} cannot be computed in float64: "
            "a Gauss–Newton step reached a point whose linear algebra fails "
            f"({str(error).splitlines()[0]}). Points of extreme spread average exactly "
            "when every point is diagonal (one eigenbasis); otherwise rescale or "
            "regularise the series (add a multiple of the identity)"
        ) from None


def _frechet_mean(manifold, points, codes, sizes, weights, start, max_iter, tol,
                  differentiate, warn):  # fmt: skip
    n_groups = sizes.numel()
    n_lead = points.ndim - 1 - manifold.point_ndim
    recording = torch.no_grad() if differentiate == "none" else contextlib.nullcontext()
    with recording:
        w = normalised_weights(weights, codes, sizes, points, n_lead)
        if manifold.is_flat:  # exact in one step, from any start
            flat = w.reshape(*w.shape, *([1] * manifold.point_ndim))
            return group_sum(flat * points, codes, n_groups)
        mean = first_members(points, codes, n_groups) if start is None else start
        if differentiate == "all":
            return _iterate(manifold, points, codes, w, mean, n_groups, max_iter, tol, warn)
    # "last" and "none": the steps off the graph, then ("last") one differentiated step
    steps = max_iter - 1 if differentiate == "last" else max_iter
    with torch.no_grad():
        mean = _iterate(manifold, points.detach(), codes, w.detach(), mean.detach(), n_groups,
                        steps, tol, warn)  # fmt: skip
    if differentiate == "none":
        return mean
    return _step(manifold, points, codes, w, mean, n_groups)


def _iterate(manifold, points, codes, weights, mean, n_groups, steps, tol, warn):
    """``steps`` Gauss–Newton steps; with ``tol > 0`` each group stops on its own, and the
    means still moving after them go on by :func:`_descend`."""
    if tol <= 0:
        for _ in range(steps):
            mean = _step(manifold, points, codes, weights, mean, n_groups)
        return mean
    running = torch.ones(n_groups, dtype=torch.bool, device=points.device)
    shape = (-1, *([1] * (mean.ndim - 1)))
    moving = mean.new_zeros(0)
    for _ in range(steps):
        new = _step(manifold, points, codes, weights, mean, n_groups)
        moving = manifold._dist(mean, new)
        moved = moving.reshape(n_groups, -1).amax(-1)
        mean = torch.where(running.view(shape), new, mean)
        running = running & (moved >= tol)
        if not bool(running.any()):
            return mean
    if steps == 0:
        return mean
    failing = (moving >= tol) & running.view(shape[: moving.ndim])
    mean, failing, last = _descend(manifold, points, codes, weights, mean, failing, n_groups,
                                   steps, tol)  # fmt: skip
    if warn and bool(failing.any()):
        warnings.warn(
            f"the Fréchet mean did not converge in {steps} Gauss–Newton iterations and "
            f"{steps} line-searched steps (the last step {last:.3g}, above "
            f"tol={tol:g}): raise max_iter, or check that the samples are not spread "
            "around a sphere's cut locus",
            ConvergenceWarning,
            stacklevel=4,
        )
    return mean


#: Fractions of the Gauss–Newton step :func:`_descend` tries, the best one taken if it
#: shortens the next step.
DESCENT_FRACTIONS = (1.0, 0.7, 0.5, 0.35, 0.25, 0.18, 0.125)


def _gauss_newton(manifold, points, codes, weights, mean, n_groups):
    """The Gauss–Newton step of every mean (:func:`_direction`) and its length."""
    direction = _direction(manifold, points, codes, weights, mean, n_groups)
    return direction, manifold._norm(mean, direction)


def _descend(manifold, points, codes, weights, mean, failing, n_groups, steps, tol):
    """At most ``steps`` line-searched steps of the means ``failing`` marks (n_groups,
    *leading): of the fractions :data:`DESCENT_FRACTIONS` of the Gauss–Newton step, the
    one after which the Gauss–Newton step (the gradient of the objective, resolved to
    rounding where the objective itself is flat) is shortest. The full step overshoots
    where the points lie far apart (it cycles: three SPD(6) matrices whose
    log-eigenvalues spread over several units); a fraction of it converges. Where no
    fraction shortens it, the fractions shrink by the smallest one. A mean stops, by the
    main loop's rule, when the step it would take is shorter than ``tol``. Each step
    computes only the leading indices where some mean still moves. Returns the means
    (the others as they were), what is still moving and the longest step of those."""
    nd = manifold.point_ndim
    pad = (Ellipsis, *([None] * nd))
    lead = mean.shape[1 : mean.ndim - nd]
    width = math.prod(lead)
    point_shape = mean.shape[mean.ndim - nd :]
    # leading axes flattened into one: (N or n_groups, width, *point_shape)
    points = points.reshape(points.shape[0], width, *point_shape)
    weights = weights.reshape(weights.shape[0], width)
    out = mean.reshape(n_groups, width, *point_shape).clone()
    failing = failing.reshape(n_groups, width)
    direction, length = _gauss_newton(manifold, points, codes, weights, out, n_groups)
    scale = torch.ones_like(length)
    last = 0.0
    for _ in range(steps):
        failing = failing & (scale * length >= tol)
        if not bool(failing.any()):
            return out.reshape(mean.shape), failing.reshape(n_groups, *lead), 0.0
        last = float((scale * length)[failing].max().detach())
        cols = failing.any(0).nonzero().squeeze(1)
        m, d, n, f = out[:, cols], direction[:, cols], length[:, cols], failing[:, cols]
        x, w, c = points[:, cols], weights[:, cols], scale[:, cols]
        best, best_direction, shortest = m, d, n
        for fraction in DESCENT_FRACTIONS:
            candidate = manifold._exp(m, (fraction * c)[pad] * d)
            new_direction, new_length = _gauss_newton(manifold, x, codes, w, candidate,
                                                      n_groups)  # fmt: skip
            better = new_length < shortest
            best = torch.where(better[pad], candidate, best)
            best_direction = torch.where(better[pad], new_direction, best_direction)
            shortest = torch.where(better, new_length, shortest)
        moves = f & (shortest < n)
        out[:, cols] = torch.where(moves[pad], best, m)
        direction[:, cols] = torch.where(moves[pad], best_direction, d)
        length[:, cols] = torch.where(moves, shortest, n)
        scale[:, cols] = torch.where(f & ~moves, DESCENT_FRACTIONS[-1] * c, c)
    return out.reshape(mean.shape), failing.reshape(n_groups, *lead), last


def checked_mean(
    manifold: Manifold,
    X: torch.Tensor,
    weights: torch.Tensor | None,
    groups: torch.Tensor | None,
    start: torch.Tensor | None,
    *,
    axis: int,
    max_iter: int,
    tol: float,
) -> torch.Tensor:
    """:func:`frechet_mean` of the arguments of :meth:`Manifold.mean`, checked: the sample
    axis, the weights, the groups and the start, each with a message naming it."""
    nd = manifold.point_ndim
    n_leading = X.ndim - nd
    if n_leading < 1:
        raise ValueError(
            f"mean needs at least one sample axis before the point axes {manifold.point_shape}"
        )
    axis = axis % n_leading
    X = torch.movedim(X, axis, 0)
    n = X.shape[0]
    if n == 0:
        raise ValueError(
            f"cannot compute the mean of zero samples: X has shape {tuple(X.shape)}, with no "
            f"sample along axis {axis}"
        )
    codes = None if groups is None else check_groups(groups, n, X.device)
    n_groups = 1 if codes is None else int(codes.max()) + 1
    if weights is not None:
        w = weights.to(dtype=X.dtype, device=X.device)
        if w.ndim == 0 or w.shape[0] != n or w.ndim > n_leading:
            raise ValueError(
                f"weights must have {n} entries along the sample axis (shape ({n},) or "
                f"broadcastable to the leading axes {tuple(X.shape[:n_leading])}), got shape "
                f"{tuple(w.shape)}"
            )
        if not bool(torch.isfinite(w).all()):
            raise ValueError("weights contain NaN or infinite values")
        if bool((w < 0).any()):
            raise ValueError("weights must be non-negative")
        index = torch.zeros(n, dtype=torch.long) if codes is None else codes
        totals = w.new_zeros(n_groups, *w.shape[1:]).index_add(0, index.to(w.device), w)
        if bool((totals <= 0).any()):
            raise ValueError("weights must not all be zero (in any group)")
        weights = w
    if start is not None:
        start = start.to(dtype=X.dtype, device=X.device)
        expected = (n_groups, *X.shape[1:])
        if groups is None:
            start = start.unsqueeze(0)
        if tuple(start.shape) != expected:
            raise ValueError(
                f"start must have shape {expected[1:] if groups is None else expected}, got "
                f"{tuple(start.shape)[1 if groups is None else 0 :]}"
            )
    mean = frechet_mean(manifold, X, weights, codes, start=start, max_iter=max_iter, tol=tol)
    return mean if groups is not None else mean[0]


def check_groups(groups: torch.Tensor, n: int, device) -> torch.Tensor:
    """Group codes ``0..n_groups - 1``, one per sample, none empty."""
    if groups.dtype.is_floating_point and not bool((groups == groups.round()).all()):
        raise ValueError("groups must be integers, one per sample")
    codes = groups.to(device=device, dtype=torch.long).reshape(-1)
    if codes.numel() != n:
        raise ValueError(f"groups must have one entry per sample ({n}), got {codes.numel()}")
    if bool((codes < 0).any()):
        raise ValueError("groups must be non-negative integers")
    empty = torch.bincount(codes) == 0
    if bool(empty.any()):
        raise ValueError(f"groups {torch.nonzero(empty).flatten().tolist()} have no sample")
    return codes
