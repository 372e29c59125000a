"""Progressive pairwise DTW averaging (p-DTW)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..dtw import check_window, path_indices
from ..manifolds import Manifold
from ..utils import check_series_collection
from ._result import MultipleAlignment, make_result


def pdtw_average(
    X: Any,
    manifold: str | Manifold = "euclidean",
    *,
    output_length: int | None = None,
    window: float | None = None,
    squared: bool = False,
) -> MultipleAlignment:
    """Average N series by aligning them one at a time to a running average (p-DTW).

    The running average starts as the first series. Series ``n`` (0-based, in input
    order) is aligned to it by manifold DTW; every matched pair is replaced by the point
    ``1/(n+1)`` of the way along the geodesic from the average to the series (the running
    Fréchet mean), which gives a sequence as long as the DTW path. That sequence is then
    resampled to ``output_length`` steps at evenly spaced path positions, so its length
    stays bounded. The sample indices of all earlier series are composed with each path,
    so every series ends up on the common time axis.

    Parameters
    ----------
    X : array-like of shape (N, T, *point_shape) or list of (T_n, *point_shape) series
        Input series, merged in this order.
    manifold : str or Manifold, default="euclidean"
        Space of the samples.
    output_length : int, optional
        Length of the average. Default: the longest input series.
    window : float in [0, 1], optional
        Sakoe–Chiba band of each pairwise DTW.
    squared : bool, default=False
        Use squared geodesic costs in the pairwise DTW.

    Returns
    -------
    MultipleAlignment
        ``mean`` of shape ``(output_length, *point_shape)``; ``cost`` is the summed DTW
        cost of the pairwise merges.
    """
    collection = check_series_collection(X, manifold, name="X", min_length=1)
    M = collection.manifold
    w = check_window(window)
    length = collection.max_length if output_length is None else output_length
    if isinstance(length, bool) or not isinstance(length, (int, np.integer)) or length < 1:
        raise ValueError(f"output_length must be a positive integer, got {output_length!r}")
    series = [collection.series(i) for i in range(collection.n_series)]

    def resample(n_steps: int) -> np.ndarray:
        return np.round(np.linspace(0, n_steps - 1, length)).astype(np.int64)

    pick = resample(len(series[0]))
    mean = series[0][pick]
    indices = [pick]
    total = 0.0
    for n, x in enumerate(series[1:], start=1):
        path, cost = path_indices(mean, x, M, w, squared)
        total += cost
        a, b = mean[path[:, 0]], x[path[:, 1]]
        merged = M.exp(a, M.log(a, b) / (n + 1))
        pick = resample(len(path))
        mean = merged[pick]
        indices = [idx[path[pick, 0]] for idx in indices] + [path[pick, 1]]
    return make_result(series, np.stack(indices), mean, total, M)
