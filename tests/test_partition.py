"""Every class split into its centroids' parts: chunks, shares, the choice's pairs reused."""

from __future__ import annotations

import numpy as np

from sk_rtw import AutoChoice, dtw_pairwise_distance
from sk_rtw.estimators import _partition, _selection
from sk_rtw.utils import check_series_collection

from .test_selection import two_shapes_per_class


def test_large_classes_are_split_in_chunks(monkeypatch):
    monkeypatch.setattr(_partition, "PART_SERIES", 7)
    rng = np.random.default_rng(2)
    X = rng.standard_normal((30, 15)).cumsum(1)
    codes = np.repeat([0, 1], [20, 10])
    groups, owners = _partition.partition(check_series_collection(X), codes, 0.25, 0.1,
                                          random_state=0)  # fmt: skip
    np.testing.assert_array_equal(np.bincount(owners), [5, 3])
    np.testing.assert_array_equal(owners[groups], codes)  # every series in its class
    assert np.all(np.bincount(groups) >= 1)
    np.testing.assert_array_equal(_partition._apportion(5, np.array([7, 7, 6])), [2, 2, 1])
    np.testing.assert_array_equal(_partition._apportion(3, np.array([4, 3, 3])), [1, 1, 1])


def test_a_sampled_class_is_split_on_its_completed_matrix(monkeypatch):
    """The pairs the choice computed are reused: the completed matrix equals the class's
    whole DTW matrix, so the parts are those of a fresh k-medoids."""
    monkeypatch.setattr(_selection, "MAX_SERIES", 14)
    X, y = two_shapes_per_class(n=20)
    collection = check_series_collection(X)
    selection = _selection.choose(collection, y, 0.1, 0.25, AutoChoice(), random_state=0)
    assert selection.report["sampled"]
    for c in (0, 1):
        members = np.flatnonzero(y == c)
        seen = np.flatnonzero(np.isin(members, selection.sample))
        completed = _partition._complete(collection, members, (seen, selection.matrices[c]),
                                         0.1, None)  # fmt: skip
        whole = dtw_pairwise_distance(X[members], window=0.1)
        np.testing.assert_allclose(completed, whole, rtol=1e-12)
    groups, owners = _partition.partition(collection, y, 0.25, 0.1, selection=selection)
    np.testing.assert_array_equal(np.bincount(owners), [5, 3])
    np.testing.assert_array_equal(owners[groups], y)
