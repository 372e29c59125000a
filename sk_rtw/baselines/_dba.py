"""DTW barycenter averaging (DBA) on a Riemannian manifold."""

from __future__ import annotations

import sys
from typing import Any

import numpy as np

from ..dtw import check_window, medoid_index, path_indices
from ..manifolds import Manifold
from ..utils import check_series_collection
from ._result import MultipleAlignment, grouped_mean, make_result

#: Gauss–Newton steps of each per-sample Fréchet mean in one DBA iteration.
MEAN_STEPS = 8


def _initial_mean(collection, init, window, squared) -> np.ndarray:
    if isinstance(init, str):
        if init != "medoid":
            raise ValueError(f"init must be 'medoid' or a series, got {init!r}")
        return collection.series(medoid_index(collection, window=window, squared=squared))
    start = check_series_collection([init], collection.manifold, name="init", min_length=1)
    return start.series(0)


def dba_average(
    X: Any,
    manifold: str | Manifold = "euclidean",
    *,
    n_iter: int = 10,
    init: str | Any = "medoid",
    window: float | None = None,
    squared: bool = True,
    tol: float = 1e-5,
    verbose: bool = False,
) -> MultipleAlignment:
    """DTW barycenter averaging with Fréchet means of the matched points.

    Each iteration aligns every series to the current average by manifold DTW and
    replaces each sample of the average by the Fréchet mean of all the points matched to
    it (Petitjean et al., 2011, with the arithmetic mean replaced by the Riemannian one).
    The average keeps the length of its initialisation.

    Parameters
    ----------
    X : array-like of shape (N, T, *point_shape) or list of (T_n, *point_shape) series
        Input series.
    manifold : str or Manifold, default="euclidean"
        Space of the samples.
    n_iter : int, default=10
        Maximum number of refinement iterations.
    init : "medoid" or array-like of shape (L, *point_shape), default="medoid"
        Starting average: the series with the smallest summed DTW to the others, or the
        given series.
    window : float in [0, 1], optional
        Sakoe–Chiba band of the DTW alignments.
    squared : bool, default=True
        Align with squared geodesic costs, the objective that a Fréchet mean minimises.
    tol : float, default=1e-5
        Stop when the summed DTW cost improves by less than this fraction.
    verbose : bool, default=False
        Print the cost after every iteration.

    Returns
    -------
    MultipleAlignment
        ``mean`` of shape ``(L, *point_shape)``; ``indices[n, l]`` is the first sample of
        series ``n`` matched with ``mean[l]``; ``cost`` is the summed DTW cost of the
        series to the returned mean.
    """
    if isinstance(n_iter, bool) or not isinstance(n_iter, (int, np.integer)) or n_iter < 1:
        raise ValueError(f"n_iter must be a positive integer, got {n_iter!r}")
    collection = check_series_collection(X, manifold, name="X", min_length=1)
    M = collection.manifold
    w = check_window(window)
    series = [collection.series(i) for i in range(collection.n_series)]
    mean = _initial_mean(collection, init, window, squared)
    best: tuple[float, np.ndarray, tuple[np.ndarray, ...]] | None = None
    previous = np.inf
    for iteration in range(n_iter + 1):
        paths, costs = zip(*(path_indices(mean, s, M, w, squared) for s in series), strict=True)
        cost = float(sum(costs))
        if best is None or cost < best[0]:
            best = (cost, mean, paths)
        if verbose:
            print(f"DBA iteration {iteration}: cost {cost:.6g}", file=sys.stderr)
        if iteration == n_iter or (iteration > 0 and previous - cost <= tol * previous):
            break
        previous = cost
        groups = np.concatenate([p[:, 0] for p in paths])
        points = np.concatenate([s[p[:, 1]] for s, p in zip(series, paths, strict=True)])
        # Gauss–Newton from the previous average: it is close, so a few steps suffice.
        mean = grouped_mean(M, groups, points, len(mean), start=mean, max_iter=MEAN_STEPS, tol=0.0)
    assert best is not None  # the loop runs at least once
    cost, mean, paths = best
    first = [np.searchsorted(p[:, 0], np.arange(len(mean))) for p in paths]
    indices = np.stack([p[f, 1] for p, f in zip(paths, first, strict=True)])
    return make_result(series, indices, mean, cost, M)
