"""Shapelets on Euclidean coordinates with their windows read in place: one shapelet
against the windows of a few series without gathering the windows first.

The forest's shapelet candidates take one shapelet at a node and compare it with the
node's series: gathering and normalising every window with numpy there costs more than
the distances. On Euclidean coordinates (the raw series of R^d, and the tangent velocity
of every manifold) the compiled kernels of :mod:`sk_rtw.dtw` read each window from the
series and z-normalise it as :meth:`~sk_rtw.manifolds.Euclidean.normalise_windows` does,
bit for bit. What they give equals :func:`~._shapelet.draw_shapelets` and
:func:`~._shapelet.features` of the same draws, with one difference: a batch of one
series is summed as a batch of many (numpy's order of summation depends on the memory
layout it reduces), so a series routes the same alone and with others.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..dtw import (
    kernel_point_form,
    linear_percentiles,
    read_window,
    series_window_feature,
    series_window_profile,
)
from ..manifolds import Euclidean, Manifold
from ..manifolds._euclidean import STD_FLOOR
from ..utils import SeriesCollection
from ._shapelet import FEATURES, Shapelet, Sites


def reads_in_place(manifold: Manifold) -> bool:
    """Whether windows of ``manifold``'s series are read in place: Euclidean
    coordinates, normalised by Euclidean's z-normalisation."""
    return (
        isinstance(manifold, Euclidean)
        and type(manifold).normalise_windows is Euclidean.normalise_windows
    )


@lru_cache(maxsize=64)
def _segments(manifold: Manifold, q: int) -> np.ndarray:
    """The kernels' segment codes of ``manifold`` (kept per value: a frozen dataclass)."""
    _, segments = kernel_point_form(manifold, np.zeros((1, q)))
    assert segments is not None
    return segments


def take_shapelet(
    collection: SeriesCollection,
    name: str,
    sites: Sites,
    j: int,
    codes: np.ndarray,
    percentiles: tuple[float, float],
) -> Shapelet:
    """Shapelet ``j`` of ``sites`` (drawn from ``collection``, the representation
    ``name``) with its points and threshold: :func:`~._shapelet.draw_shapelets`'s, one
    shapelet at a time."""
    data = collection.data
    q = data.shape[-1]
    length, dilation = int(sites.length[j]), int(sites.dilation[j])
    normalised = bool(sites.normalised[j])
    series, start, other = int(sites.series[j]), int(sites.start[j]), int(sites.other[j])
    # numpy sums one univariate shapelet, and the windows of one univariate series, in
    # its pairwise order (a contiguous axis)
    pairwise = q == 1
    points = np.empty((length, q))
    scratch = np.empty((length, q))
    read_window(data[series], start, length, dilation, normalised, pairwise, STD_FLOOR,
                points, scratch)  # fmt: skip
    n_windows = max(int(collection.lengths[other]) - (length - 1) * dilation, 1)
    profile = np.empty(n_windows)
    segments = _segments(collection.manifold, q)
    series_window_profile(data[other], n_windows, points, dilation, normalised, pairwise,
                          STD_FLOOR, segments, profile)  # fmt: skip
    bounds = np.empty(2)
    linear_percentiles(profile, n_windows, np.asarray(percentiles, dtype=np.float64), bounds)
    low, high = bounds
    threshold = float(low + sites.uniform[j] * (high - low))
    return Shapelet(name, normalised, length, dilation, points, threshold, (series, start),
                    int(codes[series]))  # fmt: skip


def feature_in_place(
    collection: SeriesCollection, rows: np.ndarray, shapelet: Shapelet, feature: str
) -> np.ndarray:
    """One feature of ``shapelet`` (``"min"``, ``"argmin"`` or ``"count"``) for the
    series ``rows`` of ``collection``: :func:`~._shapelet.features`' column."""
    q = collection.data.shape[-1]
    n_windows = np.maximum(collection.lengths[rows] - (shapelet.span - 1), 1)
    out = np.empty(len(rows))
    series_window_feature(
        collection.data, np.asarray(rows, dtype=np.int64), n_windows.astype(np.int64),
        np.ascontiguousarray(shapelet.points, dtype=np.float64), shapelet.dilation,
        shapelet.normalised, STD_FLOOR, shapelet.threshold, FEATURES.index(feature),
        _segments(collection.manifold, q), out,
    )  # fmt: skip
    return out
