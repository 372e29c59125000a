"""Distances of the training series to centroids that did not see them (out-of-fold).

A readout trained on the distances of the training series to the fitted centroids learns
from values that never occur at prediction time: a series is close to the centroid it
was averaged into. Here the training series are split into stratified folds; for every
fold, each centroid that averaged some of the fold's series is refitted on its other
series (the fit's record, :meth:`~sk_rtw.estimators._record.CentroidFitRecord.refit`:
same method, band, seed and settings; every touched centroid of the fold in one batched
fit), and the fold's series are measured against the centroids of the fit with
the refitted ones in their place. A centroid is only refitted without the series of its
own part, so the columns keep their meaning: column ``m`` is always "centroid ``m``".

A centroid whose every series lies in the fold (a centroid of one series) cannot be
refitted without them; its distance to those series is what the other series of their
class measure to it (their mean, which is out of sample for such a centroid), and the
fold's other series are measured against it as fitted.
"""

from __future__ import annotations

import sys
import time
import warnings
from typing import Any

import numpy as np
from sklearn.model_selection import KFold, StratifiedKFold

from .._random import check_random_state
from ..dtw import dtw_pairwise_distance
from ..utils import SeriesCollection, check_series_collection
from ._record import CentroidFitRecord


def out_of_fold_distances(
    record: CentroidFitRecord,
    means: list[np.ndarray],
    collection: SeriesCollection,
    n_folds: int,
    *,
    random_state: Any = None,
    owner: str = "RTWPrototypeClassifier",
) -> np.ndarray:
    """Distance of every training series to every centroid, out of fold.

    Parameters
    ----------
    record : CentroidFitRecord
        The record of the centroid fit (``_fit_record`` of a fitted
        :class:`RTWNearestCentroid`): its groups, classes, band, method and seeds.
    means : list of ndarray
        The fitted centroids (``means_``), entry ``m`` of centroid ``m``.
    collection : SeriesCollection
        The training series of the fit, in the record's representation.
    n_folds : int
        Stratified folds (at most the size of the largest class).
    random_state : int, RandomState or None
        Draws the folds. The refits keep the seeds the fit drew (the record's).
    owner : str
        The estimator's name, for the ``verbose`` lines.

    Returns
    -------
    distances : ndarray of shape (n_series, n_means)
        Column ``m`` is the entry ``m`` of ``means``.
    """
    verbose = record.context.verbose
    groups = record.groups
    codes = record.codes
    n_means = len(record.owners)
    means = list(means)
    rng = check_random_state(random_state)
    distances = np.full((collection.n_series, n_means), np.nan)
    start = time.perf_counter()
    folds = [test for _, test in split_folds(n_folds, codes, rng.randint(2**31 - 1))]
    for k, test in enumerate(folds):
        in_fold = np.zeros(collection.n_series, dtype=bool)
        in_fold[test] = True
        touched = np.unique(groups[test])
        kept = np.array([m for m in touched if np.any((groups == m) & ~in_fold)], dtype=np.int64)
        fold_means = list(means)
        if len(kept):
            rows = np.flatnonzero(np.isin(groups, kept) & ~in_fold)
            fits = record.refit(collection, rows, kept, verbose=max(0, verbose - 1), owner=owner)
            for m, fit in zip(kept, fits, strict=True):
                fold_means[m] = fit.mean
        reference = check_series_collection(fold_means, collection.manifold, name="means_",
                                            min_length=1)  # fmt: skip
        distances[test] = dtw_pairwise_distance(
            collection.subset(test), reference, window=record.dtw_window,
            n_jobs=record.context.n_jobs,
        )  # fmt: skip
        # a centroid whose every series is in the fold has not been seen without them
        lost = np.setdiff1d(touched, kept)
        own = np.isin(groups[test], lost)
        distances[test[own], groups[test[own]]] = np.nan
        if verbose:
            print(
                f"[{owner}] fold {k + 1}/{len(folds)}: {len(kept)} of {n_means} centroids "
                f"refitted without its {len(test)} series "
                f"({time.perf_counter() - start:.1f} s)",
                file=sys.stderr,
                flush=True,
            )
    return _fill_unseen(distances, codes)


def fold_count(n_folds: int, codes: np.ndarray) -> int:
    """The folds :func:`split_folds` makes of ``n_folds`` asked: at most as many as the
    largest class has series (as many as there are series where every class holds
    one)."""
    largest = int(np.bincount(codes).max())
    return min(n_folds, len(codes) if largest < 2 else largest)


def split_folds(n_folds: int, codes: np.ndarray, seed: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Stratified (train, test) folds, at most as many as the largest class has series
    (plain folds where every class holds one series; :func:`fold_count`); a class
    smaller than the folds is missing from some of them."""
    count = fold_count(n_folds, codes)
    splitter: KFold | StratifiedKFold
    if int(np.bincount(codes).max()) < 2:
        splitter = KFold(count, shuffle=True, random_state=seed)
    else:
        splitter = StratifiedKFold(count, shuffle=True, random_state=seed)
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "The least populated class", UserWarning)
        return list(splitter.split(np.zeros(len(codes)), codes))


def _fill_unseen(distances: np.ndarray, codes: np.ndarray) -> np.ndarray:
    """Each missing distance (a series to a centroid made of it alone) becomes the mean
    distance of the other series of its class to that centroid (of every series where
    the class has no other)."""
    missing = np.isnan(distances)
    if not missing.any():
        return distances
    seen = ~missing
    values = np.where(seen, distances, 0.0)
    n_classes = int(codes.max()) + 1
    sums = np.zeros((n_classes, distances.shape[1]))
    counts = np.zeros((n_classes, distances.shape[1]))
    np.add.at(sums, codes, values)
    np.add.at(counts, codes, seen)
    overall = values.sum(0) / np.maximum(seen.sum(0), 1)
    rows, columns = np.nonzero(missing)
    same = counts[codes[rows], columns]
    filled = distances.copy()
    filled[rows, columns] = np.where(
        same > 0, sums[codes[rows], columns] / np.maximum(same, 1), overall[columns]
    )
    return filled
