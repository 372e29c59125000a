"""Geodesic dilated shapelets: features against brute force on every kind of space, the
manifold's z-normalisation invariant to the frame, thresholds from the class, the
scikit-learn rules, clear errors."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from sklearn.base import clone
from sklearn.model_selection import GridSearchCV
from sklearn.utils.estimator_checks import parametrize_with_checks

from sk_rtw import SPD, GeodesicShapeletClassifier, GeodesicShapeletTransform, Quaternion
from sk_rtw.manifolds import Euclidean, Product, Sphere, quaternion_product

from .conftest import rlasa_in_own_frames
from .test_dtw import random_walk
from .test_estimators import EXPECTED_FAILURES


def _expected_failures(estimator):
    return EXPECTED_FAILURES


@parametrize_with_checks(
    [GeodesicShapeletTransform(n_shapelets=8, random_state=0),
     GeodesicShapeletClassifier(n_shapelets=8, random_state=0)],
    expected_failed_checks=_expected_failures,
)
def test_sklearn_compatible(estimator, check):
    check(estimator)


def _brute_features(transform, X, manifold):
    """Every shapelet's three features with Python loops over windows and points: the
    manifold's own distance, its own normalisation, the velocity by tangent_velocity."""
    from sk_rtw import tangent_velocity

    out = []
    for x in X:
        row = []
        for s in transform.shapelets_:
            if s.representation == "velocity":
                series = np.asarray(tangent_velocity(x[None], manifold))[0]
                space = Euclidean(series.shape[-1])
                series = series.reshape(len(series), -1)
            else:
                series, space = x, manifold
            span = (s.length - 1) * s.dilation
            distances = []
            for t in range(len(series) - span):
                window = series[t + s.dilation * np.arange(s.length)]
                compare = space
                if s.normalised:
                    window = space.normalise_windows(window[None])[0]
                    compare = space.normalised_space
                distances.append(sum(float(compare.dist(a, b))
                                     for a, b in zip(s.points, window, strict=True)))  # fmt: skip
            d = np.array(distances)
            row += [d.min(), np.argmin(d), np.count_nonzero(d < s.threshold)]
        out.append(row)
    return np.array(out)


@pytest.mark.parametrize(
    "manifold",
    [Euclidean(1), Euclidean(3), Sphere(2), Quaternion(), SPD(2), SPD(3),
     Product((Euclidean(3), Quaternion()))],
    ids=repr,
)
def test_features_are_the_brute_force_ones(manifold):
    X = np.stack([random_walk(manifold, 30, s, step=0.3) for s in range(6)])
    if manifold == Euclidean(1):
        X = X[..., 0]
    y = [0, 0, 0, 1, 1, 1]
    transform = GeodesicShapeletTransform(manifold, n_shapelets=24, lengths=(3, 5),
                                          random_state=0).fit(X, y)  # fmt: skip
    kinds = {(s.representation, s.normalised) for s in transform.shapelets_}
    if manifold.normalised_space is not None:
        assert kinds == {("raw", True), ("raw", False), ("velocity", True),
                         ("velocity", False)}  # fmt: skip
    got = transform.transform(X[:3])
    expected = _brute_features(transform, X[:3] if manifold != Euclidean(1) else X[:3, :, None],
                               manifold)  # fmt: skip
    np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("lengths", [(7, 8, 9), (11, 16, 17), (24, 31)])
def test_univariate_features_over_blocks_of_terms_are_the_brute_force_ones(lengths):
    """On R^1 the kernel checks its abandoning every eight terms: shapelets of lengths
    below, at and past multiples of eight give the brute-force features."""
    X = np.stack([random_walk(Euclidean(1), 80, s, step=0.3) for s in range(8)])[..., 0]
    y = [0, 1] * 4
    transform = GeodesicShapeletTransform(n_shapelets=40, lengths=lengths,
                                          random_state=1).fit(X, y)  # fmt: skip
    assert {s.length for s in transform.shapelets_} == set(lengths)
    np.testing.assert_allclose(transform.transform(X[:4]),
                               _brute_features(transform, X[:4, :, None], Euclidean(1)),
                               rtol=1e-12, atol=1e-12)  # fmt: skip


def test_unequal_lengths_and_thresholds_from_the_class():
    rng = np.random.default_rng(1)
    X = [rng.standard_normal(n) for n in (30, 41, 35, 50, 33, 44)]
    y = np.array([0, 1, 0, 1, 0, 1])
    transform = GeodesicShapeletTransform(n_shapelets=30, lengths=(4,), representation="raw",
                                          random_state=2).fit(X, y)  # fmt: skip
    features = transform.transform(X).reshape(6, -1, 3)
    for j, s in enumerate(transform.shapelets_):
        series, start = s.source
        assert y[series] == s.label
        # where it was drawn from, its distance is 0 (not normalised) at its start
        if not s.normalised:
            assert features[series, j, 0] == pytest.approx(0.0, abs=1e-12)
            assert features[series, j, 1] == start
    assert np.all(features[..., 2] >= 0)
    assert transform.get_feature_names_out()[:3].tolist() == [
        "shapelet0_min", "shapelet0_argmin", "shapelet0_count"]  # fmt: skip


