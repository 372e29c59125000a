"""RTWPrototypeClassifier: out-of-fold distances against refits done by hand, the readout."""

from __future__ import annotations

import pickle

import numpy as np
import pytest
from scipy.special import softmax
from sklearn.base import clone
from sklearn.linear_model import LinearRegression, LogisticRegression
from sklearn.model_selection import GridSearchCV, StratifiedKFold
from sklearn.neighbors import KNeighborsClassifier
from sklearn.pipeline import Pipeline
from sklearn.preprocessing import FunctionTransformer

from sk_rtw import DBA, RTWAverager, RTWNearestCentroid, RTWPrototypeClassifier, dtw_distance
from sk_rtw.estimators._out_of_fold import out_of_fold_distances
from sk_rtw.utils import check_series_collection

from .conftest import quick
from .test_estimators import two_shape_classes, znorm


def three_shape_classes(n_per_class=8, length=30, seed=0):
    """Three classes, each of two shapes (so that several centroids per class help)."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 1, length)
    shapes = [
        (lambda u: np.sin(2 * np.pi * u), lambda u: np.sin(4 * np.pi * u)),
        (lambda u: np.exp(-((u - 0.3) ** 2) / 0.01), lambda u: np.exp(-((u - 0.7) ** 2) / 0.01)),
        (lambda u: u, lambda u: 1 - u),
    ]
    X, y = [], []
    for label, pair in enumerate(shapes):
        for i in range(n_per_class):
            power = np.exp(rng.normal(0, 0.2))
            X.append(pair[i % 2](t**power) + 0.05 * rng.standard_normal(length))
            y.append(label)
    return np.array(X), np.array(y)


def test_out_of_fold_distances_are_those_of_centroids_refitted_without_the_fold():
    """Every distance equals the DTW of the series to its centroid averaged without the
    series' fold (an independent fit of that part), or to the fitted centroid where the
    centroid averaged no series of the fold."""
    X, y = three_shape_classes()
    window = 0.1
    nc = RTWNearestCentroid(method=DBA(), n_centroids=2, dtw_window=window, random_state=0)
    nc.fit(X, y)
    collection = check_series_collection(X)
    D = out_of_fold_distances(nc._fit_record, list(nc.means_), collection, 4, random_state=3)
    rng = np.random.RandomState(3)
    folds = StratifiedKFold(4, shuffle=True, random_state=rng.randint(2**31 - 1))
    checked_refits = 0
    for _, test in folds.split(X, y):
        for m in range(len(nc.means_)):
            members = np.flatnonzero(nc.assignments_ == m)
            rest = np.setdiff1d(members, test)
            if len(rest) == len(members):
                centroid = nc.means_[m]
            else:
                averager = RTWAverager(method=DBA(), dtw_window=window)
                centroid = averager.fit(X[rest]).means_[0]
                checked_refits += 1
            for i in test:
                expected = dtw_distance(X[i], centroid, window=window)
                np.testing.assert_allclose(D[i, m], expected, rtol=1e-10)
    assert checked_refits > 0


def test_a_centroid_of_one_series_gets_its_class_mean_distance():
    X, y = three_shape_classes(n_per_class=5)
    nc = RTWNearestCentroid(method=DBA(), n_centroids=1.0, dtw_window=0.1).fit(X, y)
    D = out_of_fold_distances(nc._fit_record, list(nc.means_), check_series_collection(X), 5,
                              random_state=0)  # fmt: skip
    full = np.array([[dtw_distance(a, b, window=0.1) for b in X] for a in X])
    for i in range(len(X)):
        same = np.flatnonzero((y == y[i]) & (np.arange(len(X)) != i))
        np.testing.assert_allclose(D[i, i], full[same, i].mean(), rtol=1e-10)
        others = np.arange(len(X)) != i
        np.testing.assert_allclose(D[i, others], full[i, others], rtol=1e-10)


def test_predictions_transform_and_readout_weights():
    X, y = three_shape_classes()
    clf = RTWPrototypeClassifier(method=DBA(), n_centroids=2, dtw_window=0.1, cv=3,
                                 decision="readout", random_state=0).fit(X, y)  # fmt: skip
    assert clf.decision_ == "readout" and clf.cv_accuracy_ == {}
    assert isinstance(clf.centroids_, RTWNearestCentroid)
    np.testing.assert_array_equal(clf.transform(X), clf.centroids_.transform(X))
    assert clf.transform(X).shape == (len(X), 6)
    assert clf.score(X, y) == 1.0
    assert clf.readout_weights_.shape == (3, 6)
    scores = clf.decision_function(X)
    np.testing.assert_array_equal(clf.classes_[scores.argmax(1)], clf.predict(X))
    assert not hasattr(clf, "predict_proba")  # RidgeClassifierCV has none
    # a feature is log(1 + d / s) of the distance d
    features = np.log1p(clf.transform(X) / clf.distance_scale_)
    np.testing.assert_allclose(scores, clf.readout_.decision_function(features))


def test_two_classes_weights_and_probabilities():
    X, y = two_shape_classes()
    clf = RTWPrototypeClassifier(
        method=DBA(),
        n_centroids=2,
        dtw_window=0.1,
        cv=3,
        readout=LogisticRegression(),
        decision="readout",
        random_state=0,
    ).fit(X, y)
    proba = clf.predict_proba(X)
    np.testing.assert_allclose(proba.sum(1), 1.0)
    np.testing.assert_array_equal(clf.classes_[proba.argmax(1)], clf.predict(X))
    weights = clf.readout_weights_
    np.testing.assert_array_equal(weights[0], -weights[1])
    np.testing.assert_array_equal(weights[1], clf.readout_.coef_[0])
    knn = clf.set_params(readout=KNeighborsClassifier(1)).fit(X, y)
    with pytest.raises(AttributeError, match="linear readout"):
        _ = knn.readout_weights_


def _left_out_by_refits(clf, features, y):
    """The default readout's classes for each series from a ridge refitted without it
    (same scaling, the penalty the readout chose): leave-one-out by brute force."""
    from sklearn.linear_model import RidgeClassifier

    scaled = clf.readout_[0].transform(features)
    alpha = clf.readout_[-1].alpha_
    predicted = np.empty(len(y), dtype=int)
    for i in range(len(y)):
        rest = np.arange(len(y)) != i
        ridge = RidgeClassifier(alpha=alpha).fit(scaled[rest], y[rest])
        predicted[i] = ridge.predict(scaled[i : i + 1])[0]
    return predicted


@pytest.mark.parametrize("readout", [None, LogisticRegression()], ids=["default", "logistic"])
def test_auto_decision_follows_the_cross_validated_scores(readout):
    """ "auto" keeps the nearest centroid unless the readout's cross-validated accuracy is
    at least one standard error above it; the scores are recomputed here: the default
    readout's leave-one-out predictions by refits, another readout's on the folds."""
    from sklearn.base import clone as clone_estimator

    from sk_rtw.estimators._out_of_fold import split_folds

    X, y = three_shape_classes(n_per_class=10, seed=1)
    clf = RTWPrototypeClassifier(method=DBA(), n_centroids=2, dtw_window=0.1, cv=3,
                                 readout=readout, random_state=0).fit(X, y)  # fmt: skip
    features = np.log1p(clf.oof_distances_ / clf.distance_scale_)
    if readout is None:
        predicted = _left_out_by_refits(clf, features, y)
    else:
        seed = np.random.RandomState(0).randint(2**31 - 1)
        predicted = np.empty(len(y), dtype=int)
        for train, test in split_folds(3, y, seed):
            predicted[test] = (
                clone_estimator(readout).fit(features[train], y[train]).predict(features[test])
            )
    nearest = np.stack([clf.oof_distances_[:, clf.centroid_classes_ == c].min(1)
                        for c in range(3)], 1).argmin(1)  # fmt: skip
    scores = clf.cv_accuracy_
    assert scores["readout"] == pytest.approx((predicted == y).mean())
    assert scores["nearest"] == pytest.approx((nearest == y).mean())
    better = int(np.sum((predicted == y) & (nearest != y)))
    worse = int(np.sum((predicted != y) & (nearest == y)))
    z = (better - worse) / np.sqrt(better + worse) if better + worse else 0.0
    assert scores["z"] == pytest.approx(z)
    assert clf.decision_ == ("readout" if z >= 1.0 else "nearest")
    forced = clone(clf).set_params(decision="nearest").fit(X, y)
    np.testing.assert_array_equal(forced.predict(X), forced.centroids_.predict(X))
    expected = softmax(-forced.centroids_.class_distances(X) / forced.temperature_, axis=1)
    np.testing.assert_allclose(forced.predict_proba(X), expected)
    assert forced.centroids_.temperature_ == 1.0  # the composed fit is never written into


@pytest.mark.parametrize(
    ("readout", "match"),
    [(LinearRegression(), r"readout must be None \(the default readout\) or a scikit-learn cl"),
     ("ridge", "readout must be")],
)  # fmt: skip
def test_a_readout_that_is_no_classifier_is_refused(readout, match):
    X, y = two_shape_classes()
    with pytest.raises(ValueError, match=match):
        RTWPrototypeClassifier(method=DBA(), readout=readout).fit(X, y)


def test_cv_is_checked_before_any_work():
    X, y = two_shape_classes()
    with pytest.raises(ValueError, match="cv must be an integer >= 2"):
        RTWPrototypeClassifier(method=DBA(), cv=1).fit(X, y)


def test_the_centroids_are_the_nearest_centroid_fit():
    X, y = three_shape_classes()
    settings = dict(method=quick(), n_centroids=0.25, dtw_window=0.1, random_state=0)
    clf = RTWPrototypeClassifier(**settings, cv=2).fit(X, y)
    nc = RTWNearestCentroid(**settings).fit(X, y)
    np.testing.assert_array_equal(clf.means_, nc.means_)
    np.testing.assert_array_equal(clf.centroid_classes_, nc.centroid_classes_)
    np.testing.assert_array_equal(clf.centroids_.predict(X), nc.predict(X))


def test_pipeline_gridsearch_clone_pickle():
    X, y = three_shape_classes()
    base = RTWPrototypeClassifier(method="dba", dtw_window=0.1, n_centroids=2, cv=2,
                                  random_state=0)  # fmt: skip
    pipe = Pipeline([("scale", FunctionTransformer(znorm)), ("clf", base)]).fit(X, y)
    restored = pickle.loads(pickle.dumps(pipe))
    np.testing.assert_array_equal(restored.predict(X), pipe.predict(X))
    grid = GridSearchCV(
        base, {"readout": [None, LogisticRegression(C=10.0)], "method__max_iter": [2, 5]}, cv=2
    ).fit(X, y)
    assert grid.best_estimator_.readout_ is not grid.best_params_["readout"]  # cloned
    assert grid.best_estimator_.centroids_.method.max_iter == grid.best_params_["method__max_iter"]
    assert clone(base).get_params() == base.get_params()


def test_a_class_of_one_series_gets_the_column_mean():
    """Every class one series (every centroid a series): folds without stratification, and
    a series' distance to itself is the mean of the others' distances to it."""
    X, _ = three_shape_classes(n_per_class=2)
    y = np.arange(len(X))
    nc = RTWNearestCentroid(method=DBA(), n_centroids=1, dtw_window=0.1).fit(X, y)
    D = out_of_fold_distances(nc._fit_record, list(nc.means_), check_series_collection(X), 3,
                              random_state=0)  # fmt: skip
    full = np.array([[dtw_distance(a, b, window=0.1) for b in X] for a in X])
    others = ~np.eye(len(X), dtype=bool)
    np.testing.assert_allclose(D[others], full[others], rtol=1e-10)
    expected = np.array([full[others[:, m], m].mean() for m in range(len(X))])
    np.testing.assert_allclose(np.diag(D), expected, rtol=1e-10)


def test_a_random_state_object_gives_one_reproducible_fit():
    """With a RandomState the fit draws one integer seed: the nearest-centroid fit keeps
    it, and the out-of-fold distances recomputed from it are the fitted ones (the refits
    used the fit's seeds and folds)."""
    X, y = three_shape_classes()
    clf = RTWPrototypeClassifier(method=quick(), n_centroids=2, dtw_window=0.1, cv=3,
                                 random_state=np.random.RandomState(5)).fit(X, y)  # fmt: skip
    seed = clf.centroids_.random_state
    assert isinstance(seed, int)
    record = clf.centroids_._fit_record
    again = out_of_fold_distances(record, list(clf.means_), check_series_collection(X), 3,
                                  random_state=seed)  # fmt: skip
    np.testing.assert_array_equal(again, clf.oof_distances_)
    twin = RTWPrototypeClassifier(method=quick(), n_centroids=2, dtw_window=0.1, cv=3,
                                  random_state=np.random.RandomState(5)).fit(X, y)  # fmt: skip
    np.testing.assert_array_equal(twin.oof_distances_, clf.oof_distances_)
