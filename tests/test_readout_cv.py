"""The prototype readout's leave-one-out predictions against refits without each series."""

from __future__ import annotations

from unittest import mock

import numpy as np
import pytest
from sklearn.base import clone
from sklearn.linear_model import LogisticRegression, Ridge, RidgeClassifierCV, _ridge
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import LabelBinarizer, StandardScaler

from sk_rtw.estimators._out_of_fold import split_folds
from sk_rtw.estimators._prototypes import default_readout
from sk_rtw.estimators._readout_cv import (
    cross_validated_predictions,
    fit_readout,
    is_default_readout,
    ridge_loo_predictions,
    ridge_loo_scores,
)


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
    features, codes = noisy_features(rng, n, p, k)
    features = np.abs(features) + features[:, :1] ** 2  # correlated, uneven scales
    plain = default_readout().fit(features, codes)
    svd = _ridge._RidgeGCV._svd_decompose_design_matrix
    with mock.patch.object(_ridge._RidgeGCV, "_svd_decompose_design_matrix", autospec=True,
                           side_effect=svd) as spy:  # fmt: skip
        fitted = fit_readout(default_readout(), features, codes)
    assert spy.call_count == 1  # scikit-learn still honours the mode
    assert fitted[-1].alpha_ == plain[-1].alpha_
    np.testing.assert_allclose(fitted[-1].coef_, plain[-1].coef_, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(fitted[-1].intercept_, plain[-1].intercept_, atol=1e-12)
    np.testing.assert_allclose(fitted[-1].best_score_, plain[-1].best_score_, rtol=1e-9)
    np.testing.assert_array_equal(fitted.predict(features), plain.predict(features))
    # the mode is no parameter: clone and repr show the readout the user gave
    assert "gcv_mode" not in fitted[-1].get_params()
    assert repr(fitted) == repr(plain)
    assert not hasattr(clone(fitted)[-1], "gcv_mode") or clone(fitted)[-1].gcv_mode is None


def test_other_readouts_and_wide_features_fit_as_given(rng):
    features, codes = noisy_features(rng, 20, 40, 3)  # more features than series
    with mock.patch.object(_ridge._RidgeGCV, "_svd_decompose_design_matrix") as spy:
        fitted = fit_readout(default_readout(), features, codes)
        weighted = make_pipeline(StandardScaler(), RidgeClassifierCV(class_weight="balanced"))
        long_features, long_codes = noisy_features(rng, 80, 5, 3)
        fit_readout(weighted, long_features, long_codes)
    spy.assert_not_called()
    assert getattr(fitted[-1], "gcv_mode", None) is None
    assert getattr(weighted[-1], "gcv_mode", None) is None
