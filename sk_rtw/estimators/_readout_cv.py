"""The default readout of a prototype classifier: its fit, and its cross-validated
predictions for the choice of the decision.

The default readout (standardised features, then
:class:`~sk_rtw.estimators._ridge_readout.RidgeGCVClassifier`, ``RidgeClassifierCV``'s
fit) is linear least squares with a ridge penalty chosen by the leave-one-out errors of
every candidate (generalised cross-validation).

Its leave-one-out predictions follow from the fitted model in closed form (Allen's
PRESS; Golub, Heath and Wahba 1979): with the hat matrix
``H = 11^T / n + Z (Z^T Z + alpha I)^{-1} Z^T`` of the centred features ``Z`` and the
unpenalised intercept, the residual of series ``i`` left out is
``(y_i - yhat_i) / (1 - H_ii)``. One factorisation of a ``min(n, p)``-square matrix gives
every series' left-out prediction, where refitting the readout on folds costs a
``RidgeClassifierCV`` fit per fold: on ElectricDevices five such fits took longer than the
out-of-fold centroids. Any other readout is refitted on the folds of the out-of-fold
distances.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.linalg
from sklearn.base import clone
from sklearn.linear_model import RidgeClassifierCV
from sklearn.pipeline import Pipeline
from sklearn.preprocessing import LabelBinarizer, StandardScaler

from ._out_of_fold import split_folds
from ._ridge_readout import RidgeGCVClassifier


def is_default_readout(readout: Any) -> bool:
    """Whether ``readout`` is standardisation then a ridge classifier chosen by
    generalised cross-validation (:class:`RidgeGCVClassifier`, or ``RidgeClassifierCV``
    with an intercept, unweighted): the readouts whose left-out predictions have a
    closed form."""
    if not isinstance(readout, Pipeline) or len(readout.steps) != 2:
        return False
    scaler, ridge = readout.steps[0][1], readout.steps[1][1]
    if type(scaler) is not StandardScaler or not scaler.with_mean:
        return False
    if type(ridge) is RidgeGCVClassifier:
        return True
    return (
        type(ridge) is RidgeClassifierCV
        and ridge.fit_intercept
        and ridge.class_weight is None
        and ridge.cv is None
    )


def ridge_loo_predictions(readout: Pipeline, features: np.ndarray, codes: np.ndarray):
    """Leave-one-out class predictions of a fitted default readout at its chosen penalty
    (:func:`ridge_loo_scores`, then the classifier's rule: the largest score, or the sign
    of the one score of two classes)."""
    scores, classes = ridge_loo_scores(readout, features, codes)
    if scores.shape[1] == 1:
        return classes[(scores[:, 0] > 0).astype(np.int64)]
    return classes[scores.argmax(1)]


def ridge_loo_scores(readout: Pipeline, features: np.ndarray, codes: np.ndarray):
    """Leave-one-out scores of a fitted default readout at its chosen penalty.

    Parameters
    ----------
    readout : Pipeline
        ``StandardScaler`` then ``RidgeGCVClassifier`` (or ``RidgeClassifierCV``), fitted
        on ``features`` and ``codes`` (:func:`is_default_readout`).
    features : ndarray of shape (n_series, n_features)
    codes : ndarray of int, shape (n_series,)

    Returns
    -------
    scores : ndarray of shape (n_series, n_targets)
        The ridge's outputs (targets +-1 per class; one column for two classes) for
        each series from the readout fitted on the other series, with the same scaling
        and penalty.
    classes : ndarray
        The class of every column (for two classes: the negative and positive class).
    """
    scaled = readout[0].transform(features)
    centred = scaled - scaled.mean(0)  # zero up to rounding already
    binarizer = LabelBinarizer(pos_label=1, neg_label=-1).fit(codes)
    targets = binarizer.transform(codes).astype(float)
    alpha = float(readout[-1].alpha_)
    n, p = centred.shape
    if n >= p:  # (Z^T Z + alpha I)^{-1} Z^T by a Cholesky factor of the p x p matrix
        factor = scipy.linalg.cho_factor(centred.T @ centred + alpha * np.eye(p))
        solved = scipy.linalg.cho_solve(factor, centred.T)  # (p, n)
        leverage = np.einsum("ij,ji->i", centred, solved)
        fitted = centred @ (solved @ (targets - targets.mean(0)))
    else:  # the n x n kernel: H_Z = K (K + alpha I)^{-1}
        kernel = centred @ centred.T
        factor = scipy.linalg.cho_factor(kernel + alpha * np.eye(n))
        hat = kernel @ scipy.linalg.cho_solve(factor, np.eye(n))
        leverage = np.diag(hat).copy()
        fitted = hat @ (targets - targets.mean(0))
    fitted += targets.mean(0)
    leverage += 1.0 / n  # the intercept
    return targets - (targets - fitted) / (1.0 - leverage)[:, None], binarizer.classes_


def cross_validated_predictions(
    readout: Any, fitted: Any, features: np.ndarray, codes: np.ndarray, n_folds: int, seed: int
) -> np.ndarray:
    """Every training series' class from a readout that did not see it: the closed form
    for the default readout (``fitted``, on all series), else a clone of ``readout``
    refitted on the folds drawn from ``seed`` (those of the out-of-fold distances)."""
    if is_default_readout(fitted):
        return ridge_loo_predictions(fitted, features, codes)
    predicted = np.empty_like(codes)
    for train, test in split_folds(n_folds, codes, seed):
        if len(np.unique(codes[train])) < 2:  # a fold without a second class
            predicted[test] = codes[train][0]
            continue
        predicted[test] = clone(readout).fit(features[train], codes[train]).predict(features[test])
    return predicted