@pytest.mark.parametrize("seed", range(4))
def test_thresholds_are_numpys_nan_percentiles_of_the_valid_windows(seed):
    """Rows of distances with NaN past each row's valid windows: the percentiles taken
    rows of one length at once are numpy's nanpercentile, bit for bit (ties, scales,
    every row valid, one valid window)."""
    from sk_rtw.shapelets._shapelet import _row_percentiles

    rng = np.random.default_rng(seed)
    for _ in range(40):
        n, width = int(rng.integers(1, 25)), int(rng.integers(1, 120))
        distances = rng.standard_normal((n, width)) * rng.choice([1e-4, 1.0, 1e6])
        if seed % 2:
            distances = np.round(distances, 1)  # ties
        valid = rng.integers(1, width + 1, size=n) if seed < 2 else np.full(n, width)
        distances[np.arange(width)[None, :] >= valid[:, None]] = np.nan
        percentiles = (5.0, 10.0) if seed < 3 else tuple(np.sort(rng.uniform(0, 100, 2)))
        np.testing.assert_array_equal(
            _row_percentiles(distances, valid, percentiles),
            np.nanpercentile(distances, percentiles, axis=1),
        )


def _rotated_quaternions(Q, seed):
    rng = np.random.default_rng(seed)
    out = []
    for q in Q:
        g = Rotation.random(random_state=rng.integers(1 << 31)).as_quat()[[3, 0, 1, 2]]
        sign = rng.choice([-1.0, 1.0])
        out.append(sign * quaternion_product(g, q))
    return np.stack(out)


def test_normalised_quaternion_shapelets_do_not_see_the_world_frame():
    """Each demonstration in its own world frame (a random rotation and sign per
    series): the normalised features do not change; the raw ones do."""
    Q = np.stack([random_walk(Quaternion(), 25, s, step=0.2) for s in range(6)])
    y = [0, 0, 0, 1, 1, 1]
    normal = GeodesicShapeletTransform("quaternion", n_shapelets=20, normalised_fraction=1.0,
                                       representation="raw", random_state=0).fit(Q, y)  # fmt: skip
    moved = _rotated_quaternions(Q, 3)
    np.testing.assert_allclose(normal.transform(moved), normal.transform(Q), atol=1e-9)
    raw = GeodesicShapeletTransform("quaternion", n_shapelets=20, normalised_fraction=0.0,
                                    representation="raw", random_state=0).fit(Q, y)  # fmt: skip
    assert not np.allclose(raw.transform(moved), raw.transform(Q), atol=1e-3)
    # the body-frame velocity does not see it either
    velocity = GeodesicShapeletTransform("quaternion", n_shapelets=20, random_state=0,
                                         representation="velocity").fit(Q, y)  # fmt: skip
    np.testing.assert_allclose(velocity.transform(moved), velocity.transform(Q), atol=1e-9)


def test_normalised_spd_shapelets_do_not_see_a_congruence():
    S = np.stack([random_walk(SPD(3), 20, s, step=0.3) for s in range(6)])
    y = [0, 0, 0, 1, 1, 1]
    A = np.random.default_rng(4).standard_normal((3, 3))
    rotation = Rotation.random(random_state=5).as_matrix()
    normal = GeodesicShapeletTransform("spd", n_shapelets=20, normalised_fraction=1.0,
                                       representation="raw", random_state=0).fit(S, y)  # fmt: skip
    for moved in (A @ S @ A.T, rotation @ S @ rotation.T):
        np.testing.assert_allclose(normal.transform(moved), normal.transform(S), atol=1e-8)


def test_the_classifier_reads_local_patterns_and_is_deterministic():
    """A bump at a random place marks class 1: the shapelets see it where the whole
    series (1-NN Euclidean) mostly sees noise."""
    from sklearn.neighbors import KNeighborsClassifier

    rng = np.random.default_rng(0)
    X = rng.standard_normal((60, 60))
    where = rng.integers(0, 50, size=60)
    y = np.arange(60) % 2
    for i in np.flatnonzero(y):
        X[i, where[i] : where[i] + 8] += np.hanning(8) * 6
    nearest = KNeighborsClassifier(1).fit(X[:30], y[:30]).score(X[30:], y[30:])
    scores = [GeodesicShapeletClassifier(n_shapelets=200, random_state=seed)
              .fit(X[:30], y[:30]).score(X[30:], y[30:]) for seed in range(3)]  # fmt: skip
    assert np.mean(scores) >= 0.85 and np.mean(scores) > nearest + 0.05
    X, y = X[:40], y[:40]
    clf = GeodesicShapeletClassifier(n_shapelets=200, random_state=0).fit(X[:24], y[:24])
    again = GeodesicShapeletClassifier(n_shapelets=200, random_state=0, n_jobs=2)
    np.testing.assert_array_equal(again.fit(X[:24], y[:24]).decision_function(X[24:]),
                                  clf.decision_function(X[24:]))  # fmt: skip
    proba = clf.predict_proba(X[24:])
    np.testing.assert_array_equal(clf.classes_[proba.argmax(1)], clf.predict(X[24:]))
    grid = GridSearchCV(GeodesicShapeletClassifier(n_shapelets=50, random_state=0),
                        {"normalised_fraction": [0.0, 1.0]}, cv=2).fit(X, y)  # fmt: skip
    assert grid.best_score_ > 0.5
    assert clone(clf).get_params()["n_shapelets"] == 200


