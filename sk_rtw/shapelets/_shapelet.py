"""A geodesic dilated shapelet, how it is drawn from training series, and the three
features it gives a series."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from ..dtw import kernel_point_form, shapelet_features, window_distances, window_profiles
from ..utils import SeriesCollection
from ._windows import Windows, gather_windows

#: The features of a shapelet, in this order.
FEATURES = ("min", "argmin", "count")


@dataclass(frozen=True, eq=False)
class Shapelet:
    """A shapelet: ``length`` points taken every ``dilation`` samples of a training
    series (``source``: its index and first sample) in a ``representation``, normalised
    by the manifold or not, and the ``threshold`` below which a window counts as an
    occurrence.

    Attributes
    ----------
    representation : str
    normalised : bool
    length, dilation : int
    points : ndarray of shape (length, *point_shape)
        Its points, in the window space (the manifold, or its normalised space).
    threshold : float
    source : tuple of int
        ``(series, start)`` in the training set it was drawn from, for reading.
    label : int
        The class code of that series.
    """

    representation: str
    normalised: bool
    length: int
    dilation: int
    points: np.ndarray
    threshold: float
    source: tuple[int, int]
    label: int

    @property
    def group(self) -> tuple[str, bool, int, int]:
        """What its windows depend on: shapelets of one group share them."""
        return self.representation, self.normalised, self.length, self.dilation

    @property
    def span(self) -> int:
        """Samples a window covers: ``(length - 1) * dilation + 1``."""
        return (self.length - 1) * self.dilation + 1


def profile(shapelet: Shapelet, windows: Windows, series: int = 0) -> np.ndarray:
    """The distance of ``shapelet`` to every window of one series of ``windows``."""
    n = int(windows.counts[series])
    if windows.segments is None:
        gaps = windows.space.dist(shapelet.points, windows.points[series, :n])
        return np.asarray(gaps, dtype=np.float64).sum(-1)
    out = np.empty(n)
    assert windows.data is not None  # the kernel form exists where segments do
    window_distances(windows.data[series], n, _form(windows, shapelet), windows.segments, out)
    return out


def _form(windows: Windows, shapelet: Shapelet) -> np.ndarray:
    """A shapelet's points in the kernels' form of its windows' space."""
    form, _ = kernel_point_form(windows.space, shapelet.points)
    assert form is not None
    return form


def draw_shapelets(
    rng: np.random.Generator,
    n_shapelets: int,
    collections: Mapping[str, SeriesCollection],
    codes: np.ndarray,
    representations: Sequence[str],
    lengths: Sequence[int],
    p_normalised: float,
    percentiles: tuple[float, float],
    candidates: np.ndarray | None = None,
) -> list[Shapelet]:
    """Shapelets drawn as random dilated shapelets are, each: a representation, a length,
    a normalisation (probability ``p_normalised``, where the manifold has one), a
    dilation ``floor(2^u)``, ``u`` uniform in ``[0, log2((T - 1) / (l - 1))]`` for the
    shortest series' ``T``, a series (of ``candidates``, default all) and a start; its
    threshold uniform between ``percentiles`` of its distances to the windows of another
    series of its class (the series itself where its class has no other).

    Every draw is made up front (:func:`draw_sites`), then the shapelets are taken
    (:func:`take_shapelets`)."""
    sites = draw_sites(rng, n_shapelets, collections, codes, representations, lengths,
                       p_normalised, candidates)  # fmt: skip
    return take_shapelets(sites, collections, codes, representations, percentiles)


def take_shapelets(
    sites: Sites,
    collections: Mapping[str, SeriesCollection],
    codes: np.ndarray,
    representations: Sequence[str],
    percentiles: tuple[float, float],
) -> list[Shapelet]:
    """The shapelets drawn at ``sites``, their points and thresholds: those of one
    window kind together (one compiled pass over the windows they need)."""
    shapelets: list[Shapelet | None] = [None] * len(sites.series)
    for r, name in enumerate(representations):
        mine = np.flatnonzero(sites.representation == r)
        if len(mine) == 0:
            continue
        collection = collections[name]
        length, dilation, normal = sites.length[mine], sites.dilation[mine], sites.normalised[mine]
        # one window kind per (length, dilation, normalised), taken in that order
        kinds = (length * (int(dilation.max()) + 1) + dilation) * 2 + normal
        for kind in np.unique(kinds):
            group = mine[kinds == kind]
            first = group[0]
            size, d = int(sites.length[first]), int(sites.dilation[first])
            is_normal = bool(sites.normalised[first])
            drawn = _group(collection, size, d, is_normal, sites.series[group],
                           sites.start[group], sites.other[group], sites.uniform[group],
                           percentiles)  # fmt: skip
            for j, (points, threshold) in zip(group, drawn, strict=True):
                shapelets[j] = Shapelet(name, is_normal, size, d, points, threshold,
                                        (int(sites.series[j]), int(sites.start[j])),
                                        int(codes[sites.series[j]]))  # fmt: skip
    return [s for s in shapelets if s is not None]


