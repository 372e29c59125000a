"""Starting warps read off DTW paths to a reference series (RTW's default start).

Gradient descent from identity warps only finds nearby alignments: on the UCR development
archive, RTW's loss from the identity stays about twice as high as the loss of warps read
off DTW paths (docs: class means). The DTW start:

1. reference: the DTW medoid (squared geodesic costs) of at most
   :data:`MEDOID_CANDIDATES` series drawn with the fit's random generator (on copies
   halved in length where the all-pairs DTW would exceed :data:`MEDOID_CELLS` cells);
2. for every series the DTW path to the reference (coarse to fine in a band for long
   pairs, :func:`sk_rtw.dtw.multiscale_path`); the warp at reference sample ``l``
   is the mean index of the series samples matched with it, as a relative position in
   [0, 1], made non-decreasing, with the ends at 0 and 1, and smoothed by a Gaussian of
   :data:`SMOOTHING` samples (monotonicity and ends kept);
3. time axis: the common time axis is the reference's (``axis="reference"``, as DBA's)
   or is reparametrised so that the average warp is the identity (``axis="average"``, the
   mean time of the paper's warp basis); the warps are sampled at the ``Z`` output times;
4. rounds: the engine's mean of the series resampled along these warps (at the ``Z``
   output times) becomes the next reference; ``rounds`` references in all.

Several groups (the classes of an estimator) each get their own reference, rounds and
centring.

The engine then learns the paper's warps ``phi_n`` (identity plus network on the
orthonormal basis, with the monotonicity penalty) and uses ``w_n = s_n ∘ phi_n``: a
composition of monotone maps, so the learned part keeps the paper's form and constraint.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
import torch

from .._settings import START_AXES
from .._threads import thread_map
from ..dtw import (
    check_window,
    coarse_collection,
    has_compiled_costs,
    mean_matched_positions,
    medoid_index,
    multiscale_path,
    path_indices,
    solved_exactly,
)
from ..manifolds import Manifold
from ..utils import SeriesCollection
from ._layout import GroupLayout

#: Series among which the first reference (the DTW medoid) is chosen.
MEDOID_CANDIDATES = 64


def path_warp(
    path: np.ndarray, n_reference: int, length: int, smoothing: float | None = None
) -> np.ndarray:
    """Relative position in a series of every reference sample, from a DTW path.

    Parameters
    ----------
    path : ndarray of shape (P, 2), int
        ``(reference index, series index)`` pairs of a DTW path.
    n_reference : int
        Length of the reference.
    length : int
        Length of the series.
    smoothing : float, optional
        Standard deviation, in reference samples, of the Gaussian that smooths the
        staircase read off the path (default :data:`SMOOTHING`; 0: none).

    Returns
    -------
    warp : ndarray of shape (n_reference,)
        Non-decreasing, 0 at the first and 1 at the last reference sample.
    """
    sums = np.bincount(path[:, 0], weights=path[:, 1], minlength=n_reference)
    counts = np.bincount(path[:, 0], minlength=n_reference)
    return position_warp(sums / counts, length, smoothing)


def position_warp(
    positions: np.ndarray, length: int, smoothing: float | None = None
) -> np.ndarray:
    """:func:`path_warp` from the mean matched index of every reference sample."""
    warp = np.maximum.accumulate(positions / max(length - 1, 1))
    warp[0], warp[-1] = 0.0, 1.0
    smoothing = SMOOTHING if smoothing is None else smoothing
    if smoothing > 0 and len(warp) > 2:
        warp = _smooth_monotone(warp, smoothing)
    return warp


#: Standard deviation, in reference samples, of the Gaussian that smooths the warps read
#: off DTW paths (staircases, whose corners leave stair-like artefacts in the aligned
#: series). Measured: S^1, N = 4, alignment quality 0.024 -> 0.013 (the paper
#: configuration: 0.016); nearest-centroid accuracy on the UCR development archive
#: unchanged (0.756 -> 0.757).
SMOOTHING = 2.0


def _smooth_monotone(warp: np.ndarray, sigma: float) -> np.ndarray:
    """Gaussian smoothing that keeps a warp non-decreasing and its ends at 0 and 1."""
    # the kernel never exceeds the warp: beyond its length it would only flatten it more
    radius = min(int(np.ceil(3 * sigma)), len(warp) - 1)
    offsets = np.arange(-radius, radius + 1)
    kernel = np.exp(-0.5 * (offsets / sigma) ** 2)
    # odd reflection about the ends keeps the end values and the monotonicity (np.pad's
    # "reflect" with reflect_type="odd", value for value, without its overhead)
    padded = np.concatenate(
        (2 * warp[0] - warp[radius:0:-1], warp, 2 * warp[-1] - warp[-2 : -radius - 2 : -1])
    )
    smooth = np.convolve(padded, kernel / kernel.sum(), mode="valid")
    smooth = (smooth - smooth[0]) / (smooth[-1] - smooth[0])
    return np.maximum.accumulate(np.clip(smooth, 0.0, 1.0))


#: Time axes of the DTW start: ``"average"`` reparametrises the common axis so that the
#: average warp is the identity (the mean has the average timing of the series);
#: ``"reference"`` keeps the time axis of the reference (the medoid), as DBA's mean does.


def reference_warps(warps: np.ndarray, n_points: int) -> np.ndarray:
    """Warps ``(N, L)`` on the reference's time axis, resampled at ``n_points`` times."""
    grid = np.linspace(0.0, 1.0, warps.shape[1])
    times = np.linspace(0.0, 1.0, n_points)
    return np.stack([np.interp(times, grid, w) for w in warps])


