"""The prototype readout's leave-one-out predictions against refits without each series."""

from __future__ import annotations

from unittest import mock

import numpy as np
import pytest
from sklearn.linear_model import LogisticRegression, Ridge, RidgeClassifierCV, _ridge
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import LabelBinarizer, StandardScaler
from sklearn.utils.estimator_checks import parametrize_with_checks

from sk_rtw.estimators._out_of_fold import split_folds
from sk_rtw.estimators._prototypes import default_readout
from sk_rtw.estimators._readout_cv import (
    cross_validated_predictions,
    is_default_readout,
    ridge_loo_predictions,
    ridge_loo_scores,
)
from sk_rtw.estimators._ridge_readout import RidgeGCVClassifier


def noisy_features(rng, n, p, k):
    codes = rng.integers(0, k, n)
    codes[:k] = np.arange(k)  # every class present
    return rng.standard_normal((n, p)) + 0.5 * codes[:, None] * (np.arange(p) % k == 0), codes


@pytest.mark.parametrize(("n", "p", "k"), [(80, 12, 3), (30, 70, 4), (50, 8, 2)],
                         ids=["long", "wide", "two classes"])  # fmt: skip
def test_leave_one_out_scores_equal_refits_without_the_series(n, p, k, rng):
    features, codes = noisy_features(rng, n, p, k)
    readout = default_readout().fit(features, codes)
    scores, classes = ridge_loo_scores(readout, features, codes)
    scaled = readout[0].transform(features)
    targets = LabelBinarizer(pos_label=1, neg_label=-1).fit_transform(codes).astype(float)
    expected = np.empty_like(targets)
    for i in range(n):
        rest = np.arange(n) != i
        ridge = Ridge(alpha=readout[-1].alpha_).fit(scaled[rest], targets[rest])
        expected[i] = ridge.predict(scaled[i : i + 1])[0]
    np.testing.assert_allclose(scores, expected, rtol=1e-8, atol=1e-10)
    np.testing.assert_array_equal(classes, np.arange(k))
    # a series left out is predicted worse than in sample: the check can tell them apart
    in_sample = readout[-1].decision_function(scaled).reshape(n, -1)
    assert np.abs(in_sample - expected).max() > 1e-3
    predicted = ridge_loo_predictions(readout, features, codes)
    rule = (expected[:, 0] > 0).astype(int) if k == 2 else expected.argmax(1)
    np.testing.assert_array_equal(predicted, rule)


def test_only_the_plain_default_readout_takes_the_closed_form():
    assert is_default_readout(default_readout())
    assert not is_default_readout(LogisticRegression())
    assert not is_default_readout(make_pipeline(StandardScaler(), LogisticRegression()))
    weighted = RidgeClassifierCV(class_weight="balanced")
    assert not is_default_readout(make_pipeline(StandardScaler(), weighted))
    assert not is_default_readout(make_pipeline(StandardScaler(), RidgeClassifierCV(cv=3)))
    assert not is_default_readout(
        make_pipeline(StandardScaler(with_mean=False), RidgeClassifierCV())
    )


def test_other_readouts_are_refitted_on_the_folds(rng):
    features, codes = noisy_features(rng, 60, 6, 3)
    readout = LogisticRegression()
    fitted = LogisticRegression().fit(features, codes)
    got = cross_validated_predictions(readout, fitted, features, codes, 4, seed=7)
    expected = np.empty_like(codes)
    for train, test in split_folds(4, codes, 7):
        expected[test] = (
            LogisticRegression().fit(features[train], codes[train]).predict(features[test])
        )
    np.testing.assert_array_equal(got, expected)


@pytest.mark.parametrize(("n", "p", "k"), [(120, 15, 3), (60, 6, 2)], ids=["three", "two"])
def test_default_readout_fit_by_svd_equals_the_covariance_fit(n, p, k, rng):
    """RidgeGCVClassifier is RidgeClassifierCV's fit (its default, covariance mode, up to
    rounding: the same penalty and predictions) by one SVD of the features."""
    features, codes = noisy_features(rng, n, p, k)
    features = np.abs(features) + features[:, :1] ** 2  # correlated, uneven scales
    plain = make_pipeline(StandardScaler(), RidgeClassifierCV(alphas=np.logspace(-3, 3, 13)))
    plain.fit(features, codes)
    svd = _ridge._RidgeGCV._svd_decompose_design_matrix
    with mock.patch.object(_ridge._RidgeGCV, "_svd_decompose_design_matrix", autospec=True,
                           side_effect=svd) as spy:  # fmt: skip
        fitted = default_readout().fit(features, codes)
    assert spy.call_count == 1  # one SVD for every penalty
    assert isinstance(fitted[-1], RidgeGCVClassifier)
    assert fitted[-1].alpha_ == plain[-1].alpha_
    np.testing.assert_allclose(fitted[-1].coef_, plain[-1].coef_, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(fitted[-1].intercept_, plain[-1].intercept_, atol=1e-12)
    np.testing.assert_allclose(fitted[-1].best_score_, plain[-1].best_score_, rtol=1e-9)
    scores = fitted.decision_function(features), plain.decision_function(features)
    np.testing.assert_allclose(*scores, rtol=1e-9, atol=1e-12)
    np.testing.assert_array_equal(fitted.predict(features), plain.predict(features))
    assert fitted[-1].coef_.shape == plain[-1].coef_.shape


def test_wide_features_take_ridge_cvs_own_mode(rng):
    features, codes = noisy_features(rng, 20, 40, 3)  # more features than series
    with mock.patch.object(_ridge._RidgeGCV, "_svd_decompose_design_matrix") as spy:
        fitted = default_readout().fit(features, codes)
    spy.assert_not_called()
    plain = make_pipeline(StandardScaler(), RidgeClassifierCV(alphas=np.logspace(-3, 3, 13)))
    expected = plain.fit(features, codes).decision_function(features)
    np.testing.assert_array_equal(fitted.decision_function(features), expected)


def test_the_ridge_readout_needs_two_classes():
    with pytest.raises(ValueError, match="2 classes"):
        RidgeGCVClassifier().fit(np.ones((4, 2)), [0, 0, 0, 0])


@parametrize_with_checks([RidgeGCVClassifier()])
def test_the_ridge_readout_is_a_scikit_learn_classifier(estimator, check):
    check(estimator)
