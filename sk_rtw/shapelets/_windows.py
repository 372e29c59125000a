"""Windows of series as the sliding kernels read them: gathered with a dilation,
normalised by the manifold where asked, in the kernels' form of their space."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..dtw import kernel_point_form
from ..manifolds import Manifold
from ..utils import SeriesCollection


@dataclass(frozen=True, eq=False)
class Windows:
    """Every window of ``n`` series: ``data`` ``(n, P, l, q)`` in the kernels' form of
    ``space`` (``segments``: its codes, None where it has none: then ``points`` holds
    the windows as points of ``space``, ``(n, P, l, *point_shape)``), ``counts`` the
    valid windows of each series."""

    data: np.ndarray | None
    points: np.ndarray
    counts: np.ndarray
    space: Manifold
    segments: np.ndarray | None


def window_space(manifold: Manifold, normalised: bool) -> Manifold:
    """The space windows are compared in: the manifold, or its normalised space."""
    if not normalised:
        return manifold
    space = manifold.normalised_space
    if space is None:
        raise ValueError(f"{manifold!r} has no form of z-normalisation")
    return space


def gather_windows(
    collection: SeriesCollection, length: int, dilation: int, normalised: bool
) -> Windows:
    """The windows ``(x_t, x_{t+d}, ..., x_{t+(l-1)d})`` of every series of
    ``collection``, normalised by the manifold (:meth:`~sk_rtw.manifolds.Manifold.
    normalise_windows`) if ``normalised``, in the kernels' form of their space. A series
    of ``T`` points has ``T - (l - 1) d`` windows; one shorter than a window's span is
    read as padded with its last point (the package's padding convention): one window."""
    span = (length - 1) * dilation
    counts = np.maximum(collection.lengths - span, 1)
    n_windows = int(counts.max())
    starts = np.arange(n_windows)
    offsets = starts[:, None] + dilation * np.arange(length)[None, :]
    # windows past a series' end read its padding (never scored: counts)
    offsets = np.minimum(offsets, collection.max_length - 1)
    points = collection.data[:, offsets]  # (n, P, l, *point_shape)
    manifold = collection.manifold
    space = window_space(manifold, normalised)
    if normalised:
        points = manifold.normalise_windows(points)
    data, segments = kernel_point_form(space, points)
    return Windows(data, points, counts.astype(np.int64), space, segments)
