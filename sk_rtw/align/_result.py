"""What :func:`sk_rtw.align` returns: the mean, the aligned series, the warps and how
the fit went."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..manifolds import Manifold
from ._config import AlignmentConfig


@dataclass(frozen=True, eq=False)
class Alignment:
    """Result of :func:`align`.

    Attributes
    ----------
    mean : ndarray of shape (Z, *point_shape)
        Riemannian mean of the aligned signals (on the manifold).
    aligned : ndarray of shape (N, Z, *point_shape)
        Every signal resampled along its warp.
    warps : ndarray of shape (N, Z)
        Warping functions in [0, 1]: ``aligned[n, z]`` is signal ``n`` at relative
        position ``warps[n, z]`` (0 = first sample, 1 = last sample).
    loss_history : ndarray of shape (n_epochs,)
        Total loss (alignment loss + penalty) at every epoch; NaN after an early stop.
    best_epoch : int
        Epoch whose parameters are returned (lowest total loss); -1 when nothing was
        optimised (a single signal, or ``n_epochs=0``).
    manifold : Manifold
    config : AlignmentConfig
    fit_time : float
        Seconds the fit took (for a batch of groups: the whole batch).
    n_iter : int
        Epochs run (fewer than ``config.n_epochs`` after an early stop).
    cost : float
        The loss (alignment loss + penalty) at the returned warps.
    """

    mean: np.ndarray
    aligned: np.ndarray
    warps: np.ndarray
    loss_history: np.ndarray
    best_epoch: int
    manifold: Manifold
    config: AlignmentConfig
    fit_time: float = field(default=0.0)
    n_iter: int = field(default=0)
    cost: float = field(default=float("nan"))
