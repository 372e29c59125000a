"""scikit-learn conformance and behaviour of the estimators."""

from __future__ import annotations

import pickle

import numpy as np
import pytest
from scipy.special import softmax
from sklearn.base import clone
from sklearn.exceptions import NotFittedError
from sklearn.model_selection import GridSearchCV, cross_val_score
from sklearn.pipeline import Pipeline
from sklearn.preprocessing import FunctionTransformer
from sklearn.utils.estimator_checks import parametrize_with_checks

from sk_rtw import (
    DBA,
    RTW,
    TTW,
    NTWAverager,
    NTWNearestCentroid,
    RTWAverager,
    RTWNearestCentroid,
    RTWPrototypeClassifier,
    TTWAverager,
    TTWNearestCentroid,
)
from sk_rtw.datasets import make_warped_signals
from sk_rtw.manifolds import SPD, Euclidean, Quaternion

from .conftest import quick

ESTIMATORS = [
    cls(method=quick(name), random_state=0)
    for cls, name in (
        (RTWAverager, "rtw"),
        (TTWAverager, "ttw"),
        (NTWAverager, "ntw"),
        (RTWNearestCentroid, "rtw"),
        (TTWNearestCentroid, "ttw"),
        (NTWNearestCentroid, "ntw"),
    )
] + [
    RTWNearestCentroid(method="dba"),
    RTWAverager(method="dba"),
    RTWPrototypeClassifier(method="dba", cv=3),
    RTWPrototypeClassifier(method=quick(), decision="readout", cv=2, random_state=0),
]

# Each expected failure of scikit-learn's generic checks, with the reason. Series of any
# length are accepted at predict/transform time (DTW compares series of different
# lengths; unequal-length test data is a requirement), so a different number of columns
# than in fit is not an error. The other assertions of these checks are covered by
# test_outputs_and_probabilities and test_fit_transform_equals_fit_then_transform.
_ANY_LENGTH = "series of any length are accepted: another column count is not an error"
EXPECTED_FAILURES = {
    "check_n_features_in_after_fitting": _ANY_LENGTH,
    "check_transformer_general": _ANY_LENGTH,
    "check_transformer_general(readonly_memmap=True)": _ANY_LENGTH,
    "check_transformer_general(readonly_memmap=True,X_dtype=float32)": _ANY_LENGTH,
    "check_classifiers_train": _ANY_LENGTH,
    "check_classifiers_train(readonly_memmap=True)": _ANY_LENGTH,
    "check_classifiers_train(readonly_memmap=True,X_dtype=float32)": _ANY_LENGTH,
}


def _expected_failures(estimator):
    return EXPECTED_FAILURES


@parametrize_with_checks(ESTIMATORS, expected_failed_checks=_expected_failures)
def test_sklearn_compatible(estimator, check):
    check(estimator)


