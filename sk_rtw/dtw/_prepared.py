"""Series prepared once for many nearest searches on the calling thread.

A proximity tree asks the same question thousands of times on subsets of one training
set: which of a few exemplars is each series nearest to, under this band, point cost and
penalty. :func:`prepare_series` puts a validated collection in the kernels' form once
(SPD blocks become their features, :mod:`._point_costs`); :meth:`PreparedSeries.take`
selects series without validating them again; :func:`nearest_group` runs the package's
nearest search (:mod:`._search`: LB_Keogh, early abandoning, the exhaustive answer) on
the calling thread, for callers that run their own threads. A manifold without compiled
point costs keeps its collection and takes the exhaustive search.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..utils import SeriesCollection
from . import _point_costs
from ._dtw import check_window
from ._search import dtw_nearest_distance, nearest_by_class_serial


@dataclass(frozen=True, eq=False)
class PreparedSeries:
    """Series in the kernels' form: ``data`` ``(n, L, p)`` (C-contiguous), ``lengths``,
    ``segments`` (the point costs' codes; None: the manifold has no kernel form and
    ``collection`` holds the series for the exhaustive search)."""

    data: np.ndarray
    lengths: np.ndarray
    segments: np.ndarray | None
    collection: SeriesCollection | None

    @property
    def n_series(self) -> int:
        return self.lengths.shape[0]

    def take(self, index: Any) -> PreparedSeries:
        """The series ``index`` (integers), in that order, padding cut to their longest."""
        index = np.asarray(index, dtype=np.int64)
        lengths = self.lengths[index]
        longest = int(lengths.max()) if len(lengths) else 0
        return PreparedSeries(
            data=np.ascontiguousarray(self.data[index, :longest]),
            lengths=lengths,
            segments=self.segments,
            collection=None if self.collection is None else self.collection.subset(index),
        )


def prepare_series(collection: SeriesCollection) -> PreparedSeries:
    """A validated collection in the kernels' form (once, for many searches)."""
    segments = _point_costs.segment_codes(collection.manifold)
    if segments is None:
        flat = collection.data.reshape(collection.n_series, collection.max_length, -1)
        return PreparedSeries(flat, collection.lengths, None, collection)
    return PreparedSeries(_point_costs.kernel_series(collection), collection.lengths,
                          segments, None)  # fmt: skip


def nearest_group(
    queries: PreparedSeries,
    references: PreparedSeries,
    groups: np.ndarray,
    n_groups: int,
    window: float | None,
    squared: bool,
    warp_penalty: float,
) -> np.ndarray:
    """For every query, the group of its nearest reference by DTW (amerced with
    ``warp_penalty``), on the calling thread: ``argmin`` of :func:`dtw_nearest_distance`
    with ``nearest_only=True`` (a tie goes to the lowest group).

    Parameters
    ----------
    queries, references : PreparedSeries
        Of one manifold (the same kernel form).
    groups : ndarray of int, shape (n_references,)
        Group of every reference, ``0..n_groups - 1``.
    n_groups : int
    window : float or None
        Sakoe-Chiba radius as a fraction of the shorter series; None: no band.
    squared : bool
        Squared point costs.
    warp_penalty : float
        Amerced DTW's penalty, at least 0.

    Returns
    -------
    nearest : ndarray of int, shape (n_queries,)
    """
    groups = np.ascontiguousarray(groups, dtype=np.int64)
    if queries.segments is None:
        assert queries.collection is not None and references.collection is not None
        distances = dtw_nearest_distance(
            queries.collection, references.collection, groups, window=window, squared=squared,
            nearest_only=True, n_jobs=1, warp_penalty=warp_penalty,
        )  # fmt: skip
        return np.argmin(distances, axis=1)
    n = queries.n_series
    none = np.full(n, -1, dtype=np.int64)
    distances, _ = nearest_by_class_serial(
        queries.data, queries.lengths, references.data, references.lengths, groups, n_groups,
        none, none, np.full(n, np.inf), False, queries.segments, bool(squared),
        check_window(window), float(warp_penalty),
    )  # fmt: skip
    return np.argmin(distances, axis=1)


def mean_diagonal_cost(
    series: PreparedSeries, first: np.ndarray, second: np.ndarray, squared: bool
) -> float:
    """The mean cost of the direct (diagonal) alignment of the pairs ``(first[k],
    second[k])`` of ``series`` (:func:`~._point_costs.diagonal_costs`): the scale of
    amerced DTW's penalty (Herrmann and Webb, 2023)."""
    first = np.ascontiguousarray(first, dtype=np.int64)
    second = np.ascontiguousarray(second, dtype=np.int64)
    if series.segments is None:  # the manifold's own distance along the diagonal
        assert series.collection is not None
        manifold = series.collection.manifold
        total = 0.0
        for a, b in zip(first, second, strict=True):
            x, y = series.collection.series(int(a)), series.collection.series(int(b))
            steps = max(len(x), len(y))
            t = np.arange(steps)
            cost = np.asarray(manifold.dist(x[t * len(x) // steps], y[t * len(y) // steps]))
            total += float((cost * cost).sum() if squared else cost.sum())
        return total / max(1, len(first))
    costs = _point_costs.diagonal_costs(series.data, series.lengths, first, second,
                                        series.segments, bool(squared))  # fmt: skip
    return float(costs.mean()) if len(costs) else 0.0
