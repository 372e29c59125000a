"""Nearest references by DTW: envelopes, LB_Keogh, and the pruned search against the
exhaustive one."""

from __future__ import annotations

import numpy as np
import pytest

from sk_rtw import dtw_nearest_distance, dtw_pairwise_distance
from sk_rtw.dtw import _kernels, _point_costs, _search
from sk_rtw.manifolds import SPD, Euclidean, Product, Quaternion, Sphere
from sk_rtw.utils import check_series_collection

from .test_dtw import random_walk

#: Every kind of compiled point distance: univariate, multivariate, sphere, quaternion
#: (sign-invariant) and a product of them.
KERNEL_MANIFOLDS = [
    Euclidean(1),
    Euclidean(3),
    Sphere(2),
    Quaternion(),
    Product((Euclidean(3), Quaternion())),
]
WINDOWS = [0.0, 0.05, 0.2, None]


def walks(manifold, lengths, seed):
    return [random_walk(manifold, int(t), seed + i) for i, t in enumerate(lengths)]


def flat(series):
    return np.ascontiguousarray(np.asarray(series, dtype=float).reshape(len(series), -1))


@pytest.mark.parametrize("window", [0.0, 0.1, 0.3, None])
@pytest.mark.parametrize(("nx", "ny"), [(20, 20), (13, 31), (31, 13), (1, 7), (7, 1)])
def test_the_envelope_spans_the_band_of_every_column(nx, ny, window, rng):
    x = rng.standard_normal((nx, 2))
    w = -1.0 if window is None else window
    lower, upper = np.empty((ny, 2)), np.empty((ny, 2))
    _search.query_envelope(x, ny, w, lower, upper)
    lo, hi = _kernels.sakoe_chiba_rows(nx, ny, w)
    for j in range(ny):
        rows = [i for i in range(nx) if lo[i] <= j < hi[i]]
        np.testing.assert_array_equal(lower[j], x[rows].min(0))
        np.testing.assert_array_equal(upper[j], x[rows].max(0))


@pytest.mark.parametrize("squared", [False, True])
@pytest.mark.parametrize("manifold", KERNEL_MANIFOLDS, ids=repr)
def test_lb_keogh_bounds_dtw_from_below(manifold, squared):
    segments = _point_costs.segment_codes(manifold)
    tight = 0
    for seed, window in enumerate([0.0, 0.05, 0.2, None] * 5):
        x, y = walks(manifold, (25, 18 + seed % 15), 100 * seed)
        w = -1.0 if window is None else window
        fx, fy = flat(x), flat(y)
        lower, upper = np.empty((len(y), fx.shape[1])), np.empty((len(y), fx.shape[1]))
        _search.query_envelope(fx, len(y), w, lower, upper)
        bound = _search.lb_keogh(fy, lower, upper, segments, squared)
        exact = dtw_pairwise_distance([x], [y], manifold, window=window, squared=squared)[0, 0]
        assert 0.0 <= bound <= exact * (1 + 1e-12)
        tight += bound > 0.2 * exact
    assert tight >= 5  # the bound is not trivially zero


def test_lb_keogh_of_a_series_against_itself_is_zero_and_exact_without_warping(rng):
    x = rng.standard_normal((30, 1))
    y = rng.standard_normal((30, 1))
    segments = _point_costs.segment_codes(Euclidean(1))
    lower, upper = np.empty((30, 1)), np.empty((30, 1))
    _search.query_envelope(x, 30, 0.0, lower, upper)
    assert _search.lb_keogh(x, lower, upper, segments, False) == 0.0
    diagonal = np.abs(x - y).sum()  # band 0: DTW is the sum along the diagonal
    assert _search.lb_keogh(y, lower, upper, segments, False) == pytest.approx(diagonal)


