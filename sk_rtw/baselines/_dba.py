"""DTW barycenter averaging (DBA) on a Riemannian manifold."""

from __future__ import annotations

import sys
from typing import Any

import numpy as np
import torch

from ..dtw import check_window, coarse_collection, medoid_index, path_indices
from ..manifolds import Manifold
from ..manifolds._mean import frechet_mean
from ..utils import check_series_collection
from ..utils._constraints import Interval
from ..utils._params import Parameter
from ._result import MultipleAlignment, make_result

#: Gauss–Newton steps of each per-sample Fréchet mean in one DBA iteration.
MEAN_STEPS = 8
MAX_ITER = Parameter("max_iter", (Interval(int, 1),), "Most refinement iterations.")
TOL = Parameter("tol", (Interval(float, 0.0),), "Relative cost improvement that counts.")


#: Series longer than this choose the starting medoid on copies halved by geodesic
#: midpoints to at most this many samples: the all-pairs DTW of N series costs N / 2
#: iterations' worth (for 8 quaternion series of 4,000 samples, a third of the fit).
MEDOID_LENGTH = 2000


def _initial_mean(collection, init, window, squared) -> np.ndarray:
    if isinstance(init, str):
        if init != "medoid":
            raise ValueError(f"init must be 'medoid' or a series, got {init!r}")
        candidates = collection
        if collection.max_length > MEDOID_LENGTH:
            series = [collection.series(i) for i in range(collection.n_series)]
            candidates = coarse_collection(series, collection.manifold, MEDOID_LENGTH)
        return collection.series(medoid_index(candidates, window=window, squared=squared))
    start = check_series_collection([init], collection.manifold, name="init", min_length=1)
    return start.series(0)


def dba_average(
    X: Any,
    manifold: str | Manifold = "euclidean",
    *,
    max_iter: int = 10,
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
    max_iter : int, default=10
        Most refinement iterations.
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
        series to the returned mean; ``n_iter`` the refinement iterations run.
    """
    max_iter, tol = MAX_ITER.check(max_iter), TOL.check(tol)
    collection = check_series_collection(X, manifold, name="X", min_length=1)
    M = collection.manifold
    w = check_window(window)
    series = [collection.series(i) for i in range(collection.n_series)]
    mean = _initial_mean(collection, init, window, squared)
    best: tuple[float, np.ndarray, tuple[np.ndarray, ...]] | None = None
    previous = np.inf
    iteration = 0
    N = len(series)
    guides: tuple[np.ndarray | None, ...] = (None,) * N
    for iteration in range(max_iter + 1):
        # the previous paths are paths to the new mean too: their costs bound the search
        found = [path_indices(mean, series[n], M, w, squared, guides[n]) for n in range(N)]
        paths, costs = zip(*found, strict=True)
        guides = paths
        cost = float(sum(costs))
        if best is None or cost < best[0]:
            best = (cost, mean, paths)
        if verbose:
            print(f"DBA iteration {iteration}: cost {cost:.6g}", file=sys.stderr)
        if iteration == max_iter or (iteration > 0 and previous - cost <= tol * previous):
            break
        previous = cost
        mean = _matched_means(M, series, paths, mean)
    assert best is not None  # the loop runs at least once
    cost, mean, paths = best
    first = [np.searchsorted(p[:, 0], np.arange(len(mean))) for p in paths]
    indices = np.stack([p[f, 1] for p, f in zip(paths, first, strict=True)])
    return make_result(series, indices, mean, cost, M, n_iter=iteration)


def _matched_means(manifold: Manifold, series, paths, mean: np.ndarray) -> np.ndarray:
    """Every sample of the average replaced by the Fréchet mean of the points matched to
    it, by Gauss–Newton steps from the previous average (it is close: a few suffice)."""
    codes = np.concatenate([p[:, 0] for p in paths])
    points = np.concatenate([s[p[:, 1]] for s, p in zip(series, paths, strict=True)])
    with torch.no_grad():
        new = frechet_mean(
            manifold, torch.as_tensor(points), codes=torch.as_tensor(codes),
            start=torch.as_tensor(mean), max_iter=MEAN_STEPS, tol=0.0, differentiate="none",
        )  # fmt: skip
    return new.numpy()