# ----------------------------------------------------------------- helpers
def two_shape_classes(n_per_class=6, length=40, seed=0):
    """Univariate two-class data: warped sines and warped square-ish waves."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 1, length)
    X, y = [], []
    for label, shape in (
        ("sine", lambda u: np.sin(2 * np.pi * u)),
        ("bump", lambda u: np.exp(-((u - 0.5) ** 2) / 0.01)),
    ):
        for _ in range(n_per_class):
            power = np.exp(rng.normal(0, 0.25))
            X.append(shape(t**power) + 0.05 * rng.standard_normal(length))
            y.append(label)
    return np.array(X), np.array(y)


def znorm(X):
    X = np.asarray(X, dtype=float)
    return (X - X.mean(1, keepdims=True)) / X.std(1, keepdims=True)


# ------------------------------------------------------------------- usage
def test_pipeline_gridsearch_clone_pickle_and_cross_validation():
    X, y = two_shape_classes()
    pipe = Pipeline(
        [
            ("scale", FunctionTransformer(znorm)),
            ("clf", RTWNearestCentroid(method=RTW(n_epochs=20, hidden_size=32), random_state=0)),
        ]
    )
    assert pipe.fit(X, y).score(X, y) == 1.0
    grid = GridSearchCV(
        RTWNearestCentroid(method=RTW(n_epochs=10, hidden_size=16), random_state=0),
        {"method__loss_window": [0, 5], "manifold": ["euclidean", Euclidean(1)]},
        cv=2,
    )
    grid.fit(X, y)
    # the searched setting reached the engine of the refitted estimator
    chosen = grid.best_params_["method__loss_window"]
    assert grid.best_estimator_.alignments_[0].config.loss_window == chosen
    assert grid.score(X, y) >= 0.9
    scores = cross_val_score(
        RTWNearestCentroid(method=RTW(n_epochs=10, hidden_size=16), random_state=0), X, y, cv=3
    )
    assert scores.mean() >= 0.9
    fitted = pipe.named_steps["clf"]
    restored = pickle.loads(pickle.dumps(pipe))
    np.testing.assert_array_equal(restored.predict(X), pipe.predict(X))
    cloned = clone(fitted)
    assert cloned.get_params() == fitted.get_params() and not hasattr(cloned, "means_")



def test_a_grid_search_on_threads_scores_as_one_on_a_single_thread():
    """The user guide's advice for short searches: the search's workers as threads. The
    kernels then run side by side (they release the GIL); every candidate and fold must
    score exactly as in a sequential search."""
    import numba
    import torch
    from joblib import parallel_config

    X, y = two_shape_classes()
    grid = {"method": [RTW(n_epochs=15, hidden_size=16), DBA()], "n_centroids": [1, 2]}
    base = RTWNearestCentroid(random_state=0)
    # the log-loss reads the distances to the centroids, not only the predicted labels
    sequential = GridSearchCV(base, grid, cv=3, n_jobs=1, scoring="neg_log_loss").fit(X, y)
    threads_before = (torch.get_num_threads(), numba.get_num_threads())
    with parallel_config(backend="threading"):
        threaded = GridSearchCV(base, grid, cv=3, n_jobs=2, scoring="neg_log_loss").fit(X, y)
    # the fits set their thread counts in their own threads: the caller's are untouched
    assert (torch.get_num_threads(), numba.get_num_threads()) == threads_before
    for key in ("mean_test_score", "split0_test_score", "split1_test_score",
                "split2_test_score"):  # fmt: skip
        np.testing.assert_array_equal(threaded.cv_results_[key], sequential.cv_results_[key])
    np.testing.assert_array_equal(threaded.predict_proba(X), sequential.predict_proba(X))


def test_outputs_and_probabilities():
    X, y = two_shape_classes()
    clf = RTWNearestCentroid(method=RTW(n_epochs=15, hidden_size=16), random_state=0).fit(X, y)
    distances = clf.class_distances(X)
    assert distances.shape == (12, 2) and np.all(distances >= 0)
    proba = clf.predict_proba(X)
    np.testing.assert_allclose(proba.sum(1), 1.0)
    np.testing.assert_array_equal(clf.classes_[proba.argmax(1)], clf.predict(X))
    decision = clf.decision_function(X)
    assert decision.shape == (12,)
    np.testing.assert_array_equal(clf.classes_[(decision > 0).astype(int)], clf.predict(X))
    # the default: several centroids per class, each with its result and its class
    assert len(clf.means_) == len(clf.alignments_) == len(clf.centroid_classes_)
    assert set(clf.centroid_classes_.tolist()) == {0, 1}
    one = RTWNearestCentroid(method=RTW(n_epochs=15, hidden_size=16), n_centroids=1,
                             dtw_window=None, random_state=0).fit(X, y)  # fmt: skip
    assert one.means_.shape[0] == 2 and len(one.alignments_) == 2


def test_averager_without_labels_and_with_a_single_series_class():
    X, _ = two_shape_classes(3)
    averager = RTWAverager(method=RTW(n_epochs=5, hidden_size=8), random_state=0).fit(X)
    assert averager.means_.shape[0] == 1 and averager.transform(X).shape == (6, 1)
    # Z - 1 = 3 (T - 1): every third output index is a sample of the input
    averager = RTWAverager(
        method=RTW(n_epochs=5, hidden_size=8, output_length=3 * 39 + 1), random_state=0
    ).fit(X, [0] * 5 + [1])
    single = averager.alignments_[1]
    np.testing.assert_allclose(single.warps[0], np.linspace(0, 1, 118))
    np.testing.assert_allclose(single.mean[::3, 0], X[5], atol=1e-10)


def test_fit_transform_equals_fit_then_transform():
    X, y = two_shape_classes(3)
    est = RTWAverager(method=RTW(n_epochs=3, hidden_size=8), random_state=0)
    np.testing.assert_allclose(est.fit_transform(X, y), clone(est).fit(X, y).transform(X))


@pytest.mark.parametrize("labels", [["a", "b"], [3, 7], ["a", 7]])
def test_string_integer_and_mixed_labels(labels):
    X, y = two_shape_classes(4)
    y = [labels[0] if v == "sine" else labels[1] for v in y]
    clf = RTWNearestCentroid(method=RTW(n_epochs=10, hidden_size=16), random_state=0).fit(X, y)
    assert set(clf.classes_.tolist()) == set(labels)
    assert np.mean(clf.predict(X) == np.array(y, dtype=object)) >= 0.9


def test_unequal_lengths_and_other_test_lengths():
    X, y = two_shape_classes(4, length=50)
    ragged = [x[: 50 - 3 * (i % 4)] for i, x in enumerate(X)]
    clf = RTWNearestCentroid(method=RTW(n_epochs=10, hidden_size=16), random_state=0)
    clf.fit(ragged, y)
    X_test, y_test = two_shape_classes(3, length=35, seed=1)
    assert np.mean(clf.predict(X_test) == y_test) >= 0.8


@pytest.mark.parametrize(("name", "manifold"), [("quaternion", Quaternion()), ("spd", SPD(2))])
def test_separates_two_manifold_shapes(name, manifold):
    X, y = [], []
    for label, seed in (("first", 10), ("second", 20)):
        data = make_warped_signals(manifold, 5, 30, seed)
        X.extend(data.signals)
        y.extend([label] * 5)
    X = np.stack(X)
    clf = RTWNearestCentroid(manifold=name, method=RTW(n_epochs=20, hidden_size=16),
                             random_state=0)  # fmt: skip
    clf.fit(X[::2], np.array(y)[::2])
    assert np.mean(clf.predict(X[1::2]) == np.array(y)[1::2]) == 1.0
    manifold.validate(clf.means_, atol=1e-8)


def test_same_random_state_same_means():
    X, y = two_shape_classes(3)
    a = RTWAverager(method=RTW(n_epochs=5, hidden_size=8), random_state=3).fit(X, y)
    b = RTWAverager(method=RTW(n_epochs=5, hidden_size=8), random_state=3).fit(X, y)
    np.testing.assert_array_equal(a.means_, b.means_)


def test_parallel_classes_equal_sequential():
    X, y = two_shape_classes(3)
    a = RTWAverager(method=RTW(n_epochs=5, hidden_size=8), random_state=3).fit(X, y)
    b = RTWAverager(method=RTW(n_epochs=5, hidden_size=8), random_state=3, n_jobs=2).fit(X, y)
    np.testing.assert_allclose(a.means_, b.means_, atol=1e-10)


def test_named_estimators_use_their_engine():
    X, y = two_shape_classes(3)
    for cls, method in ((TTWAverager, "ttw"), (NTWNearestCentroid, "ntw")):
        assert cls().method == method  # the class's own default
        est = cls(method=quick(method), random_state=0).fit(X, y)
        assert {a.config.method for a in est.alignments_} == {method}


def test_verbose_reports_classes(capsys):
    X, y = two_shape_classes(2)
    RTWAverager(method=quick(), verbose=1).fit(X, y)
    assert "class 'bump'" in capsys.readouterr().err


# --------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    ("X", "y", "match"),
    [
        (np.zeros((4, 10)), [0, 0, 0, 0], "at least 2 classes"),
        (np.zeros((4, 10)), [0, 1, 0], "4 series but y has 3"),
        (np.array([[0.0, np.nan, 1.0], [0.0, 1.0, 2.0]]), [0, 1], "NaN"),
        (np.ones((2, 5, 3)), [0, 1], "not a point"),
        (np.zeros((0, 10)), [], "0 sample"),
        (np.zeros((2, 5, 3, 3)), [0, 1], "Euclidean data must be"),
    ],
)
def test_bad_input(X, y, match):
    manifold = "sphere" if np.asarray(X).ndim == 3 else "euclidean"
    with pytest.raises(ValueError, match=match):
        RTWNearestCentroid(manifold=manifold, method=quick(), random_state=0).fit(X, y)


def test_predict_before_fit():
    with pytest.raises(NotFittedError):
        RTWNearestCentroid().predict(np.zeros((2, 10)))
    with pytest.raises(NotFittedError):
        RTWAverager().transform(np.zeros((2, 10)))


# ----------------------------------------------------------------- methods
@pytest.mark.parametrize(
    ("estimator", "method"),
    [
        (RTWAverager(), "rtw"),
        (TTWAverager(), "ttw"),
        (NTWNearestCentroid(), "ntw"),
        (TTWNearestCentroid(method="dba"), "dba"),
        (RTWNearestCentroid(method="NTW"), "ntw"),
        (RTWNearestCentroid(method=TTW(n_epochs=2)), "ttw"),
    ],
)
def test_the_class_default_is_its_own_method_and_any_method_can_be_chosen(estimator, method):
    X, y = two_shape_classes(n_per_class=3, length=30)
    if isinstance(estimator.method, str) and estimator.method.lower() != "dba":
        estimator.set_params(method=quick(estimator.method.lower()))
    fitted = estimator.set_params(random_state=0).fit(X, y)
    assert fitted.method_ == method
    assert all(a.config.method == method for a in fitted.alignments_)


def test_dba_method_equals_the_baseline_per_class():
    from sk_rtw.baselines import dba_average

    X, y = two_shape_classes(n_per_class=4, length=30)
    clf = RTWNearestCentroid(method="dba", n_centroids=1, dtw_window=None).fit(X, y)
    for k, label in enumerate(clf.classes_):
        expected = dba_average(X[y == label]).mean
        np.testing.assert_allclose(clf.means_[k], expected, atol=1e-12)


def test_dba_on_a_manifold_and_on_unequal_lengths():
    q = [make_warped_signals(Quaternion(), 4, 30, seed).signals for seed in (1, 2)]
    X, y = np.concatenate(q), np.repeat([0, 1], 4)
    clf = RTWNearestCentroid(manifold="quaternion", method="dba").fit(X, y)
    np.testing.assert_allclose(np.linalg.norm(clf.means_, axis=-1), 1.0, atol=1e-9)
    assert clf.score(X, y) == 1.0
    rng = np.random.default_rng(0)
    series = [np.sin(np.linspace(0, 6, n)) + 0.01 * rng.standard_normal(n) for n in (30, 40)]
    series += [np.cos(np.linspace(0, 6, n)) for n in (25, 35)]
    unequal = RTWNearestCentroid(method="dba").fit(series, [0, 0, 1, 1])
    assert isinstance(unequal.means_, list)  # medoid lengths differ
    assert unequal.predict(series).tolist() == [0, 0, 1, 1]


def test_grid_search_reaches_the_method_and_the_preset():
    """A scorer that reads what was fitted (not the accuracy): each candidate's score
    proves that its method and preset reached the fit."""
    X, y = two_shape_classes(n_per_class=4, length=30)

    def fitted_with(estimator, X, y):
        config = estimator.alignments_[0].config
        return float(estimator.method_ == "dba") + 0.5 * float(config.preset == "paper")

    search = GridSearchCV(
        RTWNearestCentroid(method=quick(), random_state=0),
        {"method": [quick("rtw"), DBA()], "preset": ["class-means", "paper"]},
        cv=2, scoring=fitted_with,
    ).fit(X, y)  # fmt: skip
    np.testing.assert_array_equal(search.cv_results_["mean_test_score"], [0.0, 0.5, 1.0, 1.5])
    assert isinstance(search.best_params_["method"], DBA)


def test_grid_search_over_mean_weights():
    """The class-means choice (density or the paper's equal weights) is a searchable
    setting of the method, and it changes the fitted means."""
    X, y = two_shape_classes(n_per_class=4, length=30)
    base = RTWNearestCentroid(
        method=RTW(n_epochs=3, hidden_size=8), n_centroids=1, dtw_window=None, random_state=0
    )
    search = GridSearchCV(base, {"method__mean_weights": ["equal", "density"]}, cv=2).fit(X, y)
    assert np.isfinite(search.cv_results_["mean_test_score"]).all()
    equal = clone(base).set_params(method__mean_weights="equal").fit(X, y)
    density = clone(base).set_params(method__mean_weights="density").fit(X, y)
    assert equal.alignments_[0].config.mean_weights == "equal"
    assert density.alignments_[0].config.mean_weights == "density"
    assert not np.allclose(np.asarray(equal.means_), np.asarray(density.means_))


def test_bad_method_and_preset_are_named():
    X, y = two_shape_classes(n_per_class=2, length=20)
    with pytest.raises(ValueError, match="method must be one of"):
        RTWNearestCentroid(method="kmeans").fit(X, y)
    with pytest.raises(ValueError, match="preset"):
        RTWNearestCentroid(preset="fast").fit(X, y)


# ---------------------------------------------------------------- probabilities


def test_fit_temperature_minimises_the_log_loss_like_a_grid_search(rng):
    from scipy.special import log_softmax

    from sk_rtw.estimators._classifier import fit_temperature

    labels = rng.integers(0, 3, 200)
    distances = rng.gamma(4.0, 10.0, (200, 3))
    distances[np.arange(200), labels] *= 0.7  # own class nearer, with overlap

    def loss(tau):
        return -log_softmax(-distances / tau, axis=1)[np.arange(200), labels].mean()

    grid = np.exp(np.linspace(-3, 6, 4001))
    best_on_grid = grid[np.argmin([loss(t) for t in grid])]
    tau = fit_temperature(distances, labels)
    assert tau == pytest.approx(best_on_grid, rel=0.01)
    assert loss(tau) <= loss(best_on_grid) + 1e-9


def test_probabilities_are_calibrated_not_saturated():
    from sklearn.metrics import log_loss

    from sk_rtw.datasets import make_warped_signals

    rng = np.random.default_rng(0)
    a = np.asarray(make_warped_signals("euclidean", 30, 40, random_state=1).signals)[..., 0]
    b = a[:, ::-1] + 0.0  # the same shapes reversed in time: separable but noisy below
    X = np.concatenate([a, b]) * 10.0 + rng.normal(0, 6.0, (60, 40))
    y = np.repeat([0, 1], 30)
    clf = RTWNearestCentroid(method="dba", random_state=0).fit(X[::2], y[::2])
    raw = RTWNearestCentroid(method="dba", random_state=0, temperature=1.0).fit(X[::2], y[::2])
    proba = clf.predict_proba(X[1::2])
    assert clf.temperature_ > 1.0  # distances of ~100s: a unit scale saturates
    saturated = (proba.max(1) > 0.999).mean()
    assert saturated < 0.5 < (raw.predict_proba(X[1::2]).max(1) > 0.999).mean()
    assert np.array_equal(clf.predict(X[1::2]), raw.predict(X[1::2]))  # same decisions
    assert log_loss(y[1::2], proba) < log_loss(y[1::2], raw.predict_proba(X[1::2]))
    assert log_loss(y[1::2], proba) < np.log(2)  # better than knowing nothing


def test_a_given_temperature_is_used_as_is():
    X = np.stack([np.sin(np.linspace(0, 3, 20) + s) for s in (0.0, 0.1, 2.0, 2.1)])
    y = [0, 0, 1, 1]
    clf = RTWNearestCentroid(method="dba", temperature=2.5).fit(X, y)
    assert clf.temperature_ == 2.5
    expected = softmax(-clf.class_distances(X) / 2.5, axis=1)
    np.testing.assert_allclose(clf.predict_proba(X), expected)
    assert "temperature" in TTWNearestCentroid().get_params()


@pytest.mark.parametrize("bad", [0, -1.0, np.nan, "hot", True])
def test_bad_temperatures_are_rejected(bad):
    X = np.stack([np.sin(np.linspace(0, 3, 20) + s) for s in (0.0, 0.1, 2.0, 2.1)])
    with pytest.raises(ValueError, match="temperature"):
        RTWNearestCentroid(method="dba", temperature=bad).fit(X, [0, 0, 1, 1])


@pytest.mark.parametrize("manifold", ["euclidean", "sphere"])
def test_many_centroids_predict_as_the_exhaustive_search(manifold):
    """The nearest centroid of every class is found with lower bounds and early
    abandoning: the distances of transform reduced per class, and its predictions."""
    rng = np.random.default_rng(3)
    X = rng.standard_normal((60, 25, 3 if manifold == "sphere" else 1)).cumsum(1)
    if manifold == "sphere":
        X /= np.linalg.norm(X, axis=-1, keepdims=True)
    y = np.repeat([0, 1, 2], 20)
    clf = RTWNearestCentroid(manifold, method="dba", n_centroids=0.5, dtw_window=0.1).fit(X, y)
    assert len(clf.means_) == 30
    X_new = X[::3] + 0.01 * rng.standard_normal(X[::3].shape)
    if manifold == "sphere":
        X_new /= np.linalg.norm(X_new, axis=-1, keepdims=True)
    every = clf.transform(X_new)
    by_class = np.stack([every[:, clf.centroid_classes_ == c].min(1) for c in range(3)], 1)
    np.testing.assert_array_equal(clf.class_distances(X_new), by_class)
    np.testing.assert_array_equal(clf.predict(X_new), clf.classes_[by_class.argmin(1)])
    np.testing.assert_allclose(clf.predict_proba(X_new).sum(1), 1.0)


# ------------------------------------------------------------- representation
@pytest.mark.parametrize("method", ["dba", "rtw"])
def test_velocity_representation_is_the_classifier_on_the_tangent_velocity(method):
    """representation="velocity" is the same classifier fitted on tangent_velocity(X)
    (Euclidean): the same centroids and distances; inputs stay on the manifold."""
    from sk_rtw import tangent_velocity

    from .test_dtw import random_walk

    walks = [random_walk(Quaternion(), 20, s, step=0.1 * (1 + s % 2)) for s in range(12)]
    X, y = np.stack(walks), np.arange(12) % 2
    settings = {"method": quick(method) if method == "rtw" else "dba", "random_state": 0,
                "n_centroids": 1, "dtw_window": 0.2}  # fmt: skip
    ours = RTWNearestCentroid("quaternion", representation="velocity", **settings).fit(X, y)
    direct = RTWNearestCentroid("euclidean", **settings).fit(tangent_velocity(X, "quaternion"), y)
    assert ours.manifold_ == Quaternion() and ours.representation_ == "velocity"
    np.testing.assert_allclose(ours.means_, direct.means_, atol=1e-12)
    np.testing.assert_allclose(ours.class_distances(X),
                               direct.class_distances(tangent_velocity(X, "quaternion")),
                               atol=1e-10)  # fmt: skip
    assert ours.transform(X).shape == (12, 2)
    with pytest.raises(ValueError, match="representation"):
        RTWNearestCentroid(representation="derivative").fit(X[..., 0], y)
    with pytest.raises(ValueError, match="time points"):
        ours.predict([X[0, :1]])


def test_prototype_classifier_passes_the_representation_on():
    X, y = two_shape_classes()
    proto = RTWPrototypeClassifier(method="dba", representation="velocity", cv=2).fit(X, y)
    assert proto.centroids_.representation_ == "velocity"
    assert proto.means_.shape[1] == X.shape[1] - 1
    assert proto.predict(X).shape == (len(X),)


def test_auto_representation_is_chosen_with_the_band():
    """Two shapes under random offsets far larger than the shapes: the velocity (which
    drops the offsets) classifies the held-out series better, and "auto" takes it; with
    nothing chosen "auto" keeps the series."""
    rng = np.random.default_rng(1)
    t = np.linspace(0, 2 * np.pi, 40)
    y = np.arange(24) % 2
    X = np.stack([np.where(c, np.sin(t), np.sin(2 * t)) for c in y])
    X += rng.uniform(-10, 10, (24, 1)) + 0.05 * rng.standard_normal((24, 40))
    auto = RTWNearestCentroid(method="dba", representation="auto").fit(X, y)
    report = auto.selection_["representation"]
    assert auto.representation_ == report["chosen"] == "velocity"
    assert report["z"] >= 1.0 and report["accuracy"]["velocity"] > report["accuracy"]["raw"]
    assert auto.means_.shape[1] == 39
    fixed = RTWNearestCentroid(method="dba", representation="auto", n_centroids=1,
                               dtw_window=None).fit(X, y)  # fmt: skip
    assert fixed.representation_ == "raw" and fixed.selection_ == {}
