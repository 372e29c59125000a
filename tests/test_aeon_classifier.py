"""sk_rtw.aeon.RTWClassifier: aeon's estimator checks, and the same results as
RTWNearestCentroid on aeon's layouts."""

from __future__ import annotations

import inspect
import subprocess
import sys

import numpy as np
import pytest

pytest.importorskip("aeon")

from aeon.testing.estimator_checking import parametrize_with_checks
from aeon.testing.estimator_checking._yield_multithreading_checks import (
    check_estimator_multithreading,
)
from aeon.testing.testing_data import FULL_TEST_DATA_DICT

from benchmarks.ucr._data import available_datasets, load_split
from sk_rtw import DBA, RTW, GeodesicShapeletClassifier, RTWNearestCentroid, RTWProximityForest
from sk_rtw.aeon import GeodesicShapeletClassifier as AeonShapelets
from sk_rtw.aeon import RTWClassifier, RTWProximityForestClassifier
from sk_rtw.manifolds import Quaternion
from sk_rtw.utils import from_aeon, to_aeon

from .conftest import UCR_DIR
from .test_dtw import random_walk


@parametrize_with_checks([RTWClassifier])
def test_aeon_estimator_checks(check):
    check()


@pytest.mark.parametrize("datatype", ["EqualLengthMultivariate-Classification-numpy3D",
                                      "UnequalLengthUnivariate-Classification-np-list"])
def test_aeon_multithreading_check(datatype):
    # aeon runs this check only with its MULTITHREAD_TESTING switch on; it applies here
    assert datatype in FULL_TEST_DATA_DICT
    estimator = RTWClassifier(method=RTW(n_epochs=2), random_state=0)
    check_estimator_multithreading(estimator, datatype)


def test_signature_is_the_nearest_centroid_classifiers():
    ours = inspect.signature(RTWClassifier).parameters
    theirs = inspect.signature(RTWNearestCentroid).parameters
    assert list(ours) == list(theirs)
    differing = {n for n in ours if ours[n].default != theirs[n].default}
    assert differing == {"n_jobs"}  # aeon's convention: 1, which is what None means
    assert ours["n_jobs"].default == 1 and theirs["n_jobs"].default is None


def test_importing_sk_rtw_aeon_does_not_change_sk_rtw():
    code = "import sys, sk_rtw; print('aeon' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.stdout.strip() == "False", out.stderr


def _walks(rng, n, channels, lengths):
    return [rng.standard_normal((channels, t)).cumsum(1) for t in lengths[:n]]


@pytest.mark.parametrize("equal", [True, False])
@pytest.mark.parametrize("channels", [1, 3])
def test_same_predictions_and_probabilities_as_the_nearest_centroid(channels, equal):
    rng = np.random.default_rng(3)
    lengths = [40] * 24 if equal else list(rng.integers(30, 50, 24))
    X = _walks(rng, 24, channels, lengths)
    X = [x + (i % 2) * np.linspace(0, 4, x.shape[1]) for i, x in enumerate(X)]
    y = np.array(["up" if i % 2 else "flat" for i in range(24)])
    if equal:
        X = np.stack(X)
    train, test = slice(0, 16), slice(16, 24)
    X_train, X_test = X[train], X[test]
    params = {"method": RTW(n_epochs=4), "random_state": 0}
    aeon_clf = RTWClassifier(**params).fit(X_train, y[train])
    plain = RTWNearestCentroid(**params).fit(from_aeon(X_train), y[train])
    np.testing.assert_array_equal(aeon_clf.predict(X_test), plain.predict(from_aeon(X_test)))
    np.testing.assert_allclose(
        aeon_clf.predict_proba(X_test), plain.predict_proba(from_aeon(X_test)), rtol=1e-12
    )
    assert aeon_clf.estimator_.dtw_window_ == plain.dtw_window_
    assert aeon_clf.estimator_.n_centroids_ == plain.n_centroids_


def test_short_multichannel_cases_are_read_in_aeon_layout():
    # 5 time points of 8 channels: by name, sk_rtw's layout check would refuse the
    # time-major array (it looks channels-first); the adapter knows the layout
    rng = np.random.default_rng(0)
    X = rng.standard_normal((12, 8, 5))
    y = np.repeat([0, 1], 6)
    X[y == 1] += 2.0
    clf = RTWClassifier(method=DBA(), n_centroids=1, dtw_window=None).fit(X, y)
    assert clf.estimator_.manifold_.point_shape == (8,)
    np.testing.assert_array_equal(clf.predict(X), y)


def test_spd_channels_are_matrix_entries_row_by_row():
    rng = np.random.default_rng(1)
    A = rng.standard_normal((10, 30, 2, 2))
    spd = A @ np.swapaxes(A, -1, -2) + 0.5 * np.eye(2)
    spd[5:] *= 3.0
    y = np.repeat(["small", "large"], 5)
    X_aeon = np.swapaxes(spd.reshape(10, 30, 4), 1, 2)  # (n, 4 channels, T)
    params = {"manifold": "spd", "method": DBA(), "n_centroids": 1, "dtw_window": None}
    ours = RTWClassifier(**params).fit(X_aeon, y)
    plain = RTWNearestCentroid(**params).fit(spd, y)
    np.testing.assert_array_equal(ours.predict(X_aeon), plain.predict(spd))
    np.testing.assert_allclose(ours.predict_proba(X_aeon), plain.predict_proba(spd))
    with pytest.raises(ValueError, match="square number of channels, got 3"):
        RTWClassifier(**params).fit(X_aeon[:, :3], y)