def test_bad_input_is_named():
    rng = np.random.default_rng(0)
    X = rng.standard_normal((6, 12))
    y = [0, 1, 0, 1, 0, 1]
    with pytest.raises(ValueError, match="longer than the shortest training series"):
        GeodesicShapeletTransform(lengths=(13,)).fit(X, y)
    with pytest.raises(ValueError, match="velocity one fewer"):
        GeodesicShapeletTransform(lengths=(12,)).fit(X, y)
    fitted = GeodesicShapeletTransform(n_shapelets=10, lengths=(6,), representation="raw",
                                       random_state=0).fit(X, y)  # fmt: skip
    # a series shorter than a shapelet's span reads as padded with its last point: one
    # window, its points clamped to the last sample
    short = X[:, :3]
    got = fitted.transform(short).reshape(len(X), -1, 3)
    for j, s in enumerate(fitted.shapelets_):
        for i, x in enumerate(short):
            window = x[np.minimum(s.dilation * np.arange(s.length), len(x) - 1)]
            if s.normalised:
                window = Euclidean(1).normalise_windows(window[:, None])[:, 0]
            d = np.abs(window - s.points[:, 0]).sum()
            np.testing.assert_allclose(got[i, j], [d, 0, float(d < s.threshold)], atol=1e-12)
    with pytest.raises(ValueError, match="NaN"):
        GeodesicShapeletTransform().fit(np.where(X > 1, np.nan, X), y)
    with pytest.raises(ValueError, match="not a point"):
        GeodesicShapeletTransform("sphere").fit(np.ones((4, 8, 3)))
    for params, name in (({"n_shapelets": 0}, "n_shapelets"), ({"lengths": (0,)}, "lengths"),
                         ({"normalised_fraction": 1.5}, "normalised_fraction"),
                         ({"threshold_percentiles": (10, 5)}, "threshold_percentiles"),
                         ({"representation": "both-ways"}, "representation")):  # fmt: skip
        with pytest.raises((ValueError, TypeError), match=name):
            GeodesicShapeletTransform(**params).fit(X, y)
    with pytest.raises(ValueError, match="2 classes"):
        GeodesicShapeletClassifier(n_shapelets=5).fit(X, [0] * 6)
    # a class of one series: its shapelets' thresholds come from that series itself
    one = GeodesicShapeletTransform(n_shapelets=20, random_state=0).fit(X[:3], [0, 0, 1])
    assert np.isfinite(one.transform(X)).all()


def test_a_sphere_without_normalisation_draws_raw_shapelets_only():
    S = np.stack([random_walk(Sphere(2), 20, s, step=0.3) for s in range(4)])
    transform = GeodesicShapeletTransform("sphere", n_shapelets=20, normalised_fraction=1.0,
                                          representation="raw", random_state=0).fit(S)  # fmt: skip
    assert not any(s.normalised for s in transform.shapelets_)


@pytest.mark.parametrize("representation", ["raw", "velocity"])
@pytest.mark.parametrize("space", ["quaternion", "spd"])
def test_rlasa_demonstrations_in_their_own_frames_classify_the_same(space, representation):
    """R-LASA handwriting (8 shapes, leave demonstration 0 out), every demonstration in
    a world frame of its own (a rotation and sign per quaternion series, a congruence
    by a rotation per SPD series): the normalised shapelets' classifier, and the
    classifier of shapelets from the velocity (body frame, eigenbasis; half of them
    normalised), predict the same classes, and fitted on the moved demonstrations they
    are the same classifiers."""
    demos, shapes, moved = rlasa_in_own_frames(space, every=4)
    X_train = demos[:, 1:].reshape(-1, *demos.shape[2:])
    y_train = np.repeat(shapes, 3)
    fraction = 1.0 if representation == "raw" else 0.5
    clf = GeodesicShapeletClassifier(space, n_shapelets=300, normalised_fraction=fraction,
                                     representation=representation, random_state=0)  # fmt: skip
    clf.fit(X_train, y_train)
    assert clf.score(demos[:, 0], shapes) >= 0.75
    np.testing.assert_array_equal(clf.predict(moved[:, 0]), clf.predict(demos[:, 0]))
    refit = clone(clf).fit(moved[:, 1:].reshape(-1, *demos.shape[2:]), y_train)
    np.testing.assert_allclose(refit.decision_function(moved[:, 0]),
                               clf.decision_function(demos[:, 0]), atol=1e-6)  # fmt: skip
