"""Alignment metrics of the paper (eqs. 20a-c), computed with manifold DTW.

All three are sums over the N signals of DTW distances with the geodesic point cost. By
default each DTW distance is normalised by the length of its optimal path
(``normalize="path"``): the mean geodesic cost per matched pair, so that results obtained
with different output lengths ``Z`` can be compared. Pass ``normalize=None`` for the
accumulated (unnormalised) cost.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .dtw import dtw_pairwise_distance
from .manifolds import Manifold
from .utils import check_series_collection

__all__ = ["alignment_quality", "barycenter_loss", "restoration_accuracy"]


def _sum_dtw_to(series: Any, reference: Any, manifold, normalize, window, n_jobs) -> float:
    collection = check_series_collection(series, manifold, name="series", min_length=1)
    reference = np.asarray(reference)
    if reference.ndim == 0:
        raise ValueError(
            f"the reference must be one series of shape (T, *point_shape), got the scalar "
            f"{reference!r}"
        )
    ref = check_series_collection([reference], collection.manifold, name="reference", min_length=1)
    distances = dtw_pairwise_distance(
        collection, ref, normalize=normalize, window=window, n_jobs=n_jobs
    )
    return float(distances.sum())


def restoration_accuracy(
    aligned: Any,
    original: Any,
    manifold: str | Manifold = "euclidean",
    normalize: str | None = "path",
    window: float | None = None,
    n_jobs: int | None = None,
) -> float:
    """``sum_n D_dtw(aligned_n, original)``: how well the warps were undone (eq. 20a).

    Parameters
    ----------
    aligned : array-like, shape (N, Z, *point_shape) or list of series
    original : array-like, shape (T, *point_shape)
    manifold : str or Manifold, default="euclidean"
    normalize : {"path", None}, default="path"
        DTW normalisation (see the module docstring).
    window : float in [0, 1], optional
        Sakoe–Chiba band of the DTW (default: none, as in the paper). A narrow band keeps
        DTW from undoing large warps itself, which makes the metric sensitive to them.
    n_jobs : int, optional
        Threads for the DTW computations.
    """
    return _sum_dtw_to(aligned, original, manifold, normalize, window, n_jobs)


#: The parameters and result shared by the two sums of DTW distances to a mean.
_TO_THE_MEAN = """mean : array-like, shape (Z, *point_shape)
manifold : str or Manifold, default="euclidean"
normalize : {"path", None}, default="path"
    DTW normalisation (see the module docstring).
window : float in [0, 1], optional
    Sakoe–Chiba band of the DTW (default: none, as in the paper).
n_jobs : int, optional
    Threads for the DTW computations.

Returns
-------
value : float
    Sum over the N series; lower is better."""


def _to_the_mean_docs(function):
    body = _TO_THE_MEAN.replace("\n", "\n    ").replace("\n    \n", "\n\n")
    function.__doc__ = function.__doc__.replace("%(to_the_mean)s", body)
    return function


@_to_the_mean_docs
def barycenter_loss(
    signals: Any,
    mean: Any,
    manifold: str | Manifold = "euclidean",
    normalize: str | None = "path",
    window: float | None = None,
    n_jobs: int | None = None,
) -> float:
    """``sum_n D_dtw(x_n, mean)``: how well the mean represents the input (eq. 20b).

    Parameters
    ----------
    signals : array-like, shape (N, T, *point_shape) or list of series
        The input series (before alignment).
    %(to_the_mean)s
    """
    return _sum_dtw_to(signals, mean, manifold, normalize, window, n_jobs)


@_to_the_mean_docs
def alignment_quality(
    aligned: Any,
    mean: Any,
    manifold: str | Manifold = "euclidean",
    normalize: str | None = "path",
    window: float | None = None,
    n_jobs: int | None = None,
) -> float:
    """``sum_n D_dtw(aligned_n, mean)``: closeness of the aligned signals to their mean
    (eq. 20c).

    Parameters
    ----------
    aligned : array-like, shape (N, Z, *point_shape) or list of series
        The aligned series.
    %(to_the_mean)s
    """
    return _sum_dtw_to(aligned, mean, manifold, normalize, window, n_jobs)