@dataclass(frozen=True, eq=False)
class Sites:
    """Where ``n`` shapelets are drawn, one entry each: the index of the representation,
    length, dilation, whether normalised, the series and the first sample, another series
    of its class and the uniform number that places its threshold between the
    percentiles."""

    representation: np.ndarray
    length: np.ndarray
    dilation: np.ndarray
    normalised: np.ndarray
    series: np.ndarray
    start: np.ndarray
    other: np.ndarray
    uniform: np.ndarray


def draw_sites(
    rng: np.random.Generator,
    n: int,
    collections: Mapping[str, SeriesCollection],
    codes: np.ndarray,
    representations: Sequence[str],
    lengths: Sequence[int],
    p_normalised: float,
    candidates: np.ndarray | None = None,
) -> Sites:
    """Every random draw of :func:`draw_shapelets` (made up front, in its order)."""
    pool = np.arange(len(codes)) if candidates is None else np.asarray(candidates)
    rep = rng.integers(len(representations), size=n)
    length = np.asarray(lengths, dtype=np.int64)[rng.integers(len(lengths), size=n)]
    wants_normal = rng.uniform(size=n) < p_normalised
    u_dilation, u_series, u_start, u_other, u_threshold = rng.uniform(size=(5, n))
    series = pool[np.minimum((u_series * len(pool)).astype(np.int64), len(pool) - 1)]
    dilation = np.ones(n, dtype=np.int64)
    start = np.zeros(n, dtype=np.int64)
    normal = np.zeros(n, dtype=bool)
    other = np.zeros(n, dtype=np.int64)
    for r, name in enumerate(representations):
        mine = np.flatnonzero(rep == r)
        if len(mine) == 0:  # every draw is made: nothing of this representation to take
            continue
        collection = collections[name]
        lengths_r = collection.lengths
        shortest = int(lengths_r[pool].min())
        upper = np.log2(np.maximum(shortest - 1, 1) / np.maximum(length[mine] - 1, 1))
        spread = (2.0 ** (u_dilation[mine] * upper)).astype(np.int64)
        dilation[mine] = np.where(length[mine] < 2, 1, np.maximum(1, spread))
        starts = lengths_r[series[mine]] - (length[mine] - 1) * dilation[mine]
        start[mine] = np.minimum((u_start[mine] * starts).astype(np.int64), starts - 1)
        normal[mine] = wants_normal[mine] & (collection.manifold.normalised_space is not None)
        other[mine] = _others(series[mine], u_other[mine], pool, codes)
    return Sites(rep, length, dilation, normal, series, start, other, u_threshold)


def draw_site(
    rng: np.random.Generator,
    collections: Mapping[str, SeriesCollection],
    codes: np.ndarray,
    representations: Sequence[str],
    lengths: Sequence[int],
    p_normalised: float,
    pool: np.ndarray,
    shortest: Mapping[str, int],
    classmates: Mapping[int, np.ndarray],
) -> Sites:
    """:func:`draw_sites` of one shapelet from ``pool`` in scalars, bit for bit (the same
    draws from ``rng``, numpy's arithmetic on them): what a forest's candidate draws.
    ``shortest[name]``: the shortest series of ``pool`` in each representation;
    ``classmates[label]``: the series of ``pool`` of each class, in ``pool``'s order."""
    r = int(rng.integers(len(representations)))
    length = int(lengths[int(rng.integers(len(lengths)))])
    wants_normal = rng.random() < p_normalised
    u_dilation, u_series, u_start, u_other, u_threshold = rng.random(5)
    series = int(pool[min(int(u_series * len(pool)), len(pool) - 1)])
    name = representations[r]
    collection = collections[name]
    upper = np.log2(np.float64(max(shortest[name] - 1, 1) / max(length - 1, 1)))
    spread = int(np.power(2.0, u_dilation * upper))
    dilation = 1 if length < 2 else max(1, spread)
    starts = int(collection.lengths[series]) - (length - 1) * dilation
    start = min(int(u_start * starts), starts - 1)
    normal = bool(wants_normal) and collection.manifold.normalised_space is not None
    same = classmates[int(codes[series])]
    other = series
    if len(same) >= 2:
        pick = min(int(u_other * (len(same) - 1)), len(same) - 2)
        own = int(np.searchsorted(same, series))  # the drawn series, skipped
        other = int(same[pick + (pick >= own)])
    return Sites(np.array([r]), np.array([length]), np.array([dilation]), np.array([normal]),
                 np.array([series]), np.array([start]), np.array([other]),
                 np.array([u_threshold]))  # fmt: skip


