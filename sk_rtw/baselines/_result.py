"""The result type shared by the DTW-family baselines and their path helpers."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

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
    n_iter : int
        Refinement iterations run (DBA); 0 for the one-pass methods.
    config : object or None
        The resolved settings, when the result comes from an estimator's method object.
    fit_time : float
        Seconds the fit took, when measured by an estimator's method object.
    """

    mean: np.ndarray
    aligned: np.ndarray
    indices: np.ndarray
    warps: np.ndarray
    cost: float
    manifold: Manifold
    n_iter: int = 0
    config: Any = None
    fit_time: float = 0.0


def make_result(
    series: list[np.ndarray],
    indices: np.ndarray,
    mean: np.ndarray,
    cost: float,
    manifold,
    n_iter: int = 0,
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
        n_iter=int(n_iter),
    )
