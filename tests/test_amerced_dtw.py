"""Amerced DTW (a penalty on every step off the diagonal) against aeon and a plain-Python
reference, on every manifold, in the distance, the pairwise matrix and the nearest
search."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from aeon.distances import adtw_distance as aeon_adtw_distance
from aeon.distances import adtw_pairwise_distance as aeon_adtw_pairwise

from sk_rtw.dtw import dtw_distance, dtw_nearest_distance, dtw_pairwise_distance
from sk_rtw.manifolds import SPD, Product, Sphere

from .conftest import MANIFOLDS
from .test_dtw import random_walk


def reference_adtw(x, y, manifold, penalty, squared=False):
    """Textbook amerced DTW with Python loops and the manifold's own distance."""
    nx, ny = len(x), len(y)
    D = np.full((nx + 1, ny + 1), np.inf)
    D[0, 0] = 0.0
    for i in range(nx):
        for j in range(ny):
            c = float(manifold.dist(x[i], y[j]))
            c = c * c if squared else c
            D[i + 1, j + 1] = c + min(D[i, j], D[i, j + 1] + penalty, D[i + 1, j] + penalty)
    return D[nx, ny]


@pytest.mark.parametrize("penalty", [0.0, 0.05, 1.0, 25.0])
@pytest.mark.parametrize("window", [None, 0.1, 0.3])
@pytest.mark.parametrize(("nx", "ny"), [(30, 30), (25, 41)])
def test_matches_aeon_on_euclidean_data(nx, ny, window, penalty, rng):
    x, y = rng.standard_normal(nx), rng.standard_normal(ny)
    expected = aeon_adtw_distance(x, y, window=window, warp_penalty=penalty)
    got = dtw_distance(x, y, squared=True, window=window, warp_penalty=penalty)
    assert got == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("manifold", MANIFOLDS, ids=repr)
def test_matches_the_python_reference_on_manifolds(manifold):
    x, y = random_walk(manifold, 9, 1), random_walk(manifold, 12, 2)
    for penalty, squared in ((0.3, False), (0.05, True)):
        expected = reference_adtw(x, y, manifold, penalty, squared)
        got = dtw_distance(x, y, manifold, squared=squared, warp_penalty=penalty)
        assert got == pytest.approx(expected, rel=1e-9)


def test_no_penalty_is_dtw_bit_for_bit(rng):
    X = np.cumsum(rng.standard_normal((6, 50)), axis=1)
    plain = dtw_pairwise_distance(X, window=0.2)
    assert np.array_equal(dtw_pairwise_distance(X, window=0.2, warp_penalty=0.0), plain)
    assert dtw_distance(X[0], X[1], warp_penalty=0.0) == dtw_distance(X[0], X[1])


def test_the_penalty_moves_the_distance_from_dtw_to_the_direct_alignment(rng):
    """Non-decreasing in the penalty, from DTW (0) to the diagonal path's cost (a penalty
    above that cost: no step off the diagonal can pay)."""
    x, y = rng.standard_normal(40), rng.standard_normal(40)
    direct = float(np.abs(x - y).sum())
    values = [dtw_distance(x, y, warp_penalty=w) for w in (0.0, 0.01, 0.1, 1.0, 10.0)]
    assert values[0] == dtw_distance(x, y)
    assert all(a <= b for a, b in itertools.pairwise(values))
    assert dtw_distance(x, y, warp_penalty=2 * direct) == pytest.approx(direct, rel=1e-12)


def test_pairwise_matches_aeon_with_unequal_lengths(rng):
    X = [rng.standard_normal(n) for n in (20, 31, 25)]
    Y = [rng.standard_normal(n) for n in (22, 18)]
    got = dtw_pairwise_distance(X, Y, squared=True, warp_penalty=0.7)
    expected = aeon_adtw_pairwise([x[None] for x in X], [y[None] for y in Y], warp_penalty=0.7)
    np.testing.assert_allclose(got, expected, rtol=1e-12)


@pytest.mark.parametrize(
    "manifold", [Sphere(2), SPD(2), Product((Sphere(2), SPD(13)))], ids=repr
)
def test_nearest_search_equals_the_exhaustive_minimum(manifold):
    """The bounds and early abandoning give the exhaustive answer (a product with an SPD
    block too large for the kernels takes the exhaustive route itself)."""
    X = np.stack([random_walk(manifold, 14, s) for s in range(4)])
    Y = np.stack([random_walk(manifold, 14, s) for s in range(10, 16)])
    groups = np.array([0, 1, 1, 2, 0, 2])
    for window, penalty in ((None, 0.4), (0.2, 1.5)):
        full = dtw_pairwise_distance(X, Y, manifold, window=window, warp_penalty=penalty)
        expected = np.stack([full[:, groups == g].min(1) for g in range(3)], axis=1)
        got = dtw_nearest_distance(X, Y, groups, manifold, window=window,
                                   warp_penalty=penalty)  # fmt: skip
        np.testing.assert_allclose(got, expected, rtol=1e-12)
        nearest = dtw_nearest_distance(X, Y, groups, manifold, window=window,
                                       warp_penalty=penalty, nearest_only=True)  # fmt: skip
        assert np.array_equal(nearest.argmin(1), expected.argmin(1))


@pytest.mark.parametrize("bad", [-0.1, np.nan, np.inf, "1"])
def test_bad_penalties_are_refused_by_name(bad):
    with pytest.raises((ValueError, TypeError), match="warp_penalty"):
        dtw_distance(np.zeros(5), np.ones(5), warp_penalty=bad)
    with pytest.raises((ValueError, TypeError), match="warp_penalty"):
        dtw_nearest_distance(np.zeros((2, 5)), np.ones((3, 5)), warp_penalty=bad)


def test_path_normalisation_is_refused_with_a_penalty():
    with pytest.raises(ValueError, match="amerced"):
        dtw_distance(np.zeros(5), np.ones(5), normalize="path", warp_penalty=1.0)
    assert dtw_distance(np.zeros(5), np.ones(5), normalize="path", warp_penalty=0.0) == 1.0


@pytest.mark.parametrize("penalty", [0.05, 0.5, 3.0])
def test_the_search_narrows_amerced_dtw_to_its_bound_without_changing_the_answer(penalty, rng):
    """Equal lengths and no band: a path d columns off the diagonal costs at least
    2 d penalty, so the search computes the band that the best distance so far allows;
    the distances (and the nearest group) are the exhaustive ones."""
    X = np.cumsum(rng.standard_normal((12, 60)), axis=1)
    Y = np.cumsum(rng.standard_normal((25, 60)), axis=1)
    groups = np.arange(25) % 5
    full = dtw_pairwise_distance(X, Y, warp_penalty=penalty)
    expected = np.stack([full[:, groups == g].min(1) for g in range(5)], axis=1)
    got = dtw_nearest_distance(X, Y, groups, warp_penalty=penalty)
    np.testing.assert_allclose(got, expected, rtol=1e-12)
    nearest = dtw_nearest_distance(X, Y, groups, warp_penalty=penalty, nearest_only=True)
    assert np.array_equal(nearest.argmin(1), expected.argmin(1))