def exhaustive(X, Y, groups, manifold, window, squared=False, exclude=None, skip_group=None,
               limit=None, nearest_only=False):  # fmt: skip
    """dtw_nearest_distance from every pair: the plain reduction it must equal."""
    distances = dtw_pairwise_distance(X, Y, manifold, window=window, squared=squared)
    if exclude is not None:
        rows = np.flatnonzero(exclude >= 0)
        distances[rows, exclude[rows]] = np.inf
    if skip_group is not None:
        distances[skip_group[:, None] == groups[None, :]] = np.inf
    if limit is not None:
        distances[distances > np.reshape(limit, (-1, 1))] = np.inf
    out = np.full((len(distances), groups.max() + 1), np.inf)
    for g in range(groups.max() + 1):
        if np.any(groups == g):
            out[:, g] = distances[:, groups == g].min(1)
    if nearest_only:
        out[out > out.min(1, keepdims=True)] = np.inf
    return out


@pytest.mark.parametrize("window", WINDOWS)
@pytest.mark.parametrize("manifold", KERNEL_MANIFOLDS, ids=repr)
def test_the_search_gives_the_exhaustive_distances_bit_for_bit(manifold, window, rng):
    X = walks(manifold, rng.integers(15, 40, 12), 1)
    Y = walks(manifold, rng.integers(15, 40, 30), 500)
    groups = rng.integers(0, 4, 30)
    got = dtw_nearest_distance(X, Y, groups, manifold, window=window)
    np.testing.assert_array_equal(got, exhaustive(X, Y, groups, manifold, window))
    squared = dtw_nearest_distance(X, Y, groups, manifold, window=window, squared=True)
    np.testing.assert_array_equal(squared, exhaustive(X, Y, groups, manifold, window, True))


@pytest.mark.parametrize("window", [0.0, 0.1, None])
def test_the_nearest_group_alone_and_a_distance_cap(window, rng):
    X = walks(Euclidean(2), rng.integers(20, 40, 15), 7)
    Y = walks(Euclidean(2), rng.integers(20, 40, 40), 900)
    groups = rng.integers(0, 5, 40)
    got = dtw_nearest_distance(X, Y, groups, window=window, nearest_only=True)
    expected = exhaustive(X, Y, groups, Euclidean(2), window, nearest_only=True)
    np.testing.assert_array_equal(got, expected)
    full = exhaustive(X, Y, groups, Euclidean(2), window)
    np.testing.assert_array_equal(got.argmin(1), full.argmin(1))
    limit = np.quantile(full, 0.3, axis=1)
    for nearest_only in (False, True):
        capped = dtw_nearest_distance(X, Y, groups, window=window, max_distance=limit,
                                      nearest_only=nearest_only)  # fmt: skip
        expected = exhaustive(X, Y, groups, Euclidean(2), window, limit=limit,
                              nearest_only=nearest_only)  # fmt: skip
        np.testing.assert_array_equal(capped, expected)


def test_ties_between_groups_are_kept():
    """A series whose copy sits in two groups: both groups are the nearest, as in the
    exhaustive search, so argmin gives the same (first) group."""
    t = np.linspace(0, 1, 30)
    Y = np.array([np.sin(6 * t), np.cos(6 * t), np.cos(6 * t), np.sin(6 * t) + 1])
    X = np.array([np.cos(6 * t)])
    got = dtw_nearest_distance(X, Y, [0, 2, 1, 3], window=0.1, nearest_only=True)
    np.testing.assert_array_equal(got, [[np.inf, 0.0, 0.0, np.inf]])


