"""Choices made from the training data: the DTW window and the number of centroids.

``dtw_window="auto"`` and ``n_centroids="auto"`` are resolved in ``fit`` from the
training series alone, before the final fit, into ``dtw_window_`` and ``n_centroids_``:

* the window: the Sakoe-Chiba band among :data:`WINDOWS` under which a training series'
  nearest other training series (leave-one-out 1-NN by manifold DTW) most often has its
  class; ties go to the narrower band (less warping, faster DTW). This is the UCR
  archive's "learned window" (Dau et al., 2019), computed once whatever the averaging
  method: it is a property of the data;
* the number of centroids per class: the value among :data:`CENTROIDS` (at most the size
  of the smallest class ...) with the best stratified cross-validated nearest-centroid
  accuracy of the estimator itself at that window, ties going to fewer centroids.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from sklearn.base import clone
from sklearn.model_selection import StratifiedKFold

from .._random import check_generator
from ..dtw import dtw_pairwise_distance
from ..utils import SeriesCollection

#: Candidate Sakoe-Chiba radii of ``dtw_window="auto"`` (None: no band).
WINDOWS: tuple[float | None, ...] = (0.0, 0.02, 0.05, 0.1, 0.2, None)
#: Candidate centroids per class of ``n_centroids="auto"``.
CENTROIDS = (1, 2, 4, 8)
#: Folds of the internal cross-validation.
FOLDS = 3


def _width(window: float | None) -> float:
    return 2.0 if window is None else float(window)


def loo_window(
    collection: SeriesCollection,
    codes: np.ndarray,
    windows: tuple[float | None, ...] = WINDOWS,
    n_jobs: int | None = None,
) -> tuple[float | None, dict[str, float]]:
    """The window of the best leave-one-out 1-NN accuracy on the training series.

    Returns
    -------
    window : float or None
    scores : dict
        Accuracy of every candidate (key: ``str(window)``).
    """
    scores = {}
    for window in windows:
        D = dtw_pairwise_distance(collection, window=window, n_jobs=n_jobs)
        np.fill_diagonal(D, np.inf)
        scores[str(window)] = float((codes[D.argmin(1)] == codes).mean())
    best = max(windows, key=lambda w: (scores[str(w)], -_width(w)))
    return best, scores


def folds(codes: np.ndarray, random_state: Any) -> list[tuple[np.ndarray, np.ndarray]]:
    """Stratified folds (as many as the smallest class allows, at most :data:`FOLDS`)."""
    smallest = int(np.bincount(codes).min())
    n_folds = min(FOLDS, smallest)
    if n_folds < 2:
        return []
    seed = int(check_generator(random_state).integers(2**31 - 1))
    splitter = StratifiedKFold(n_folds, shuffle=True, random_state=seed)
    return list(splitter.split(np.zeros(len(codes)), codes))


def cv_accuracy(
    estimator, collection: SeriesCollection, codes: np.ndarray, splits, **params: Any
) -> float:
    """Mean nearest-centroid accuracy of ``clone(estimator)`` with ``params`` over ``splits``."""
    scores = []
    for train, test in splits:
        model = clone(estimator).set_params(verbose=0, **params)
        model._fit_means(collection.subset(train), codes[train], require_two_classes=False)
        distances = model._centroid_distances(collection.subset(test))
        predicted = model.classes_[model.centroid_classes_[distances.argmin(1)]]
        scores.append(float((predicted == codes[test]).mean()))
    return float(np.mean(scores))
