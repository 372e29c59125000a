"""Every accepted input form, and every rejected one with its message."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from sk_rtw.manifolds import SPD, Euclidean, Quaternion, Sphere
from sk_rtw.utils import check_series, check_series_collection


def test_univariate_2d_becomes_3d(rng):
    c = check_series_collection(rng.standard_normal((4, 12)))
    assert c.data.shape == (4, 12, 1) and c.manifold == Euclidean(1) and c.equal_length


def test_multivariate_and_manifold_names(rng):
    assert check_series_collection(rng.standard_normal((3, 10, 5))).manifold == Euclidean(5)
    q = Quaternion().random_point((3, 10), 0)
    assert check_series_collection(q, "quaternion").manifold == Quaternion()
    s = SPD(3).random_point((2, 6), 1)
    assert check_series_collection(s, "spd").manifold == SPD(3)
    c = check_series_collection(torch.from_numpy(Sphere(1).random_point((2, 5), 2)), "sphere")
    assert c.manifold == Sphere(1) and isinstance(c.data, np.ndarray)


def test_unequal_lengths_are_padded_with_the_last_sample(rng):
    series = [rng.standard_normal((n, 2)) for n in (5, 9, 7)]
    c = check_series_collection(series)
    assert c.data.shape == (3, 9, 2) and list(c.lengths) == [5, 9, 7] and not c.equal_length
    np.testing.assert_array_equal(c.data[0, 5:], np.repeat(series[0][-1:], 4, 0))
    for i, s in enumerate(series):
        np.testing.assert_array_equal(c.series(i), s)
    c1 = check_series_collection([rng.standard_normal(n) for n in (4, 6)])
    assert c1.data.shape == (2, 6, 1)


@pytest.mark.parametrize(
    ("X", "manifold", "error", "match"),
    [
        (np.zeros((0, 5)), "euclidean", ValueError, "0 sample"),
        ([], "euclidean", ValueError, "empty"),
        (np.zeros(5), "euclidean", ValueError, "Reshape your data"),
        (np.zeros((2, 3, 4, 5)), "euclidean", ValueError, "Euclidean data must be"),
        (np.zeros((2, 1)), "euclidean", ValueError, "1 feature"),
        ([np.zeros(1), np.zeros(3)], "euclidean", ValueError, "at least 2 are needed"),
        (np.array([[0.0, np.inf, 1.0]]), "euclidean", ValueError, "time index 1"),
        (np.ones((2, 4, 3)), "sphere", ValueError, r"X\[0, 0\].*norm"),
        (np.ones((2, 4, 3)), Quaternion(), ValueError, "expected"),
        (np.array([["a", "b"]]), "euclidean", ValueError, "numeric"),
        ([np.zeros((3, 2)), np.zeros((4, 3))], "euclidean", ValueError, r"X\[1\]"),
    ],
)
def test_bad_collections(X, manifold, error, match):
    with pytest.raises(error, match=match):
        check_series_collection(X, manifold)


def test_off_manifold_point_in_unequal_length_list_is_located():
    good = SPD(2).random_point(5, 0)
    bad = SPD(2).random_point(7, 1)
    bad[4] = [[1.0, 3.0], [3.0, 1.0]]
    with pytest.raises(ValueError, match=r"X\[1, 4\].*positive definite"):
        check_series_collection([good, bad], "spd")


def test_min_series():
    with pytest.raises(ValueError, match="minimum of 2"):
        check_series_collection(np.zeros((1, 5)), min_series=2)


def test_single_series_forms(rng):
    x, m = check_series(rng.standard_normal(7))
    assert x.shape == (7, 1) and m == Euclidean(1)
    x, m = check_series(Sphere(2).random_point(6, 0), "sphere")
    assert x.shape == (6, 3) and m == Sphere(2)
    with pytest.raises(ValueError, match="scalar"):
        check_series(3.0)
    with pytest.raises(ValueError, match=r"x\[2\].*NaN"):
        check_series(np.array([0.0, 1.0, np.nan]))
