"""Choices made from the training data: the DTW band and the centroids of every class.

``dtw_window="auto"`` and ``n_centroids="auto"`` (:class:`~sk_rtw.RTWNearestCentroid`'s
defaults) are resolved in ``fit``, before the centroids are averaged, into
``dtw_window_`` and ``n_centroids_``. A number of centroids is a count per class (an
integer, at most the class's series) or a fraction of every class (a float in (0, 1],
rounded up, at least one centroid: :func:`class_counts`), so that a class's centroids
follow its size; ``1.0`` makes every series a centroid (1-NN DTW within the band).
Everything is computed once and scored many times:

1. one DTW matrix of every class's training series per candidate band
   (:class:`~sk_rtw.AutoChoice`'s ``windows``);
2. every candidate (band, centroids of its ``centroids``) is scored by leave-one-out
   nearest-medoid classification: k-medoids of every class on its matrix; each series'
   distance to its own class is the nearest of that class's medoids, a medoid itself
   left out and replaced in its cluster
   (:func:`~sk_rtw.estimators._medoids.held_out_distances`), and its distance to every
   other class the nearest of their medoids (:func:`~sk_rtw.dtw.dtw_nearest_distance`:
   lower bounds and early abandoning). No centroid is averaged;
3. the choice is its ``prior`` unless another candidate classifies the held-out
   series better by at least its ``z_threshold`` standard errors of the paired
   difference (McNemar's statistic on the series where exactly one of the two is right);
   ties go to fewer centroids, then to the narrower band.

The criterion is deterministic (no folds to draw), so the choice does not depend on
``random_state`` unless the training set is sampled. On more than :data:`MAX_SERIES`
series, or when every pair of them would exceed :data:`CELLS_PER_POINT` DTW cells per
training sample, the choice is made on a stratified random sample
(``selection_["n_series"]``); a fraction then applies to the full classes. Finally
every class is split into its count of parts
(:func:`~sk_rtw.estimators._partition.partition`), and the averaging method fits every
part once.

Why these values: docs, UCR benchmark ("the default classifier"), measured with
``benchmarks/studies/candidates.py`` on half A of the development archive and on half C1 of
the large training sets, confirmed on halves B and C2.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._random import check_random_state
from ..dtw import dtw_nearest_distance, dtw_pairwise_distance
from ..utils import SeriesCollection
from ._choice import AutoChoice, mcnemar
from ._medoids import held_out_distances, kmedoids

#: Most training series the choice is made on (a stratified sample beyond).
MAX_SERIES = 1000
#: DTW cells of the choice per sample of the training set (sum of the series lengths):
#: every pair of the sampled series once per band, about the work of one plain fit.
CELLS_PER_POINT = 40_000


def class_counts(n_centroids: int | float, sizes: np.ndarray) -> np.ndarray:
    """Centroids of every class: ``min(n_centroids, size)`` for an integer, ``ceil(f size)``
    (at least one) for a fraction ``f``.

    Parameters
    ----------
    n_centroids : int or float
    sizes : ndarray of int
        Series of every class.

    Returns
    -------
    ndarray of int
    """
    sizes = np.asarray(sizes, dtype=np.int64)
    if isinstance(n_centroids, (int, np.integer)):
        return np.minimum(int(n_centroids), sizes)
    counts = np.ceil(float(n_centroids) * sizes - 1e-9).astype(np.int64)
    return np.clip(counts, 1, np.maximum(sizes, 1))


@dataclass
class Selection:
    """What the choice found: the values, their scores and what the final fit reuses.

    Attributes
    ----------
    dtw_window : float or None
    n_centroids : int or float
    report : dict
        ``selection_``: criterion, prior, every candidate's held-out accuracy and
        statistic, the sample size and the seconds.
    sample : ndarray of int
        Training series the matrices cover (all of them unless sampled).
    medoids : dict
        :func:`candidate_key` -> per class, the k-medoids labels of its sampled
        series (what :func:`~sk_rtw.estimators._partition.partition` reuses for a class
        scored whole).
    held_out : ndarray of shape (n_sample, n_classes)
        Leave-one-out distance of every sampled series to every class under the chosen
        candidate (what the probability temperature is fitted on); ``inf`` for the class
        of a series that is alone in it.
    matrices : list of ndarray
        Per class, the DTW matrix of its sampled series in the chosen band (what
        :func:`~sk_rtw.estimators._partition.partition` completes for a class scored in
        part).
    """

    dtw_window: float | None
    n_centroids: int | float
    report: dict[str, Any]
    sample: np.ndarray
    medoids: dict[tuple[Any, Any], list[np.ndarray]] = field(default_factory=dict)
    held_out: np.ndarray = field(default_factory=lambda: np.empty((0, 0)))
    matrices: list[np.ndarray] = field(default_factory=list)


def band_cells(length: float, window: float | None) -> float:
    """DTW cells of a pair of series of ``length`` within the Sakoe-Chiba ``window``."""
    if window is None:
        return float(length) ** 2
    return float(length) * min(float(length), 2 * int(window * length) + 1)


def selection_sample(
    collection: SeriesCollection, codes: np.ndarray, windows, rng: np.random.RandomState
) -> np.ndarray:
    """Indices of the series the choice is made on: all of them, or a stratified sample
    within :data:`MAX_SERIES` and the :data:`CELLS_PER_POINT` budget (every pair of the
    sample once in every band: the class matrices and the searches together); every
    class keeps at least two series, or all it has."""
    n = collection.n_series
    lengths = collection.lengths
    sizes = np.bincount(codes)
    pair = sum(band_cells(float(np.mean(lengths)), w) for w in windows)
    budget = CELLS_PER_POINT * float(lengths.sum())
    # the class matrices hold the pairs of the same class, the searches reach the others:
    # about the work of every pair of the sample once
    size = int(min(n, MAX_SERIES, np.sqrt(2.0 * budget / max(pair, 1.0))))
    if size >= n:
        return np.arange(n)
    keep = []
    for c, n_c in enumerate(sizes):
        quota = min(int(n_c), max(2, round(size * n_c / n)))
        members = np.flatnonzero(codes == c)
        keep.append(rng.choice(members, quota, replace=False))
    return np.sort(np.concatenate(keep))


def candidate_key(window: float | None, n_centroids: int | float) -> tuple:
    """A candidate as a dictionary key: ``1`` (one centroid per class) and ``1.0`` (every
    series) are equal numbers but different candidates."""
    return (window, isinstance(n_centroids, float), n_centroids)


def _width(window: float | None) -> float:
    return 2.0 if window is None else float(window)


def _centroid_order(n_centroids: int | float) -> float:
    """Fewer centroids first: a count before every fraction, then by size."""
    if isinstance(n_centroids, (int, np.integer)):
        return float(n_centroids) - 1e6
    return float(n_centroids)


def class_medoids(D: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """k-medoids of one class's matrix; every series its own medoid when ``k`` is its size."""
    n = D.shape[0]
    if k >= n:
        return np.arange(n), np.arange(n)
    return kmedoids(np.ascontiguousarray(D), k)


