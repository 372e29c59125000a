"""AutoChoice (the candidates and rule of every "auto" choice) and the fit record."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from sklearn.base import clone
from sklearn.model_selection import GridSearchCV

from sk_rtw import AutoChoice, RTWAverager, RTWNearestCentroid, RTWPrototypeClassifier
from sk_rtw.estimators._choice import DEFAULT_CHOICE, mcnemar
from sk_rtw.estimators._out_of_fold import out_of_fold_distances
from sk_rtw.utils import check_series_collection

from .conftest import quick
from .test_selection import shifted_bumps, two_shapes_per_class


def test_the_default_is_the_measured_grid():
    choice = AutoChoice()
    assert choice.windows == (0.0, 0.05, 0.1, 0.2, None)
    assert choice.centroids == (1, 0.125, 0.25, 0.5, 1.0)
    assert choice.prior == (None, 0.25) and choice.z_threshold == 1.0
    assert choice.representations == ("raw", "velocity")
    assert repr(choice.checked()) == "AutoChoice()"


def test_the_docstring_grid_is_rendered_from_the_default():
    text = " ".join(RTWNearestCentroid.__doc__.split())
    assert " ".join(DEFAULT_CHOICE.describe().split()) in text
    assert "0, 0.05, 0.1, 0.2 or none" in text and "1/8 of the class" in text
    assert "%(choice)s" not in RTWNearestCentroid.__doc__


@pytest.mark.parametrize(
    ("values", "match"),
    [
        ({"windows": (0.1, 2.0)}, "windows"),
        ({"windows": "auto"}, "windows"),
        ({"centroids": ()}, "centroids"),
        ({"centroids": (0,)}, "centroids"),
        ({"centroids": (True,)}, "centroids"),
        ({"prior": (None,)}, "prior"),
        ({"prior": (None, 1.5)}, "prior"),
        ({"z_threshold": float("nan")}, "z_threshold"),
        ({"representations": ("raw", "raw")}, "representations"),
        ({"representations": ("raw", "speed")}, "representations"),
    ],
)
def test_bad_values_are_named_before_any_work(values, match):
    X, y = shifted_bumps()
    with pytest.raises(ValueError, match=match):
        RTWNearestCentroid(method="dba", choice=AutoChoice(**values)).fit(X, y)
    with pytest.raises(TypeError, match="choice"):
        RTWNearestCentroid(method="dba", choice={"windows": (0.1,)}).fit(X, y)


def test_a_grid_of_ones_own_is_the_one_scored():
    X, y = shifted_bumps()
    choice = AutoChoice(windows=(0.1, None), centroids=(1, 1.0), prior=(0.1, 1))
    clf = RTWNearestCentroid(method="dba", choice=choice).fit(X, y)
    scored = [(c["dtw_window"], c["n_centroids"]) for c in clf.selection_["candidates"]]
    assert scored == [(0.1, 1), (0.1, 1.0), (None, 1), (None, 1.0)]
    assert clf.selection_["prior"] == {"dtw_window": 0.1, "n_centroids": 1}
    assert (clf.dtw_window_, clf.n_centroids_) in scored


def test_the_threshold_decides_against_the_prior():
    """With an infinite threshold the prior is kept; with -inf the best candidate wins."""
    X, y = shifted_bumps()
    keep = RTWNearestCentroid(method="dba", choice=AutoChoice(z_threshold=np.inf)).fit(X, y)
    assert (keep.dtw_window_, keep.n_centroids_) == AutoChoice().prior
    leave = RTWNearestCentroid(method="dba", choice=AutoChoice(z_threshold=-np.inf)).fit(X, y)
    best = max(c["z"] for c in leave.selection_["candidates"])
    chosen = [c for c in leave.selection_["candidates"]
              if (c["dtw_window"], c["n_centroids"]) == (leave.dtw_window_, leave.n_centroids_)]
    assert chosen[0]["z"] == pytest.approx(best)


def test_the_representation_choice_asks_the_same_object():
    X, y = shifted_bumps()
    only_raw = AutoChoice(representations=("raw",))
    clf = RTWNearestCentroid(method="dba", representation="auto", choice=only_raw).fit(X, y)
    assert clf.representation_ == "raw"
    assert clf.selection_["representation"]["chosen"] == "raw"
    first = AutoChoice(representations=("velocity", "raw"), z_threshold=np.inf)
    clf = RTWNearestCentroid(method="dba", representation="auto", choice=first).fit(X, y)
    assert clf.representation_ == "velocity"  # the first is the prior


def test_the_prototype_decision_asks_the_threshold():
    X, y = two_shapes_per_class()
    common = {"method": quick("dba"), "n_centroids": 2, "dtw_window": 0.1, "cv": 3,
              "random_state": 0}  # fmt: skip
    never = RTWPrototypeClassifier(**common, choice=AutoChoice(z_threshold=np.inf)).fit(X, y)
    always = RTWPrototypeClassifier(**common, choice=AutoChoice(z_threshold=-np.inf)).fit(X, y)
    assert never.decision_ == "nearest" and always.decision_ == "readout"
    assert never.cv_accuracy_ == always.cv_accuracy_  # the same scores, another rule


def test_the_choice_is_a_searchable_parameter():
    X, y = shifted_bumps()
    clf = RTWNearestCentroid(method="dba", choice=AutoChoice())
    assert "choice__z_threshold" in clf.get_params()
    search = GridSearchCV(clf, {"choice__z_threshold": [1.0, np.inf]}, cv=2).fit(X, y)
    assert search.best_params_["choice__z_threshold"] in (1.0, np.inf)
    choices = {"choice": [None, AutoChoice(windows=(0.1,))]}
    grid = GridSearchCV(RTWNearestCentroid(method="dba"), choices, cv=2).fit(X, y)
    assert "choice" in grid.best_params_
    twin = clone(clf)
    assert twin.choice is not clf.choice and repr(twin.choice) == repr(clf.choice)


def test_mcnemar_counts_the_discordant_pairs():
    candidate = np.array([1, 1, 1, 0, 1], bool)
    prior = np.array([0, 0, 1, 1, 1], bool)
    assert mcnemar(candidate, prior) == pytest.approx((2 - 1) / np.sqrt(3))
    assert mcnemar(prior, prior) == 0.0


def test_the_fit_record_is_frozen_and_describes_the_fit():
    X, y = two_shapes_per_class()
    clf = RTWNearestCentroid(method=quick("dba"), n_centroids=2, dtw_window=0.1,
                             random_state=3).fit(X, y)  # fmt: skip
    record = clf._fit_record
    with pytest.raises(dataclasses.FrozenInstanceError):
        record.dtw_window = None
    with pytest.raises(ValueError, match="read-only"):
        record.groups[0] = 1
    np.testing.assert_array_equal(record.groups, clf.assignments_)
    np.testing.assert_array_equal(record.owners, clf.centroid_classes_)
    assert (record.dtw_window, record.n_centroids) == (clf.dtw_window_, clf.n_centroids_)
    expected = np.random.RandomState(3).randint(2**31 - 1, size=len(record.owners))
    assert record.seeds == tuple(int(s) for s in expected)
    assert record.selection is None and record.representation == "raw"


def test_a_refit_of_every_centroid_on_all_its_series_is_the_fit():
    """record.refit on every series gives the fitted centroids back (same seeds,
    configuration and band), whatever random_state was."""
    X, y = two_shapes_per_class()
    for random_state in (0, np.random.RandomState(1), None):
        clf = RTWNearestCentroid(method=quick("rtw"), n_centroids=2, dtw_window=0.1,
                                 random_state=random_state).fit(X, y)  # fmt: skip
        record = clf._fit_record
        collection = check_series_collection(X)
        refits = record.refit(collection, np.arange(len(y)), np.arange(len(record.owners)))
        for fit, mean in zip(refits, clf.means_, strict=True):
            np.testing.assert_array_equal(fit.mean, mean)


def test_out_of_fold_distances_need_no_integer_seed():
    """The refits read the record, so a RandomState-seeded fit gives the same out-of-fold
    distances as a twin with the same stream."""
    X, y = two_shapes_per_class()
    fits = [RTWNearestCentroid(method=quick("rtw"), n_centroids=2, dtw_window=0.1,
                               random_state=np.random.RandomState(7)).fit(X, y)
            for _ in range(2)]  # fmt: skip
    collection = check_series_collection(X)
    a, b = (out_of_fold_distances(f._fit_record, list(f.means_), collection, 3, random_state=0)
            for f in fits)  # fmt: skip
    np.testing.assert_array_equal(a, b)


def test_an_averager_with_y_none_records_one_class():
    X, _ = two_shapes_per_class()
    averager = RTWAverager(method=quick("dba")).fit(X)
    assert averager._fit_record.kind == "class" and len(averager._fit_record.owners) == 1


STREAMS = {"Generator": lambda: np.random.default_rng(5),
           "RandomState": lambda: np.random.RandomState(5)}  # fmt: skip


@pytest.mark.parametrize("make", STREAMS.values(), ids=STREAMS.keys())
def test_any_declared_random_state_type_fits_reproducibly(make):
    """A Generator (declared, and once refused by scikit-learn's check_random_state) or
    a RandomState: the fit runs and twin streams give the same fit."""
    X, y = two_shapes_per_class()
    common = {"method": quick("dba"), "n_centroids": 2, "dtw_window": 0.1}
    a, b = (RTWPrototypeClassifier(**common, cv=3, random_state=make()).fit(X, y)
            for _ in range(2))  # fmt: skip
    np.testing.assert_array_equal(a.oof_distances_, b.oof_distances_)
    c, d = (RTWNearestCentroid(**common, random_state=make()).fit(X, y) for _ in range(2))
    assert c._fit_record.seeds == d._fit_record.seeds