def centred_warps(warps: np.ndarray, n_points: int) -> np.ndarray:
    """Warps ``(N, L)`` on the reference's time axis, resampled at ``n_points`` times of
    the axis on which their average is the identity.

    Parameters
    ----------
    warps : ndarray of shape (N, L)
        Non-decreasing warps from 0 to 1.
    n_points : int

    Returns
    -------
    ndarray of shape (N, n_points)
    """
    grid = np.linspace(0.0, 1.0, warps.shape[1])
    # the average warp, made strictly increasing so that it can be inverted
    average = warps.mean(0) + 1e-9 * grid
    average = (average - average[0]) / (average[-1] - average[0])
    times = np.interp(np.linspace(0.0, 1.0, n_points), average, grid)
    return np.stack([np.interp(times, grid, w) for w in warps])


def reference_medoid(
    series: list[np.ndarray],
    manifold: Manifold,
    rng: np.random.Generator,
    window: float | None = None,
    n_threads: int = 1,
) -> np.ndarray:
    """The first reference: the DTW medoid of (at most :data:`MEDOID_CANDIDATES`) series.

    The all-pairs DTW costs ``N^2 T^2 / 2`` cells (a minute for 12 robot demonstrations of
    3,000 samples); beyond :data:`MEDOID_CELLS` the medoid is chosen on copies halved by
    geodesic midpoints until it fits, and the full-length series it designates is
    returned.
    """
    index = np.arange(len(series))
    if len(series) > MEDOID_CANDIDATES:
        index = np.sort(rng.choice(len(series), MEDOID_CANDIDATES, replace=False))
    if len(index) == 1:
        return series[int(index[0])]
    length = max(len(series[i]) for i in index)
    pairs = len(index) * (len(index) - 1) / 2
    while length > 16 and pairs * length**2 > MEDOID_CELLS:
        length = (length + 1) // 2
    collection = coarse_collection([series[i] for i in index], manifold, length)
    return series[int(index[medoid_index(collection, window=window, n_jobs=n_threads)])]


#: DTW cells of the all-pairs medoid search beyond which the series are halved first.
MEDOID_CELLS = 2e8


def dtw_start(
    collection: SeriesCollection,
    layout: GroupLayout,
    n_points: int,
    rounds: int,
    mean_along: Callable[[torch.Tensor], torch.Tensor],
    rngs: list[np.random.Generator],
    smoothing: float | None = None,
    axis: str = "average",
    window: float | None = None,
    n_threads: int = 1,
    report: Callable[[str], None] | None = None,
) -> np.ndarray:
    """Starting warps ``(N, n_points)`` from DTW paths (see the module docstring).

    Parameters
    ----------
    collection : SeriesCollection
        The series to align (all groups, stacked).
    layout : GroupLayout
        Group of every series; each group gets its own reference and centring.
    n_points : int
        Output length ``Z``.
    rounds : int
        References used: the medoid, then the mean of each round.
    mean_along : callable
        Warps (N, L) tensor -> the mean of every group along them (n_groups, L,
        *point_shape) tensor: the engine's interpolation and mean.
    rngs : list of numpy.random.Generator
        One per group; draws the medoid candidates.
    smoothing : float, optional
        Gaussian smoothing of the path warps, in reference samples (default
        :data:`SMOOTHING`).
    axis : {"average", "reference"}, default="average"
        Time axis of the returned warps (:data:`START_AXES`).
    window : float in [0, 1] or None
        Sakoe-Chiba band of the medoid search and of the paths (None: no band; long
        pairs are then solved coarse to fine).
    n_threads : int, default=1
        Threads for the paths solved one by one (long pairs coarse to fine, or without
        compiled costs); each path is the same on any number of threads.
    report : callable, optional
        Receives a line after the medoid and after each round (``verbose``: on long
        series the start can take longer than training).

    Returns
    -------
    warps : ndarray of shape (N, n_points)
    """
    if axis not in START_AXES:
        raise ValueError(f"axis must be one of {START_AXES}, got {axis!r}")
    on_axis = centred_warps if axis == "average" else reference_warps
    manifold = collection.manifold
    series = [collection.series(i) for i in range(collection.n_series)]
    members = [layout.members(g) for g in range(layout.n_groups)]
    clock = time.perf_counter()
    references = [
        reference_medoid([series[i] for i in idx], manifold, rng, window, n_threads)
        for idx, rng in zip(members, rngs, strict=True)
    ]
    if report is not None:
        report(f"DTW start: {len(references)} medoid(s) in {time.perf_counter() - clock:.1f} s")
    # later references: the group mean at the output length
    ref_points = [n_points for _ in members]
    codes = layout.codes.cpu().numpy()
    stacked = (collection.data.reshape(collection.n_series, collection.max_length, -1),
               collection.lengths)  # fmt: skip
    along: list[np.ndarray] = []
    for round_ in range(rounds):
        previous = list(along)
        clock = time.perf_counter()
        along = _path_warps(references, series, stacked, codes, manifold, window, smoothing,
                            n_threads)  # fmt: skip
        if report is not None:
            report(f"DTW start: round {round_ + 1}/{rounds}, {len(series)} paths in "
                   f"{time.perf_counter() - clock:.1f} s")  # fmt: skip
        if round_ == rounds - 1 or (
            round_ > 1 and all(np.array_equal(a, b) for a, b in zip(along, previous, strict=True))
        ):  # a fixed point: the next reference would be this one again
            break
        length = max(ref_points)
        warps = np.empty((len(series), length))
        for g, idx in enumerate(members):
            group = on_axis(np.stack([along[i] for i in idx]), ref_points[g])
            # groups with shorter references: pad with the end value (ignored below)
            warps[idx] = np.pad(group, ((0, 0), (0, length - ref_points[g])), mode="edge")
        means = mean_along(torch.as_tensor(warps)).cpu().numpy()
        references = [means[g, : ref_points[g]] for g in range(layout.n_groups)]
    warps = np.empty((len(series), n_points))
    for idx in members:
        if len(idx) == 1:  # a series alone: its mean is itself, its warp the identity
            warps[idx] = np.linspace(0.0, 1.0, n_points)
        else:
            warps[idx] = on_axis(np.stack([along[i] for i in idx]), n_points)
    return warps