@dataclass
class Partition:
    """One candidate's k-medoids of every class (:func:`class_partitions`)."""

    #: Held-out distance of every series to its own class (leave-one-out).
    own: np.ndarray
    #: Per class, the k-medoids label of each of its series.
    labels: list[np.ndarray]
    #: Positions of every class's medoids among the series, class after class.
    medoids: np.ndarray


def class_partitions(
    matrices: list[np.ndarray], members: list[np.ndarray], n_centroids: int | float
) -> Partition:
    """k-medoids of every class on its matrix under one candidate's count.

    Parameters
    ----------
    matrices : list of ndarray
        Per class, the DTW matrix of its series.
    members : list of ndarray
        Per class, the positions of its series among all.
    n_centroids : int or float

    Returns
    -------
    Partition
    """
    counts = class_counts(n_centroids, np.array([len(m) for m in members]))
    own = np.empty(sum(len(m) for m in members))
    labels, references = [], []
    for c, D in enumerate(matrices):
        medoids, part = class_medoids(D, int(counts[c]))
        own[members[c]] = held_out_distances(D, medoids, part)
        labels.append(part)
        references.append(members[c][medoids])
    return Partition(own, labels, np.concatenate(references))


@dataclass
class NearestOther:
    """Every series' nearest series of another class, where it is at most ``limit``
    (:func:`nearest_other_class`)."""

    #: ``(n, n_classes)``: the nearest other class's distance (and any tied with it),
    #: ``inf`` elsewhere and where none is at most the limit.
    distances: np.ndarray
    #: ``(n,)``: the distance up to which ``distances`` is known.
    limit: np.ndarray


