"""RTWKMeans and several centroids per class."""

from __future__ import annotations

import numpy as np
import pytest
from sklearn.metrics import adjusted_rand_score
from sklearn.model_selection import GridSearchCV
from sklearn.utils.estimator_checks import parametrize_with_checks

from sk_rtw import DBA, RTW, RTWAverager, RTWKMeans, RTWNearestCentroid
from sk_rtw.baselines import dba_average
from sk_rtw.datasets import make_warped_signals
from sk_rtw.estimators._core import fill_empty as _fill_empty
from sk_rtw.estimators._selection import candidate_key
from sk_rtw.manifolds import Sphere

from .conftest import quick
from .test_estimators import EXPECTED_FAILURES


def three_shapes(manifold="euclidean", n_per=6, length=40, seed=0):
    """Warped copies of three different originals: the clusters are the originals."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 1, length)
    X, y = [], []
    for k, freq in enumerate((1.0, 2.0, 3.0)):
        if manifold == "euclidean":
            original = np.sin(2 * np.pi * freq * t)[:, None] + k
        else:  # a curve on S^2
            angle = np.pi * (0.2 + 0.6 * t)
            phase = freq * 3 * t + k
            original = np.stack(
                [np.sin(angle) * np.cos(phase), np.sin(angle) * np.sin(phase), np.cos(angle)],
                axis=1,
            )
        data = make_warped_signals(
            Sphere(2) if manifold == "sphere" else manifold,
            n_per,
            original=original,
            random_state=int(rng.integers(1000)),
        )
        X.append(np.asarray(data.signals))
        y += [k] * n_per
    return np.concatenate(X), np.array(y)


@parametrize_with_checks(
    [RTWKMeans(n_clusters=2, method="dba", random_state=0),
     RTWKMeans(n_clusters=2, method=quick(), max_iter=2, random_state=0)],
    expected_failed_checks=lambda est: EXPECTED_FAILURES,
)  # fmt: skip
def test_sklearn_compatible(estimator, check):
    check(estimator)


@pytest.mark.parametrize("method", [DBA(), RTW(n_epochs=32, hidden_size=64)], ids=repr)
def test_recovers_warped_copies_of_three_shapes(method):
    X, y = three_shapes()
    km = RTWKMeans(3, method=method, n_init=2, random_state=0).fit(X)
    assert adjusted_rand_score(y, km.labels_) == 1.0
    assert km.cluster_centers_.shape == (3, 40, 1)
    np.testing.assert_array_equal(km.predict(X), km.labels_)
    assert km.transform(X).shape == (18, 3)


def test_clusters_curves_on_the_sphere():
    X, y = three_shapes("sphere")
    km = RTWKMeans(3, method="dba", manifold="sphere", n_init=2, random_state=0).fit(X)
    assert adjusted_rand_score(y, km.labels_) == 1.0
    centres = km.cluster_centers_
    np.testing.assert_allclose(np.linalg.norm(centres, axis=-1), 1.0, atol=1e-9)  # on S^2
    assert isinstance(km.manifold_, Sphere)


def test_inertia_is_the_sum_of_squared_cost_dtw_as_aeon_computes_it():
    from aeon.distances import dtw_distance

    X, _ = three_shapes()
    km = RTWKMeans(3, method="dba", random_state=0).fit(X)
    expected = sum(
        dtw_distance(x[:, 0], km.cluster_centers_[k][:, 0])  # aeon: sum of squared costs
        for x, k in zip(X, km.labels_, strict=True)
    )
    assert km.inertia_ == pytest.approx(expected, rel=1e-9)
    own = [km.cluster_centers_[k][:, 0] for k in km.labels_]
    np.testing.assert_allclose(
        km.transform(X).min(1) ** 2,
        [dtw_distance(x[:, 0], c) for x, c in zip(X, own, strict=True)],
        rtol=1e-9,
    )


def test_more_seedings_never_raise_the_inertia():
    X, _ = three_shapes(seed=3)
    one = RTWKMeans(3, method="dba", n_init=1, random_state=5).fit(X)
    many = RTWKMeans(3, method="dba", n_init=4, random_state=5).fit(X)
    assert many.inertia_ <= one.inertia_ + 1e-9  # the first seeding is among the four


def test_empty_clusters_take_the_farthest_series_of_a_shared_cluster():
    distances = np.array([[0.0, 5.0, 5.0], [1.0, 5.0, 5.0], [9.0, 5.0, 5.0], [0.5, 0.2, 5.0]])
    labels = np.array([0, 0, 0, 1])
    filled, count = _fill_empty(labels, distances, 3)
    assert count == 1
    np.testing.assert_array_equal(filled, [0, 0, 2, 1])  # series 2 is farthest from its centre
    alone = _fill_empty(np.array([0, 1]), np.array([[9.0, 1.0], [1.0, 0.0]]), 2)
    np.testing.assert_array_equal(alone[0], [0, 1])  # nothing to fill, nothing moved


def test_identical_series_still_give_n_clusters():
    X = np.tile(np.sin(np.linspace(0, 3, 20)), (5, 1))
    km = RTWKMeans(3, method="dba", random_state=0).fit(X)
    assert sorted(set(km.labels_.tolist())) == [0, 1, 2]
    assert km.inertia_ == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize(
    ("params", "match"),
    [
        ({"n_clusters": 0}, "n_clusters"),
        ({"n_clusters": 2.5}, "n_clusters"),
        ({"n_init": 0}, "n_init"),
        ({"max_iter": 0}, "max_iter"),
        ({"tol": -1.0}, "tol"),
        ({"method": "kmeans"}, "method"),
        ({"dtw_window": 2.0}, "dtw_window"),
        ({"n_clusters": 50}, "at least as many series"),
    ],
)
def test_bad_parameters_are_named(params, match):
    X, _ = three_shapes()
    with pytest.raises(ValueError, match=match):
        RTWKMeans(**{"method": "dba", **params}).fit(X)


# ---------------------------------------------------------- several centroids per class


def test_one_centroid_per_class_is_each_classs_mean():
    """n_centroids=1 (the default) averages each class once, with no clustering: the
    means are the DBA baseline of every class, each series assigned to its own class."""
    X, y = three_shapes()
    one = RTWNearestCentroid(method="dba", n_centroids=1, dtw_window=None).fit(X, y)
    for k in range(3):
        np.testing.assert_allclose(one.means_[k], dba_average(X[y == k]).mean, atol=1e-12)
    np.testing.assert_array_equal(one.centroid_classes_, [0, 1, 2])
    np.testing.assert_array_equal(one.assignments_, y)


def test_several_centroids_capture_a_class_made_of_two_shapes():
    X, y = three_shapes()
    y = np.where(y == 2, 0, y)  # class 0: two different shapes; its mean fits neither
    one = RTWNearestCentroid(method="dba", n_centroids=1, dtw_window=None).fit(X, y)
    two = RTWNearestCentroid(method="dba", n_centroids=2, dtw_window=None).fit(X, y)
    assert len(two.means_) == 4 and two.centroid_classes_.tolist() == [0, 0, 1, 1]
    distances = two.class_distances(X)  # to every class: its nearest centroid
    assert distances.shape == (18, 2)
    all_centroids = two.transform(X)  # to every centroid, as RTWAverager.transform
    assert all_centroids.shape == (18, 4)
    np.testing.assert_allclose(distances[:, 0], all_centroids[:, :2].min(1))
    assert two.score(X, y) == 1.0
    assert two.score(X, y) >= one.score(X, y)


def test_n_centroids_is_searchable_and_validated():
    X, labels = three_shapes()
    y = np.where(labels == 2, 0, labels)  # class 0 of two shapes

    def centroids_fitted(estimator, X, y):  # what the candidate fitted, not its accuracy
        return float(len(estimator.means_))

    search = GridSearchCV(
        RTWNearestCentroid(method="dba", dtw_window=None), {"n_centroids": [1, 2]}, cv=2,
        scoring=centroids_fitted,
    ).fit(X, y)  # fmt: skip
    np.testing.assert_array_equal(search.cv_results_["mean_test_score"], [2.0, 4.0])
    assert search.best_params_ == {"n_centroids": 2}
    with pytest.raises(ValueError, match="n_centroids"):
        RTWNearestCentroid(method="dba", n_centroids=0).fit(X, y)
    few = RTWNearestCentroid(method="dba", n_centroids=10).fit(X, labels)  # capped per class
    assert len(few.means_) == 18


def test_centroids_per_class_use_the_classifiers_engine_settings():
    X, y = three_shapes()
    clf = RTWNearestCentroid(
        method=RTW(n_epochs=2, hidden_size=8, learning_rate=0.05, warp_start="identity"),
        n_centroids=2,
    ).fit(X, y)
    assert len(clf.alignments_) == len(clf.means_) == 6
    for fit in clf.alignments_:
        config = fit.config
        assert config.hidden_size == 8 and config.learning_rate == 0.05
        assert config.warp_start == "identity" and config.n_epochs == 2
    # every training series was averaged into a centroid of its own class
    _, codes = np.unique(y, return_inverse=True)
    assert np.array_equal(clf.centroid_classes_[clf.assignments_], codes)


def test_assignments_are_the_series_each_centroid_was_averaged_from():
    """``assignments_`` is the partition every centroid was averaged from:
    ``alignments_[k].aligned`` holds its series, all of its own class."""
    from aeon.datasets import load_classification

    X, y = load_classification("ItalyPowerDemand", split="train")
    clf = RTWAverager(method=RTW(n_epochs=4), n_centroids=4, dtw_window=0.0, random_state=2)
    clf.fit(X[:, 0], y)
    for k, fit in enumerate(clf.alignments_):
        members = np.flatnonzero(clf.assignments_ == k)
        assert len(fit.aligned) == len(members)
    _, codes = np.unique(y, return_inverse=True)
    assert np.array_equal(clf.centroid_classes_[clf.assignments_], codes)


def test_centroid_settings_belong_to_the_method_and_are_checked():
    X, _ = three_shapes()
    with pytest.raises(TypeError, match="method=RTW"):
        RTWKMeans(2, averager_params={"hidden_size": 8})
    with pytest.raises(TypeError, match="not of DBA"):
        RTWKMeans(2, method=DBA(n_epochs=3))
    with pytest.raises(ValueError, match="n_epochs"):
        RTWKMeans(2, method=RTW(n_epochs=-1)).fit(X)
    with pytest.raises(ValueError, match="max_iter"):
        RTWKMeans(2, method=DBA(max_iter=0)).fit(X)
    km = RTWKMeans(2, method=RTW(n_epochs=3, hidden_size=8), random_state=0).fit(X)
    assert {fit.config.hidden_size for fit in km.alignments_} == {8}


def test_distances_to_every_centroid_are_features_for_a_pipeline():
    """RTWAverager(n_centroids=k): one column per centroid (k per class, class of each
    column in centroid_classes_), usable in a Pipeline and searchable."""
    from sklearn.linear_model import LogisticRegression
    from sklearn.pipeline import Pipeline

    X, y = three_shapes()
    y = np.where(y == 2, 0, y)  # class 0 of two shapes: two centroids capture it
    averager = RTWAverager(method="dba", n_centroids=2, random_state=0).fit(X, y)
    features = averager.transform(X)
    assert features.shape == (len(X), 4) and averager.centroid_classes_.tolist() == [0, 0, 1, 1]
    # each column is the DTW distance to that centroid
    from sk_rtw import dtw_distance

    np.testing.assert_allclose(features[3, 1], dtw_distance(X[3], averager.means_[1]))
    pipe = Pipeline(
        [
            ("centroids", RTWAverager(method="dba", n_centroids=2, random_state=0)),
            ("clf", LogisticRegression(max_iter=1000)),
        ]
    ).fit(X, y)
    assert pipe.score(X, y) == 1.0
    search = GridSearchCV(pipe, {"centroids__n_centroids": [1, 2]}, cv=3).fit(X, y)
    k = search.best_params_["centroids__n_centroids"]
    assert search.best_estimator_[0].transform(X).shape[1] == 2 * k  # the searched k reached it


def test_the_documented_centroid_length_is_the_one_used():
    """Issue 27, 6: the docstring states the preset's rule; the centroids follow it."""
    from sk_rtw.align import PRESETS

    rule = PRESETS[RTWKMeans().preset].output_length
    assert rule.formula in " ".join(RTWKMeans.__doc__.split())
    rng = np.random.default_rng(0)
    lengths = [15, 16, 18, 22, 17, 21]
    X = [np.sin(np.linspace(0, 3, n)) + 0.01 * rng.standard_normal(n) for n in lengths[:3]]
    X += [np.cos(np.linspace(0, 3, n)) + 0.01 * rng.standard_normal(n) for n in lengths[3:]]
    km = RTWKMeans(2, method=quick(), random_state=0).fit(X)
    for k in range(2):
        members = np.asarray(lengths)[km.labels_ == k]
        assert len(km.cluster_centers_[k]) == rule(members)


