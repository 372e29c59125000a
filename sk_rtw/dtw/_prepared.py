"""Series prepared once for many nearest searches on the calling thread.

A proximity tree asks the same question thousands of times on subsets of one training
set: which of a few exemplars is each series nearest to, under this band, point cost and
penalty. :func:`prepare_series` puts a validated collection in the kernels' form once
(SPD blocks become their features, :mod:`._point_costs`); :meth:`PreparedSeries.take`
selects series without validating them again; :func:`nearest_group` runs the package's
nearest search (:mod:`._search`: LB_Keogh, early abandoning, the exhaustive answer) on
the calling thread, for callers that run their own threads, with a point cost that is
the geodesic distance to the power 1/2, 1 or 2 (:data:`EXPONENTS`). A manifold without
compiled point costs keeps its collection and takes the exhaustive search.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..utils import SeriesCollection
from . import _kernels, _point_costs
from ._costs import point_cost_matrix
from ._dtw import check_window
from ._search import nearest_by_class_serial


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


#: The point-cost exponents of the prepared searches: the point cost is the geodesic
#: distance raised to one of them (Proximity Forest 2.0's cost-function exponents).
EXPONENTS = (0.5, 1.0, 2.0)


def _cost_flags(exponent: float) -> tuple[bool, bool]:
    """The kernels' ``(squared, root)`` for a point-cost exponent of :data:`EXPONENTS`."""
    if exponent not in EXPONENTS:
        raise ValueError(f"the point-cost exponent must be one of {EXPONENTS}, got {exponent!r}")
    return exponent == 2.0, exponent == 0.5


def nearest_group(
    queries: PreparedSeries,
    references: PreparedSeries,
    groups: np.ndarray,
    n_groups: int,
    window: float | None,
    exponent: float,
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
    exponent : {0.5, 1.0, 2.0}
        The point cost is the geodesic distance to this power.
    warp_penalty : float
        Amerced DTW's penalty, at least 0.

    Returns
    -------
    nearest : ndarray of int, shape (n_queries,)
    """
    groups = np.ascontiguousarray(groups, dtype=np.int64)
    squared, root = _cost_flags(exponent)
    w = check_window(window)
    n = queries.n_series
    if queries.segments is None:
        return np.argmin(_exhaustive(queries, references, groups, n_groups, w, exponent,
                                     float(warp_penalty)), axis=1)  # fmt: skip
    none = np.full(n, -1, dtype=np.int64)
    distances, _ = nearest_by_class_serial(
        queries.data, queries.lengths, references.data, references.lengths, groups, n_groups,
        none, none, np.full(n, np.inf), False, queries.segments, squared, w,
        float(warp_penalty), root,
    )  # fmt: skip
    return np.argmin(distances, axis=1)


def _exhaustive(queries, references, groups, n_groups, window, exponent, penalty) -> np.ndarray:
    """:func:`nearest_group`'s distances for a manifold without compiled point costs:
    every pair's cost matrix from the manifold's distances, then the recursion."""
    assert queries.collection is not None and references.collection is not None
    out = np.full((queries.n_series, n_groups), np.inf)
    manifold = queries.collection.manifold
    for q in range(queries.n_series):
        x = queries.collection.series(q)
        for r in range(references.n_series):
            y = references.collection.series(r)
            costs = point_cost_matrix(x, y, manifold) ** exponent
            value = _kernels.final_cost(costs, len(x), len(y), window, penalty)
            out[q, groups[r]] = min(out[q, groups[r]], value)
    return out


def mean_diagonal_cost(
    series: PreparedSeries, first: np.ndarray, second: np.ndarray, exponent: float
) -> float:
    """The mean cost of the direct (diagonal) alignment of the pairs ``(first[k],
    second[k])`` of ``series`` (:func:`~._point_costs.diagonal_costs`), the point cost the
    distance to ``exponent``: the scale of amerced DTW's penalty (Herrmann and Webb,
    2023)."""
    squared, root = _cost_flags(exponent)
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
            total += float((cost**exponent).sum())
        return total / max(1, len(first))
    costs = _point_costs.diagonal_costs(series.data, series.lengths, first, second,
                                        series.segments, squared, root)  # fmt: skip
    return float(costs.mean()) if len(costs) else 0.0