def nearest_other_class(
    subset: SeriesCollection,
    codes: np.ndarray,
    limit: np.ndarray,
    window: float | None,
    n_jobs: int | None = None,
) -> NearestOther:
    """Each series' nearest series of another class, where it is at most ``limit``: with
    the own-class distances of a band's candidates as the limit, one search that settles
    most series of every candidate (:func:`held_out_scores`)."""
    distances = dtw_nearest_distance(
        subset, subset, codes, window=window, exclude_group=codes, max_distance=limit,
        nearest_only=True, n_jobs=n_jobs,
    )  # fmt: skip
    return NearestOther(distances, limit)


def held_out_scores(
    subset: SeriesCollection,
    codes: np.ndarray,
    partition: Partition,
    window: float | None,
    every_class: bool = True,
    nearest_other: NearestOther | None = None,
    n_jobs: int | None = None,
) -> np.ndarray:
    """Leave-one-out nearest-medoid distances of one candidate (module docstring, step 2).

    Parameters
    ----------
    subset : SeriesCollection
        The series scored.
    codes : ndarray of int, shape (n,)
        Their classes.
    partition : Partition
        The candidate's k-medoids of every class (:func:`class_partitions`).
    window : float or None
        The candidate's band.
    every_class : bool, default=True
        False: the other classes only where one is nearer than (or as near as) a series'
        own (``inf`` elsewhere): the same ``argmin``, from far fewer DTWs.
    nearest_other : NearestOther, optional
        With ``every_class=False``: :func:`nearest_other_class` of the band. A series
        farther from every other class than from its own needs no search (no medoid of
        another class can be nearer), nor one whose every series is a medoid (the
        nearest other series is the nearest other medoid), where the limit covers its
        own distance.
    n_jobs : int, optional

    Returns
    -------
    held_out : ndarray of shape (n, n_classes)
    """
    own, chosen = partition.own, partition.medoids
    n = subset.n_series
    held_out = np.full((n, len(partition.labels)), np.inf)
    rows = np.arange(n)
    if not every_class and nearest_other is not None:
        known = own <= nearest_other.limit
        nearest = nearest_other.distances.min(1)
        if len(chosen) == n:  # every series a medoid: the search is the band's
            held_out[known] = np.where(nearest_other.distances[known] <= own[known, None],
                                       nearest_other.distances[known], np.inf)  # fmt: skip
            rows = np.flatnonzero(~known)
        else:
            rows = np.flatnonzero(~known | (nearest <= own))
    if len(rows):
        held_out[rows] = dtw_nearest_distance(
            subset.subset(rows), subset.subset(chosen), codes[chosen], window=window,
            exclude_group=codes[rows], max_distance=None if every_class else own[rows],
            nearest_only=not every_class, n_jobs=n_jobs,
        )  # fmt: skip
    held_out[np.arange(n), codes] = own
    return held_out