def _others(series: np.ndarray, uniform: np.ndarray, pool: np.ndarray, codes: np.ndarray):
    """For every drawn series, another series of the pool of its class (uniformly), or
    itself where its class has no other."""
    out = series.copy()
    for label in np.unique(codes[series]):
        same = pool[codes[pool] == label]
        if len(same) < 2:
            continue
        chosen = np.flatnonzero(codes[series] == label)
        pick = np.minimum((uniform[chosen] * (len(same) - 1)).astype(np.int64), len(same) - 2)
        own = np.searchsorted(same, series[chosen])  # the drawn series, skipped
        out[chosen] = same[pick + (pick >= own)]
    return out


def _group(collection, length, dilation, normalised, series, start, other, uniform,
           percentiles):  # fmt: skip
    """Points and thresholds of shapelets of one window kind."""
    offsets = start[:, None] + dilation * np.arange(length)[None, :]
    points = collection.data[series[:, None], offsets]
    if normalised:
        points = collection.manifold.normalise_windows(points)
    needed, rows = np.unique(other, return_inverse=True)
    windows = gather_windows(collection.subset(needed), length, dilation, normalised)
    if windows.segments is None or windows.data is None:
        distances = np.full((len(series), int(windows.counts.max())), np.nan)
        for j in range(len(series)):
            shapelet = Shapelet("", normalised, length, dilation, points[j], 0.0, (0, 0), 0)
            gaps = profile(shapelet, windows, int(rows[j]))
            distances[j, : len(gaps)] = gaps
    else:
        form, _ = kernel_point_form(windows.space, points)
        distances = np.empty((len(series), windows.data.shape[1]))
        window_profiles(windows.data, windows.counts, rows.astype(np.int64),
                        np.ascontiguousarray(form), windows.segments, distances)  # fmt: skip
    valid = windows.counts[rows]
    low, high = _row_percentiles(distances, valid, percentiles)
    thresholds = low + uniform * (high - low)
    return list(zip(points, thresholds.tolist(), strict=True))


def _row_percentiles(
    distances: np.ndarray, valid: np.ndarray, percentiles: tuple[float, float]
) -> np.ndarray:
    """``np.nanpercentile(distances, percentiles, axis=1)`` for rows whose first
    ``valid[j]`` entries are numbers and the rest NaN: rows of one length at once
    (``nanpercentile`` along an axis takes one row at a time, in Python)."""
    out = np.empty((len(percentiles), len(distances)))
    lengths = np.unique(valid)
    for count in lengths:
        chosen = slice(None) if len(lengths) == 1 else np.flatnonzero(valid == count)
        out[:, chosen] = np.percentile(distances[chosen, :count], percentiles, axis=1)
    return out


@dataclass(frozen=True, eq=False)
class ShapeletBank:
    """Shapelets grouped by what their windows depend on, each group's points stacked in
    the kernels' form once (for every series that is transformed)."""

    shapelets: tuple[Shapelet, ...]
    groups: tuple[tuple[tuple[str, bool, int, int], np.ndarray, np.ndarray | None,
                        np.ndarray], ...]  # fmt: skip

    @classmethod
    def build(cls, shapelets: Sequence[Shapelet], space_of) -> ShapeletBank:
        """``space_of(representation, normalised)``: the window space of a group."""
        members: dict[tuple[str, bool, int, int], list[int]] = {}
        for j, shapelet in enumerate(shapelets):
            members.setdefault(shapelet.group, []).append(j)
        groups = []
        for key, chosen in members.items():
            space = space_of(key[0], key[1])
            stacked = np.stack([shapelets[j].points for j in chosen])
            form, _ = kernel_point_form(space, stacked)
            thresholds = np.array([shapelets[j].threshold for j in chosen])
            groups.append((key, np.array(chosen), form, thresholds))
        return cls(tuple(shapelets), tuple(groups))


def features(collections: Mapping[str, SeriesCollection], bank: ShapeletBank) -> np.ndarray:
    """``(n_series, n_shapelets, 3)``: every shapelet's smallest window distance, where it
    lies (the first window of it) and how many windows lie closer than its threshold,
    for every series of ``collections`` (one per representation, the same series)."""
    n = next(iter(collections.values())).n_series
    out = np.empty((n, len(bank.shapelets), 3))
    for (representation, normalised, length, dilation), members, form, thresholds in (
        bank.groups
    ):
        windows = gather_windows(collections[representation], length, dilation, normalised)
        if windows.segments is None or form is None:
            chosen = [bank.shapelets[j] for j in members]
            block = np.stack([_plain_features(s, windows) for s in chosen], axis=1)
        else:
            block = np.empty((n, len(members), 3))
            shapelet_features(windows.data, windows.counts, form, thresholds,
                              windows.segments, block)  # fmt: skip
        out[:, members] = block
    return out


def _plain_features(shapelet: Shapelet, windows: Windows) -> np.ndarray:
    """:func:`features` of one shapelet for a space without a kernel form."""
    out = np.empty((len(windows.counts), 3))
    for i in range(len(windows.counts)):
        d = profile(shapelet, windows, i)
        out[i] = d.min(), np.argmin(d), np.count_nonzero(d < shapelet.threshold)
    return out