# ------------------------------------------------------------ choices from the data (26)
def shifted_bumps(n_per=8, seed=0):
    """Two classes of the same bump, early and late: DTW without a band warps the shift
    away (the classes look alike); a narrow band keeps them apart."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 1, 50)
    X = [np.exp(-((t - c - rng.normal(0, 0.02)) ** 2) / 0.003) + 0.05 * rng.standard_normal(50)
         for c in [0.3] * n_per + [0.7] * n_per]  # fmt: skip
    return np.array(X), np.repeat([0, 1], n_per)


def test_an_auto_window_is_chosen_from_the_training_series_and_used_in_the_fit():
    from sk_rtw import AutoChoice

    PRIOR, WINDOWS = AutoChoice().prior, AutoChoice().windows

    X, y = shifted_bumps()
    X_test, y_test = shifted_bumps(seed=1)
    unbanded = RTWNearestCentroid(method="dba", n_centroids=1, dtw_window=None).fit(X, y)
    banded = RTWNearestCentroid(method="dba", n_centroids=1, dtw_window=0.05).fit(X, y)
    assert banded.score(X_test, y_test) == 1.0 > unbanded.score(X_test, y_test)
    auto = RTWNearestCentroid(method="dba", n_centroids=1, random_state=0).fit(X, y)
    candidates = auto.selection_["candidates"]
    assert [c["dtw_window"] for c in candidates] == list(WINDOWS)
    best = max(c["z"] for c in candidates)  # the prior's band unless clearly beaten
    chosen = next(c for c in candidates if c["dtw_window"] == auto.dtw_window_)
    assert chosen["z"] == best if best >= 1 else auto.dtw_window_ == PRIOR[0]
    # the same window given explicitly: the same means (the choice is what the fit used)
    explicit = RTWNearestCentroid(method="dba", n_centroids=1, dtw_window=auto.dtw_window_)
    np.testing.assert_array_equal(explicit.fit(X, y).means_, auto.means_)
    engine = RTWNearestCentroid(method=quick(), n_centroids=1, random_state=0).fit(X, y)
    assert {a.config.dtw_window for a in engine.alignments_} == {engine.dtw_window_}


def test_auto_centroids_split_a_class_made_of_two_shapes():
    """Class 0 holds series near +1 and near -1, class 1 series near 0: one centroid of
    class 0 sits near 0 too, two centroids do not."""
    rng = np.random.default_rng(0)
    levels = [1.0, -1.0] * 6 + [0.0] * 6
    X = np.array([level + 0.1 * rng.standard_normal(30) for level in levels])
    y = np.array([0] * 12 + [1] * 6)
    auto = RTWNearestCentroid(method="dba", dtw_window=None, random_state=0).fit(X, y)
    assert np.bincount(auto.centroid_classes_)[0] >= 2 and len(auto.means_) >= 4
    scores = {
        candidate_key(None, c["n_centroids"]): c["accuracy"] for c in auto.selection_["candidates"]
    }
    assert scores[candidate_key(None, auto.n_centroids_)] > scores[candidate_key(None, 1)]
    assert auto.score(X, y) == 1.0


def test_auto_choices_need_classes_and_work_with_a_class_of_one_series():
    X, y = three_shapes()
    with pytest.raises(ValueError, match="need y with at least 2 classes"):
        RTWAverager(method="dba", dtw_window="auto").fit(X)
    y_single = y.copy()
    y_single[0] = 9  # a class of one series: it cannot be held out (always wrong)
    clf = RTWNearestCentroid(method="dba").fit(X, y_single)
    assert clf.predict(X[:1]).tolist() == [9]  # its series is its centroid
    assert all(c["accuracy"] < 1 for c in clf.selection_["candidates"])
    assert clf.selection_["seconds"] >= 0  # every report says what the search cost