def choose(
    collection: SeriesCollection,
    codes: np.ndarray,
    window: Any,
    n_centroids: Any,
    choice: AutoChoice,
    *,
    random_state: Any = None,
    n_jobs: int | None = None,
    verbose: int = 0,
    owner: str = "RTWNearestCentroid",
) -> Selection:
    """Resolve ``"auto"`` band and centroids (module docstring).

    Parameters
    ----------
    collection : SeriesCollection
        The training series.
    codes : ndarray of int, shape (n_series,)
        Class of every series, ``0..n_classes - 1`` (at least two classes).
    window : float, None or "auto"
    n_centroids : int, float or "auto"
    choice : AutoChoice
        The candidates and the rule, checked (:meth:`AutoChoice.checked`).
    random_state : int, RandomState or None
        Draws the sample of a large training set.
    n_jobs : int, optional
        Threads of the DTW matrices and searches.
    verbose : int
        1 and more: one line with the choice and its cost.
    owner : str
        The estimator's name in the ``verbose`` line.

    Returns
    -------
    Selection
    """
    start = time.perf_counter()
    windows, counts, prior = choice.candidates(window, n_centroids)
    rng = check_random_state(random_state)
    sample = selection_sample(collection, codes, windows, rng)
    subset = collection.subset(sample)
    sampled_codes = codes[sample]
    n_classes = int(codes.max()) + 1
    members = [np.flatnonzero(sampled_codes == c) for c in range(n_classes)]
    candidates = {candidate_key(w, k): (w, k) for w in windows for k in counts}
    candidates.setdefault(candidate_key(*prior), prior)  # a fixed value off the grid
    outcomes, partitions, matrices = {}, {}, {}
    for w in dict.fromkeys(w for w, _ in candidates.values()):
        matrices[w] = [
            dtw_pairwise_distance(subset.subset(m), window=w, n_jobs=n_jobs) for m in members
        ]
        keys = [q for q, c in candidates.items() if c[0] == w]
        for q in keys:
            partitions[q] = class_partitions(matrices[w], members, candidates[q][1])
        # the one-per-class candidates' own distances are large, and their own search
        # cheap: the shared search stops at the others'
        shares = [q for q in keys if isinstance(candidates[q][1], float)] or keys
        limit = np.max([partitions[q].own for q in shares], axis=0)
        nearest = nearest_other_class(subset, sampled_codes, limit, w, n_jobs)
        for q in keys:
            held_out = held_out_scores(subset, sampled_codes, partitions[q], w,
                                       every_class=False, nearest_other=nearest,
                                       n_jobs=n_jobs)  # fmt: skip
            outcomes[q] = held_out.argmin(1) == sampled_codes
    base = outcomes[candidate_key(*prior)]
    statistics = {q: mcnemar(outcomes[q], base) for q in outcomes}
    best = max(statistics.values())
    chosen = prior
    if choice.prefers(best):
        chosen = min(
            (candidates[q] for q, z in statistics.items() if z >= best - 1e-12),
            key=lambda c: (_centroid_order(c[1]), _width(c[0])),
        )
    # every class's held-out distance under the choice (the probability temperature's)
    chosen_key = candidate_key(*chosen)
    held_out = held_out_scores(subset, sampled_codes, partitions[chosen_key], chosen[0],
                               n_jobs=n_jobs)  # fmt: skip
    sizes = np.bincount(codes, minlength=n_classes)
    report: dict[str, Any] = {
        "criterion": (
            "leave-one-out nearest-medoid accuracy on the training series; the prior "
            f"(dtw_window={prior[0]}, n_centroids={prior[1]}) unless a candidate is better "
            f"by at least {choice.z_threshold} standard errors (McNemar)"
        ),
        "prior": {"dtw_window": prior[0], "n_centroids": prior[1]},
        "candidates": [
            {
                "dtw_window": w,
                "n_centroids": k,
                "accuracy": float(outcomes[q].mean()),
                "z": float(statistics[q]),
            }
            for q, (w, k) in candidates.items()
        ],
        "class_centroids": class_counts(chosen[1], sizes).tolist(),
        "n_series": len(sample),
        "sampled": len(sample) < collection.n_series,
        "seconds": time.perf_counter() - start,
    }
    if verbose:
        print(
            f"[{owner}] chose dtw_window={chosen[0]}, n_centroids={chosen[1]} "
            f"({int(np.sum(report['class_centroids']))} centroids) from {len(outcomes)} "
            f"candidates on {len(sample)} of {collection.n_series} series (held-out "
            f"accuracy {outcomes[chosen_key].mean():.3f}) in {report['seconds']:.1f} s",
            file=sys.stderr,
            flush=True,
        )
    medoids = {q: partition.labels for q, partition in partitions.items()}
    return Selection(chosen[0], chosen[1], report, sample, medoids, held_out,
                     matrices[chosen[0]])  # fmt: skip