def test_nan_is_refused_by_aeon_with_its_message():
    X = np.random.default_rng(0).standard_normal((6, 1, 20))
    X[0, 0, 3] = np.nan
    with pytest.raises(ValueError, match=r"[Mm]issing"):
        RTWClassifier().fit(X, [0, 1] * 3)


@pytest.mark.slow
@pytest.mark.skipif(not UCR_DIR.is_dir(), reason="needs the UCR development archive")
def test_same_predictions_on_the_development_archive():
    """Every dataset of the archive in aeon's layout (a list for unequal lengths)."""
    names = [n for n in available_datasets(str(UCR_DIR)) if (UCR_DIR / n).is_dir()]
    assert len(names) >= 30
    params = {"method": RTW(n_epochs=8), "random_state": 0}
    for name in names:
        train = load_split(name, "train", str(UCR_DIR))  # NaNs filled, as the benchmark
        test = load_split(name, "test", str(UCR_DIR))
        ours = RTWClassifier(**params).fit(to_aeon(train.X), train.y).predict(to_aeon(test.X))
        plain = RTWNearestCentroid(**params).fit(train.X, train.y).predict(test.X)
        np.testing.assert_array_equal(ours, plain, err_msg=name)


# ------------------------------------------------------------- the forest
@parametrize_with_checks([RTWProximityForestClassifier])
def test_aeon_estimator_checks_of_the_forest(check):
    check()


def test_forest_signature_is_the_forests():
    ours = inspect.signature(RTWProximityForestClassifier).parameters
    theirs = inspect.signature(RTWProximityForest).parameters
    assert list(ours) == list(theirs)
    differing = {n for n in ours if ours[n].default != theirs[n].default}
    assert differing == {"n_jobs"}


@pytest.mark.parametrize("equal", [True, False])
@pytest.mark.parametrize("channels", [1, 3])
def test_same_predictions_and_probabilities_as_the_forest(channels, equal):
    rng = np.random.default_rng(4)
    lengths = [30] * 20 if equal else list(rng.integers(25, 40, 20))
    X = _walks(rng, 20, channels, lengths)
    X = [x + (i % 2) * np.linspace(0, 4, x.shape[1]) for i, x in enumerate(X)]
    y = np.array(["up" if i % 2 else "flat" for i in range(20)])
    if equal:
        X = np.stack(X)
    params = {"n_trees": 6, "random_state": 0}
    aeon_clf = RTWProximityForestClassifier(**params).fit(X[:14], y[:14])
    plain = RTWProximityForest(**params).fit(from_aeon(X[:14]), y[:14])
    np.testing.assert_array_equal(
        aeon_clf.predict_proba(X[14:]), plain.predict_proba(from_aeon(X[14:]))
    )
    np.testing.assert_array_equal(aeon_clf.predict(X[14:]), plain.predict(from_aeon(X[14:])))


def test_forest_on_quaternion_channels():
    walks = [random_walk(Quaternion(), 20, s, step=0.1 * (1 + s % 2)) for s in range(12)]
    X = np.stack([w.T for w in walks])  # (n, 4 channels, T)
    y = np.arange(12) % 2
    forest = RTWProximityForestClassifier("quaternion", n_trees=5, random_state=0).fit(X, y)
    assert forest.estimator_.manifold_ == Quaternion()
    assert forest.predict(X).shape == (12,)


# ------------------------------------------------------------- the shapelets
@parametrize_with_checks([AeonShapelets])
def test_aeon_estimator_checks_of_the_shapelets(check):
    check()


def test_shapelet_signature_is_the_classifiers():
    ours = inspect.signature(AeonShapelets).parameters
    theirs = inspect.signature(GeodesicShapeletClassifier).parameters
    assert list(ours) == list(theirs)
    assert {n for n in ours if ours[n].default != theirs[n].default} == {"n_jobs"}


@pytest.mark.parametrize("channels", [1, 3])
def test_same_predictions_as_the_shapelet_classifier(channels):
    rng = np.random.default_rng(4)
    X = np.stack(_walks(rng, 20, channels, [30] * 20))
    X = X + (np.arange(20) % 2)[:, None, None] * np.linspace(0, 4, 30)
    y = np.array(["up" if i % 2 else "flat" for i in range(20)])
    params = {"n_shapelets": 40, "random_state": 0}
    ours = AeonShapelets(**params).fit(X[:14], y[:14])
    plain = GeodesicShapeletClassifier(**params).fit(from_aeon(X[:14]), y[:14])
    np.testing.assert_array_equal(ours.predict(X[14:]), plain.predict(from_aeon(X[14:])))