def _path_warps(
    references: list[np.ndarray],
    series: list[np.ndarray],
    stacked: tuple[np.ndarray, np.ndarray],
    codes: np.ndarray,
    manifold: Manifold,
    window: float | None,
    smoothing: float | None,
    n_threads: int = 1,
) -> list[np.ndarray]:
    """:func:`path_warp` of every series' DTW path (squared costs) to the reference of
    its group: in a band if ``window`` is given, else coarse to fine for long pairs.

    The pairs whose path is exact (a band, or short enough for
    :func:`~sk_rtw.dtw.multiscale_path` to solve them exactly) go through one
    compiled pass (:func:`~sk_rtw.dtw.mean_matched_positions`: the same paths, no
    Python per pair); the others one by one, on ``n_threads`` threads. ``stacked``: the
    same series as one padded ``(N, T_max, p)`` array and their lengths.
    """
    band = check_window(window)
    compiled = has_compiled_costs(manifold)
    exact = [
        n for n, s in enumerate(series)
        if compiled
        and ((0.0 <= band < 1.0) or solved_exactly(len(references[codes[n]]), len(s)))
    ]  # fmt: skip
    warps: list[np.ndarray] = [np.empty(0)] * len(series)
    if exact:
        lengths = stacked[1][exact]
        # padding read as the last sample (on the manifold), then the kernels' form
        last = np.minimum(np.arange(stacked[0].shape[1]), lengths[:, None] - 1)
        padded = np.take_along_axis(stacked[0][exact], last[:, :, None], axis=1)
        positions = mean_matched_positions(
            _stack(references), np.array([len(r) for r in references]), padded, lengths,
            codes[exact], manifold, band, squared=True,
        )  # fmt: skip
        for row, n in enumerate(exact):
            length = len(references[codes[n]])
            warps[n] = position_warp(positions[row, :length], len(series[n]), smoothing)

    def one_by_one(n: int) -> np.ndarray:
        reference = references[codes[n]]
        if window is None:
            path, _ = multiscale_path(reference, series[n], manifold, squared=True)
        else:
            path, _ = path_indices(reference, series[n], manifold, band, squared=True)
        return path_warp(path, len(reference), len(series[n]), smoothing)

    rest = sorted(set(range(len(series))) - set(exact))
    for n, warp in zip(rest, thread_map(one_by_one, rest, n_threads), strict=True):
        warps[n] = warp
    return warps


def _stack(arrays: list[np.ndarray]) -> np.ndarray:
    """The references (a few) as one ``(G, L_max, p)`` float64 array, padded by repeating
    each one's last sample (padding stays on the manifold)."""
    out = np.empty((len(arrays), max(len(a) for a in arrays), int(np.prod(arrays[0].shape[1:]))))
    for k, a in enumerate(arrays):
        out[k, : len(a)] = a.reshape(len(a), -1)
        out[k, len(a) :] = out[k, len(a) - 1]
    return out
