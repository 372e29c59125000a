"""Choices made from the training data: the DTW window and the number of centroids.

``dtw_window="auto"`` and ``n_centroids="auto"`` are resolved in ``fit`` from the
training series alone, before the final fit, into ``dtw_window_`` and ``n_centroids_``:
every candidate (a Sakoe-Chiba radius of :data:`WINDOWS`, a number of centroids per class
of :data:`CENTROIDS`; the pairs of both when both are "auto") is scored by the
stratified cross-validated (:data:`FOLDS` folds) nearest-centroid accuracy of DBA
centroids -- a fast stand-in for every averaging method, whose own centroids are then
fitted once with the best candidate. Ties go to fewer centroids, then to the narrower
band (less warping, faster prediction). A class smaller than a number of centroids
keeps one centroid per series.

Chosen on half A of the UCR development archive (15 datasets; the test accuracy of the
DBA centroids each rule picks, docs: UCR benchmark): this joint search 0.836 mean
accuracy, at least as accurate as 1-NN DTW (0.838) on 9 of 15; the window first (at one
centroid per class), then the centroids, 0.829 and 7 of 15 at half the cost; the window
of the best leave-one-out 1-NN accuracy (the UCR archive's "learned window", which suits
1-NN, not centroids) with the centroids by cross-validation, 0.817 and 6 of 15.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
from sklearn.base import clone
from sklearn.model_selection import StratifiedKFold

from .._random import check_generator
from ..utils import SeriesCollection

#: Candidate Sakoe-Chiba radii of ``dtw_window="auto"`` (None: no band).
WINDOWS: tuple[float | None, ...] = (0.0, 0.05, 0.1, 0.2, None)
#: Candidate centroids per class of ``n_centroids="auto"``.
CENTROIDS = (1, 2, 4, 8)
#: Folds of the internal cross-validation.
FOLDS = 3


def _width(window: float | None) -> float:
    return 2.0 if window is None else float(window)


def choose(
    estimator, collection: SeriesCollection, codes: np.ndarray, window: Any, n_centroids: Any
) -> tuple[float | None, int, dict]:
    """Resolve ``"auto"`` window and centroid count (module docstring); their scores."""
    from ..methods import DBA

    start = time.perf_counter()
    proxy = clone(estimator).set_params(method=DBA(), verbose=0)
    splits = folds(codes, estimator.random_state)
    report: dict[str, Any] = {"criterion": f"{len(splits)}-fold accuracy of DBA centroids"}
    if not splits:  # a class of one series: nothing to validate on
        report["criterion"] = "no fold possible (a class of one series): the defaults"
        report["seconds"] = time.perf_counter() - start
        return (
            (None if window == "auto" else window),
            (1 if n_centroids == "auto" else n_centroids),
            report,
        )
    windows = WINDOWS if window == "auto" else (window,)
    counts = CENTROIDS if n_centroids == "auto" else (n_centroids,)
    scores = {
        (w, k): cv_accuracy(proxy, collection, codes, splits, dtw_window=w, n_centroids=k)
        for w in windows
        for k in counts
    }
    window, n_centroids = max(scores, key=lambda c: (round(scores[c], 12), -c[1], -_width(c[0])))
    report["candidates"] = [
        {"dtw_window": w, "n_centroids": k, "accuracy": v} for (w, k), v in scores.items()
    ]
    report["seconds"] = time.perf_counter() - start
    return window, n_centroids, report


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