def test_the_nearest_group_is_found_without_most_pairs(rng):
    """Series near one of four shapes: the nearest group is found after about one
    group's worth of exact DTWs per query, not all 200 (every group's nearest needs more:
    the members of a far group are near-copies, whose bounds all lie below their
    distances)."""
    t = np.linspace(0, 1, 60)
    shapes = [np.sin(2 * np.pi * (f * t + p)) for f, p in ((1, 0), (2, 0.3), (3, 0.1), (1, 0.5))]

    def noisy(g):
        return np.roll(shapes[g], int(rng.integers(-3, 4))) + 0.05 * rng.standard_normal(60)

    groups = np.repeat(np.arange(4), 50)
    Y = np.array([noisy(g) for g in groups])
    X = np.array([noisy(g) for g in range(4) for _ in range(5)])
    for nearest_only in (True, False):
        distances, computed = _search._nearest(X, Y, groups, "euclidean", 0.1, False, None,
                                               None, None, nearest_only, 1)  # fmt: skip
        expected = exhaustive(X, Y, groups, Euclidean(1), 0.1, nearest_only=nearest_only)
        np.testing.assert_array_equal(distances, expected)
        if nearest_only:
            assert computed.mean() < 0.4 * len(Y)


def test_leave_one_out_and_excluded_groups(rng):
    X = rng.standard_normal((25, 20)).cumsum(1)
    groups = np.repeat([0, 1, 2], [10, 10, 5])
    exclude = np.arange(25)
    got = dtw_nearest_distance(X, X, groups, exclude=exclude, window=0.1)
    np.testing.assert_array_equal(got, exhaustive(X, X, groups, Euclidean(1), 0.1, False, exclude))
    assert np.all(got[np.arange(25), groups] > 0)  # a series is not its own neighbour
    skip = np.array([-1, 0, 1, 2, 0] * 5)
    got = dtw_nearest_distance(X, X, groups, window=0.1, exclude_group=skip)
    expected = exhaustive(X, X, groups, Euclidean(1), 0.1, False, None, skip)
    np.testing.assert_array_equal(got, expected)
    assert np.isinf(got[1, 0]) and np.isfinite(got[0]).all()
    one = dtw_nearest_distance(X[:3], X)  # one group: the nearest series overall
    np.testing.assert_array_equal(one[:, 0], dtw_pairwise_distance(X[:3], X).min(1))


def test_manifolds_without_compiled_distances_take_the_exhaustive_search(rng):
    spd = SPD(2)
    X, Y = walks(spd, (12, 15, 9), 3), walks(spd, (10, 14, 11, 13), 40)
    groups = np.array([0, 1, 1, 0])
    got = dtw_nearest_distance(X, Y, groups, spd, window=0.2, exclude=np.array([0, -1, 3]))
    expected = exhaustive(X, Y, groups, spd, 0.2, False, np.array([0, -1, 3]))
    np.testing.assert_array_equal(got, expected)


def test_bad_arguments_are_named():
    X = np.zeros((3, 10))
    with pytest.raises(ValueError, match="groups must be 3 integers"):
        dtw_nearest_distance(X, X, groups=[0, 1])
    with pytest.raises(ValueError, match="groups must hold integers from 0"):
        dtw_nearest_distance(X, X, groups=[0, -1, 1])
    with pytest.raises(ValueError, match="exclude holds 5, but Y has 3 series"):
        dtw_nearest_distance(X, X, exclude=[5, 0, 0])
    with pytest.raises(ValueError, match="exclude_group must be 3 integers"):
        dtw_nearest_distance(X, X, exclude_group=[0.5, 0, 0])
    with pytest.raises(ValueError, match="max_distance must not be NaN"):
        dtw_nearest_distance(X, X, max_distance=np.nan)
    with pytest.raises(ValueError, match="window must be a finite number in \\[0, 1\\] or None"):
        dtw_nearest_distance(X, X, window=2.0)
    with pytest.raises(ValueError, match="NaN"):
        dtw_nearest_distance(np.full((2, 5), np.nan), X)


def test_collections_and_threads_give_the_same_values(rng):
    X = rng.standard_normal((9, 30)).cumsum(1)
    Y = rng.standard_normal((21, 34)).cumsum(1)
    groups = rng.integers(0, 3, 21)
    one = dtw_nearest_distance(X, Y, groups, window=0.1)
    two = dtw_nearest_distance(check_series_collection(X), check_series_collection(Y), groups,
                               window=0.1, n_jobs=2)  # fmt: skip
    np.testing.assert_array_equal(one, two)
