"""The DTW medoid of a collection: a consumer of the pairwise distances."""

from __future__ import annotations

import numpy as np

from ..utils import SeriesCollection
from ._dtw import dtw_pairwise_distance


def medoid_index(
    collection: SeriesCollection,
    candidates: np.ndarray | None = None,
    window: float | None = None,
    squared: bool = True,
    n_jobs: int | None = None,
) -> int:
    """Index of the series with the smallest summed DTW cost to the others.

    Parameters
    ----------
    collection : SeriesCollection
    candidates : ndarray of int, optional
        Only these series take part (both as candidates and as the others); default all.
    window : float in [0, 1], optional
        Sakoe–Chiba band.
    squared : bool, default=True
        Squared geodesic point costs.
    n_jobs : int, optional
        Threads of the pairwise distances (:func:`dtw_pairwise_distance`).

    Returns
    -------
    index : int
        Index into ``collection``.
    """
    index = np.arange(collection.n_series) if candidates is None else np.asarray(candidates)
    D = dtw_pairwise_distance(collection.subset(index), window=window, squared=squared,
                              n_jobs=n_jobs)  # fmt: skip
    return int(index[np.argmin(D.sum(1))])
