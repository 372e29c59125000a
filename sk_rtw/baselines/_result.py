"""The result type shared by the DTW-family baselines and their path helpers."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from ..manifolds import Manifold


@dataclass(frozen=True, eq=False)
class MultipleAlignment:
    """Joint alignment of N series by a DTW-family method.

    Attributes
    ----------
    mean : ndarray of shape (L, *point_shape)
        Average series on the manifold.
    aligned : ndarray of shape (N, L, *point_shape)
        Every input series resampled on the common time axis: ``aligned[n, l]`` is
        ``X[n][indices[n, l]]``.
    indices : ndarray of shape (N, L), int
        Sample of series ``n`` matched with step ``l`` of the common axis (non-decreasing).
    warps : ndarray of shape (N, L)
        ``indices`` as relative positions in [0, 1] (0 = first, 1 = last sample), the
        counterpart of :attr:`sk_rtw.Alignment.warps`.
    cost : float
        The objective the method minimised (its definition is given by each method).
    manifold : Manifold
    """

    mean: np.ndarray
    aligned: np.ndarray
    indices: np.ndarray
    warps: np.ndarray
    cost: float
    manifold: Manifold


def make_result(
    series: list[np.ndarray], indices: np.ndarray, mean: np.ndarray, cost: float, manifold
) -> MultipleAlignment:
    """Assemble a :class:`MultipleAlignment` from per-series index arrays ``(N, L)``."""
    indices = np.asarray(indices, dtype=np.int64)
    aligned = np.stack([s[i] for s, i in zip(series, indices, strict=True)])
    scale = np.array([max(len(s) - 1, 1) for s in series], dtype=float)[:, None]
    return MultipleAlignment(
        mean=manifold.continuous(mean),
        aligned=manifold.continuous(aligned),
        indices=indices,
        warps=indices / scale,
        cost=float(cost),
        manifold=manifold,
    )


def grouped_mean(
    manifold: Manifold,
    groups: np.ndarray,
    points: np.ndarray,
    n_groups: int,
    start: np.ndarray | None = None,
    max_iter: int = 64,
    tol: float = 1e-10,
) -> np.ndarray:
    """Fréchet mean of ``points`` per group label in ``range(n_groups)``, all at once.

    Groups of different sizes are padded to the largest one with zero-weight copies of
    their first point, so one batched Gauss–Newton run averages every group. ``start``
    ``(n_groups, *point_shape)`` puts a starting estimate first in every group (weight 0).
    """
    order = np.argsort(groups, kind="stable")
    groups, points = groups[order], points[order]
    counts = np.bincount(groups, minlength=n_groups)
    if np.any(counts == 0):
        raise ValueError("every group needs at least one point")
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    slots = np.arange(len(groups)) - starts[groups]
    offset = 0 if start is None else 1
    padded = np.repeat(points[starts][:, None], counts.max() + offset, axis=1)
    if start is not None:
        padded[:, 0] = start
    padded[groups, slots + offset] = points
    weights = np.zeros((n_groups, counts.max() + offset))
    weights[groups, slots + offset] = 1.0
    # torch in, torch out: the points were validated on the way in; a fixed number of
    # steps from a close start is what DBA asks for (tol=0: no convergence warning)
    mean = manifold.mean(
        torch.as_tensor(padded), torch.as_tensor(weights.T), axis=1, max_iter=max_iter, tol=tol
    )
    return mean.numpy()
