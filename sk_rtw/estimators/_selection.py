"""Choices made from the training data: the DTW band and the number of centroids per class.

``dtw_window="auto"`` and ``n_centroids="auto"`` (:class:`~sk_rtw.RTWNearestCentroid`'s
defaults) are resolved in ``fit``, before the centroids are averaged, into
``dtw_window_`` and ``n_centroids_``. Everything is computed once and scored many times:

1. one DTW matrix of the training series per candidate band (:data:`WINDOWS`);
2. every candidate (band, centroids per class of :data:`CENTROIDS`) is scored by
   leave-one-out nearest-medoid classification on that matrix: each series is given the
   class of the nearest of ``k`` medoids per class, its own class's medoids chosen
   without it (:func:`~sk_rtw.estimators._medoids.loo_class_distances`); no centroid is
   averaged and no new DTW is computed;
3. the choice is the prior :data:`PRIOR` unless another candidate classifies the
   held-out series better by at least :data:`Z_THRESHOLD` standard errors of the paired
   difference (McNemar's statistic on the series where exactly one of the two is right);
   ties go to fewer centroids, then to the narrower band.

The criterion is deterministic (no folds to draw), so the choice does not depend on
``random_state`` unless the training set is sampled. On more than :data:`MAX_SERIES`
series, or when the matrices would exceed :data:`CELLS_PER_POINT` DTW cells per training
sample, the choice is made on a stratified random sample (``selection_["n_series"]``).
The matrix of the chosen band then gives each class's partition into ``k`` parts
(:func:`partition`), and the averaging method fits every part once.

Why these values (UCR development archive, 30 datasets in two fixed halves, docs: UCR
benchmark; ``benchmarks/ucr/candidates.py``): the grid and the rule were chosen on half A
from the test accuracy of every candidate's centroids, and confirmed on half B.
Cross-validated accuracy on training sets of 16-60 series is too noisy to pick the best of
16-20 candidates (the previous rule, the best 3-fold accuracy of DBA centroids, kept the
same choice on all of 3 seeds for 8 of 30 datasets and trailed 1-NN DTW on half A); a good
prior that the data must clearly beat does better on both halves. The full band was never
chosen over the narrower ones by any rule measured and costs more than the four others
together, so it is not a candidate.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from sklearn.utils import check_random_state

from ..dtw import dtw_pairwise_distance
from ..utils import SeriesCollection
from ._medoids import kmedoids, loo_class_distances

#: Candidate Sakoe-Chiba radii of ``dtw_window="auto"``.
WINDOWS: tuple[float, ...] = (0.0, 0.05, 0.1, 0.2)
#: Candidate centroids per class of ``n_centroids="auto"``.
CENTROIDS: tuple[int, ...] = (1, 2, 4, 8)
#: The choice unless the training data clearly prefer another candidate.
PRIOR: tuple[float, int] = (0.05, 8)
#: Standard errors by which a candidate must beat the prior on the held-out series.
Z_THRESHOLD = 1.0
#: Most training series the choice is made on (a stratified sample beyond).
MAX_SERIES = 500
#: DTW cells of the selection's matrices per sample of the training set (sum of the
#: series lengths): about the work of one plain fit (docs: UCR benchmark).
CELLS_PER_POINT = 40_000


@dataclass
class Selection:
    """What the choice found: the values, their scores and what the final fit reuses.

    Attributes
    ----------
    dtw_window : float or None
    n_centroids : int
    report : dict
        ``selection_``: criterion, prior, every candidate's held-out accuracy and
        statistic, the sample size and the seconds.
    sample : ndarray of int
        Training series the matrices cover (all of them unless sampled).
    matrices : dict
        DTW matrix of the sample per band.
    held_out : ndarray of shape (n_sample, n_classes)
        Leave-one-out distance of every sampled series to every class under the chosen
        candidate (what the probability temperature is fitted on); ``inf`` for the class
        of a series that is alone in it.
    """

    dtw_window: float | None
    n_centroids: int
    report: dict[str, Any]
    sample: np.ndarray
    matrices: dict[float | None, np.ndarray] = field(default_factory=dict)
    held_out: np.ndarray = field(default_factory=lambda: np.empty((0, 0)))


def band_cells(length: float, window: float | None) -> float:
    """DTW cells of a pair of series of ``length`` within the Sakoe-Chiba ``window``."""
    if window is None:
        return float(length) ** 2
    return float(length) * min(float(length), 2 * int(window * length) + 1)


def selection_sample(
    collection: SeriesCollection, codes: np.ndarray, windows, rng: np.random.RandomState
) -> np.ndarray:
    """Indices of the series the choice is made on: all of them, or a stratified sample
    within :data:`MAX_SERIES` and the :data:`CELLS_PER_POINT` budget (every class keeps
    at least two series, or all it has)."""
    n = collection.n_series
    lengths = collection.lengths
    pair = sum(band_cells(float(np.mean(lengths)), w) for w in windows)
    budget = CELLS_PER_POINT * float(lengths.sum())
    size = int(min(n, MAX_SERIES, np.sqrt(2.0 * budget / max(pair, 1.0))))
    if size >= n:
        return np.arange(n)
    sizes = np.bincount(codes)
    keep = []
    for c, n_c in enumerate(sizes):
        quota = min(int(n_c), max(2, round(size * n_c / n)))
        members = np.flatnonzero(codes == c)
        keep.append(rng.choice(members, quota, replace=False))
    return np.sort(np.concatenate(keep))


def mcnemar(candidate: np.ndarray, prior: np.ndarray) -> float:
    """Paired difference of two 0/1 outcome vectors in standard errors (McNemar)."""
    better = int(np.sum(candidate & ~prior))
    worse = int(np.sum(~candidate & prior))
    return (better - worse) / np.sqrt(better + worse) if better + worse else 0.0


def _width(window: float | None) -> float:
    return 2.0 if window is None else float(window)


def choose(
    collection: SeriesCollection,
    codes: np.ndarray,
    window: Any,
    n_centroids: Any,
    *,
    random_state: Any = None,
    n_jobs: int | None = None,
    verbose: int = 0,
    owner: str = "RTWNearestCentroid",
) -> Selection:
    """Resolve ``"auto"`` band and centroids per class (module docstring).

    Parameters
    ----------
    collection : SeriesCollection
        The training series.
    codes : ndarray of int, shape (n_series,)
        Class of every series, ``0..n_classes - 1`` (at least two classes).
    window : float, None or "auto"
    n_centroids : int or "auto"
    random_state : int, RandomState or None
        Draws the sample of a large training set.
    n_jobs : int, optional
        Threads of the DTW matrices.
    verbose : int
        1 and more: one line with the choice and its cost.
    owner : str
        The estimator's name in the ``verbose`` line.

    Returns
    -------
    Selection
    """
    start = time.perf_counter()
    windows = WINDOWS if window == "auto" else (window,)
    counts = CENTROIDS if n_centroids == "auto" else (int(n_centroids),)
    prior = (
        PRIOR[0] if window == "auto" else window,
        PRIOR[1] if n_centroids == "auto" else counts[0],
    )
    rng = check_random_state(random_state)
    sample = selection_sample(collection, codes, windows, rng)
    subset = collection.subset(sample)
    sampled_codes = codes[sample]
    n_classes = int(codes.max()) + 1
    matrices = {w: dtw_pairwise_distance(subset, window=w, n_jobs=n_jobs) for w in windows}
    outcomes, distances = {}, {}
    for w in windows:
        for k in counts:
            held_out = loo_class_distances(matrices[w], sampled_codes, n_classes, k)
            distances[w, k] = held_out
            outcomes[w, k] = held_out.argmin(1) == sampled_codes
    if prior not in outcomes:  # a fixed value the grid does not hold: score it too
        held_out = loo_class_distances(matrices[prior[0]], sampled_codes, n_classes, prior[1])
        distances[prior], outcomes[prior] = held_out, held_out.argmin(1) == sampled_codes
    statistics = {q: mcnemar(outcomes[q], outcomes[prior]) for q in outcomes}
    best = max(statistics.values())
    chosen = prior
    if best >= Z_THRESHOLD:
        chosen = min(
            (q for q, z in statistics.items() if z >= best - 1e-12),
            key=lambda q: (q[1], _width(q[0])),
        )
    report: dict[str, Any] = {
        "criterion": (
            "leave-one-out nearest-medoid accuracy on the training series; the prior "
            f"(dtw_window={prior[0]}, n_centroids={prior[1]}) unless a candidate is better "
            f"by at least {Z_THRESHOLD} standard errors (McNemar)"
        ),
        "prior": {"dtw_window": prior[0], "n_centroids": prior[1]},
        "candidates": [
            {
                "dtw_window": w,
                "n_centroids": k,
                "accuracy": float(outcomes[w, k].mean()),
                "z": float(statistics[w, k]),
            }
            for (w, k) in outcomes
        ],
        "n_series": len(sample),
        "sampled": len(sample) < collection.n_series,
        "seconds": time.perf_counter() - start,
    }
    if verbose:
        print(
            f"[{owner}] chose dtw_window={chosen[0]}, n_centroids={chosen[1]} from "
            f"{len(outcomes)} candidates on {len(sample)} of {collection.n_series} series "
            f"(held-out accuracy {outcomes[chosen].mean():.3f}) in {report['seconds']:.1f} s",
            file=sys.stderr,
            flush=True,
        )
    return Selection(chosen[0], chosen[1], report, sample, matrices, distances[chosen])


def partition(
    collection: SeriesCollection,
    codes: np.ndarray,
    n_centroids: int,
    window: float | None,
    *,
    selection: Selection | None = None,
    random_state: Any = None,
    n_jobs: int | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Split every class into ``min(n_centroids, class size)`` parts by k-medoids on DTW.

    Each class's medoids come from the DTW matrix (band ``window``) of its series, or of
    at most :data:`MAX_SERIES` of them (the selection's sample when there is one); every
    series joins its nearest medoid.

    Returns
    -------
    groups : ndarray of int, shape (n_series,)
        Part of every series, numbered class by class.
    owners : ndarray of int, shape (n_groups,)
        Class of every part.
    """
    rng = check_random_state(random_state)
    groups = np.empty(collection.n_series, dtype=np.int64)
    owners: list[int] = []
    matrix = None if selection is None else selection.matrices.get(window)
    for c in range(int(codes.max()) + 1):
        members = np.flatnonzero(codes == c)
        if matrix is not None:
            position = np.flatnonzero(codes[selection.sample] == c)  # type: ignore[union-attr]
            chosen = selection.sample[position]  # type: ignore[union-attr]
            D = matrix[np.ix_(position, position)]
        else:
            chosen = members
            if len(members) > MAX_SERIES:
                chosen = np.sort(rng.choice(members, MAX_SERIES, replace=False))
            D = dtw_pairwise_distance(collection.subset(chosen), window=window, n_jobs=n_jobs)
        k = min(n_centroids, len(members), len(chosen))
        medoids, labels = kmedoids(np.ascontiguousarray(D), k)
        if len(chosen) == len(members):
            part = labels
        else:  # the series outside the sample join their nearest medoid
            to_medoids = dtw_pairwise_distance(
                collection.subset(members), collection.subset(chosen[medoids]),
                window=window, n_jobs=n_jobs,
            )  # fmt: skip
            part = to_medoids.argmin(1)
            part[np.searchsorted(members, chosen[medoids])] = np.arange(k)
        groups[members] = len(owners) + part
        owners += [c] * k
    return groups, np.asarray(owners, dtype=np.int64)
