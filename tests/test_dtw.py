"""Manifold DTW against aeon (Euclidean) and against a plain-Python reference."""

from __future__ import annotations

import math

import numpy as np
import pytest
from aeon.distances import dtw_alignment_path as aeon_dtw_path
from aeon.distances import dtw_distance as aeon_dtw_distance
from aeon.distances import dtw_pairwise_distance as aeon_dtw_pairwise_distance

from sk_rtw.dtw import dtw_cost_matrix, dtw_distance, dtw_pairwise_distance, dtw_path
from sk_rtw.manifolds import SPD, Product, Quaternion, Sphere

from .conftest import MANIFOLDS


def reference_dtw(x, y, manifold, squared=False, band=None):
    """Textbook DTW with Python loops; ``band`` is a boolean mask of allowed cells."""
    nx, ny = len(x), len(y)
    D = np.full((nx + 1, ny + 1), np.inf)
    D[0, 0] = 0.0
    for i in range(nx):
        for j in range(ny):
            if band is not None and not band[i, j]:
                continue
            c = float(manifold.dist(x[i], y[j]))
            c = c * c if squared else c
            D[i + 1, j + 1] = c + min(D[i, j], D[i, j + 1], D[i + 1, j])
    return D[nx, ny]


def random_walk(manifold, length, seed, step=0.2):
    rng = np.random.default_rng(seed)
    p = manifold.random_point((), rng.integers(1 << 30))
    points = [p]
    for _ in range(length - 1):
        v = manifold.random_tangent(points[-1], step, rng.integers(1 << 30))
        points.append(manifold.exp(points[-1], v))
    return np.stack(points)


@pytest.mark.parametrize("window", [None, 0.0, 0.1, 0.3, 1.0])
@pytest.mark.parametrize(("nx", "ny", "d"), [(30, 30, 1), (25, 40, 1), (40, 17, 3)])
def test_matches_aeon_on_euclidean_data(nx, ny, d, window, rng):
    x, y = rng.standard_normal((nx, d)), rng.standard_normal((ny, d))
    expected = aeon_dtw_distance(x.T, y.T, window=window)
    assert dtw_distance(x, y, squared=True, window=window) == pytest.approx(expected, rel=1e-12)
    if d == 1:
        assert dtw_distance(x[:, 0], y[:, 0], squared=True, window=window) == pytest.approx(
            expected, rel=1e-12
        )


def test_path_matches_aeon(rng):
    x, y = rng.standard_normal(30), rng.standard_normal(22)
    path, dist = dtw_path(x, y, squared=True)
    aeon_path, aeon_dist = aeon_dtw_path(x, y)
    assert dist == pytest.approx(aeon_dist)
    assert path == [tuple(map(int, p)) for p in aeon_path]


@pytest.mark.parametrize("window", [None, 0.2])
def test_pairwise_matches_aeon(window, rng):
    X, Y = rng.standard_normal((6, 40)), rng.standard_normal((4, 40))
    np.testing.assert_allclose(
        dtw_pairwise_distance(X, Y, squared=True, window=window, n_jobs=2),
        aeon_dtw_pairwise_distance(X, Y, window=window),
        rtol=1e-12,
    )
    np.testing.assert_allclose(
        dtw_pairwise_distance(X, squared=True, window=window),
        aeon_dtw_pairwise_distance(X, window=window),
        rtol=1e-12,
    )


def test_unequal_length_pairwise_matches_aeon(rng):
    X = [rng.standard_normal(n) for n in (20, 31, 26)]
    Y = [rng.standard_normal(n) for n in (18, 40)]
    expected = np.array([[aeon_dtw_distance(x, y) for y in Y] for x in X])
    np.testing.assert_allclose(dtw_pairwise_distance(X, Y, squared=True), expected, rtol=1e-12)


def aeon_band(nx, ny, window):
    """aeon's Sakoe-Chiba bounding matrix, in Python.

    Its compiled form is not a reference: aeon's amerced DTW is compiled with
    ``fastmath=True``, numba compiles the bounding matrix it calls with those flags (and
    caches that build), and ``(step / size) * n`` is then taken as ``step * (1 / size) * n``
    -- at 28 x 57 without a band, ``floor(0.5 * 28)`` becomes 13 and one column moves
    to the row above. Whether the test saw that depended on which test compiled aeon's
    function first.
    """
    from aeon.distances.elastic._bounding_matrix import _sakoe_chiba_bounding

    if nx > ny:  # the Python function transposes through its compiled self
        return _sakoe_chiba_bounding.py_func(ny, nx, window).T
    return _sakoe_chiba_bounding.py_func(nx, ny, window)


@pytest.mark.parametrize("window", [0.0, 0.05, 0.1, 0.33, 0.9])
def test_band_rows_are_aeons_bounding_matrix(window):
    from sk_rtw.dtw._kernels import sakoe_chiba_rows

    for nx in range(1, 30):
        for ny in (1, 2, 7, nx, 2 * nx + 1, 29):
            lo, hi = sakoe_chiba_rows(nx, ny, window)
            cols = np.arange(ny)
            mask = (cols >= lo[:, None]) & (cols < hi[:, None])
            np.testing.assert_array_equal(mask, aeon_band(nx, ny, window), err_msg=f"{nx}x{ny}")


@pytest.mark.parametrize("window", [0.0, 0.05, 0.2])
def test_banded_unequal_length_pairwise_matches_aeon(window, rng):
    X = [rng.standard_normal(n) for n in (20, 31, 26, 57)]
    Y = [rng.standard_normal(n) for n in (18, 40, 57)]
    expected = np.array([[aeon_dtw_distance(x, y, window=window) for y in Y] for x in X])
    np.testing.assert_allclose(
        dtw_pairwise_distance(X, Y, squared=True, window=window), expected, rtol=1e-12
    )
    expected = np.array([[aeon_dtw_distance(x, y, window=window) for y in X] for x in X])
    np.testing.assert_allclose(
        dtw_pairwise_distance(X, squared=True, window=window), expected, rtol=1e-12, atol=1e-12
    )


@pytest.mark.parametrize("manifold", MANIFOLDS, ids=repr)
@pytest.mark.parametrize("squared", [False, True])
def test_matches_python_reference_on_manifolds(manifold, squared):
    x, y = random_walk(manifold, 14, 1), random_walk(manifold, 11, 2)
    expected = reference_dtw(x, y, manifold, squared)
    assert dtw_distance(x, y, manifold, squared=squared) == pytest.approx(expected, rel=1e-10)
    band = aeon_band(14, 11, 0.3)
    expected = reference_dtw(x, y, manifold, squared, band)
    assert dtw_distance(x, y, manifold, window=0.3, squared=squared) == pytest.approx(
        expected, rel=1e-10
    )


@pytest.mark.parametrize("manifold", MANIFOLDS, ids=repr)
def test_pairwise_matches_single_distances_on_manifolds(manifold):
    X = [random_walk(manifold, n, 10 + n) for n in (9, 12, 7)]
    Y = [random_walk(manifold, n, 20 + n) for n in (10, 8)]
    expected = np.array([[dtw_distance(x, y, manifold) for y in Y] for x in X])
    np.testing.assert_allclose(dtw_pairwise_distance(X, Y, manifold), expected, rtol=1e-10)
    expected_xx = np.array([[dtw_distance(a, b, manifold) for b in X] for a in X])
    np.testing.assert_allclose(
        dtw_pairwise_distance(X, manifold=manifold), expected_xx, rtol=1e-10, atol=1e-12
    )
    normalised = dtw_pairwise_distance(X, Y, manifold, normalize="path")
    expected_norm = np.array(
        [[dtw_distance(x, y, manifold, normalize="path") for y in Y] for x in X]
    )
    np.testing.assert_allclose(normalised, expected_norm, rtol=1e-10)


def test_sign_flips_do_not_change_quaternion_dtw():
    Q = Quaternion()
    x, y = random_walk(Q, 20, 3), random_walk(Q, 15, 4)
    flipped = x * np.where(np.arange(20) % 3 == 0, -1.0, 1.0)[:, None]
    assert dtw_distance(flipped, y, Q) == pytest.approx(dtw_distance(x, y, Q), rel=1e-12)


def test_path_is_a_valid_warping_path_whose_costs_sum_to_the_distance(rng):
    S = Sphere(2)
    x, y = random_walk(S, 25, 5), random_walk(S, 18, 6)
    path, dist = dtw_path(x, y, S)
    assert path[0] == (0, 0) and path[-1] == (24, 17)
    steps = np.diff(np.array(path), axis=0)
    assert np.all((steps >= 0) & (steps <= 1)) and np.all(steps.sum(1) >= 1)
    assert sum(float(S.dist(x[i], y[j])) for i, j in path) == pytest.approx(dist, rel=1e-10)
    assert dtw_distance(x, y, S, normalize="path") == pytest.approx(dist / len(path))
    D = dtw_cost_matrix(x, y, S)
    assert D.shape == (25, 18) and D[-1, -1] == pytest.approx(dist)


def test_band_cells_outside_are_infinite(rng):
    D = dtw_cost_matrix(rng.standard_normal(20), rng.standard_normal(20), window=0.1)
    assert np.isinf(D[0, 10]) and np.isfinite(D[10, 10])
    np.testing.assert_array_equal(np.isfinite(D), aeon_band(20, 20, 0.1))


def test_identical_and_time_stretched_series_have_zero_distance():
    S = Sphere(1)
    angles = np.linspace(0, 3, 30)
    x = np.stack([np.cos(angles), np.sin(angles)], -1)
    assert dtw_distance(x, x, S) == pytest.approx(0.0, abs=1e-12)
    assert dtw_distance(x, np.repeat(x, 3, axis=0), S) == pytest.approx(0.0, abs=1e-12)
    assert dtw_distance(x, x[::-1], S) > 1.0


def test_distance_is_the_geodesic_cost_not_the_chordal_one():
    S = Sphere(1)
    x = np.array([[1.0, 0.0], [1.0, 0.0]])
    y = np.array([[-1.0, 0.0], [-1.0, 0.0]])
    assert dtw_distance(x, y, S) == pytest.approx(2 * math.pi)


@pytest.mark.parametrize("window", [-0.1, 1.5])
def test_invalid_window(window):
    with pytest.raises(ValueError, match="window"):
        dtw_distance(np.zeros(5), np.zeros(5), window=window)


def test_invalid_normalize_and_bad_series():
    with pytest.raises(ValueError, match="normalize"):
        dtw_distance(np.zeros(5), np.zeros(5), normalize="length")
    with pytest.raises(ValueError, match="NaN"):
        dtw_distance(np.array([0.0, np.nan]), np.zeros(5))
    with pytest.raises(ValueError, match="not a point"):
        dtw_distance(np.ones((4, 3)), np.ones((4, 3)), "sphere")
    with pytest.raises(ValueError, match="expected"):
        dtw_distance(np.ones((4, 3)), np.ones((4, 3)), SPD(2))


def test_product_without_kernel_distance_uses_general_path():
    from sk_rtw.dtw._point_costs import segment_codes
    from sk_rtw.manifolds._spd_pairs import MAX_KERNEL_SIZE

    k = MAX_KERNEL_SIZE + 1
    M = Product((Sphere(2), SPD(k)))  # no kernel form beyond MAX_KERNEL_SIZE
    assert segment_codes(M) is None
    rng = np.random.default_rng(0)
    X = np.concatenate(
        [Sphere(2).random_point((3, 6), rng), SPD(k).random_point((3, 6), rng).reshape(3, 6, -1)],
        axis=-1,
    )
    D = dtw_pairwise_distance(X, manifold=M)
    assert D[0, 1] == pytest.approx(dtw_distance(X[0], X[1], M), rel=1e-10)


@pytest.mark.parametrize("name", ["quaternion", "sphere", "euclidean", "product"])
def test_paths_with_costs_computed_inside_the_accumulation_equal_the_full_matrix(name):
    """path_indices computes the point costs row by row inside the band; the full cost
    matrix gives the same path and cost, bit for bit."""
    from sk_rtw.datasets import make_warped_signals
    from sk_rtw.dtw import optimal_path, path_indices, point_cost_matrix
    from sk_rtw.manifolds import Euclidean, Product, Quaternion

    rng = np.random.default_rng(3)
    if name == "product":
        M = Product((Euclidean(3), Quaternion()))
        x, y = M.random_point(41, random_state=rng), M.random_point(33, random_state=rng)
    else:
        data = make_warped_signals(name, 2, 60, random_state=1)
        M, x, y = data.manifold, data.signals[0], data.signals[1][:47]
    for window in (-1.0, 0.1, 0.3):
        for squared in (True, False):
            path, cost = path_indices(x, y, M, window, squared)
            full_path, full_cost = optimal_path(point_cost_matrix(x, y, M, squared), window)
            np.testing.assert_array_equal(path, full_path)
            assert cost == full_cost


def dense(rows, nx, ny):
    """The stored rows of accumulated_segment_cost as a matrix (``inf`` where not stored)."""
    values, offsets, starts = rows
    D = np.full((nx, ny), np.inf)
    for i in range(nx):
        row = values[offsets[i] : offsets[i + 1]]
        D[i, starts[i] : starts[i] + len(row)] = row
    return D


@pytest.mark.parametrize("name", ["quaternion", "sphere", "euclidean"])
def test_a_guide_path_skips_cells_without_changing_the_path_or_cost(name):
    """PrunedDTW: cells whose accumulated cost exceeds a known path's cost are skipped;
    the cells under it are bit for bit the full recursion's, the others no lower, so the
    optimal path and cost are the same whatever the guide (a poor one, one outside the
    band: recomputed), and a close guide skips most cells and stores only what it
    computed."""
    from sk_rtw.datasets import make_warped_signals
    from sk_rtw.dtw import _kernels, _point_costs, _pruned, point_cost_matrix
    from sk_rtw.dtw._costs import flat_points as _flat
    from sk_rtw.dtw._paths import path_indices

    data = make_warped_signals(name, 2, 300, random_state=4)
    M, x, y = data.manifold, data.signals[0], data.signals[1][:260]
    segments = _point_costs.segment_codes(M)
    fx, fy = _flat(x), _flat(y)
    staircase = np.stack([np.r_[np.arange(300), np.full(259, 299)],
                          np.r_[np.zeros(300, int), np.arange(1, 260)]], 1)  # fmt: skip
    diagonal = np.stack([np.arange(300), np.arange(300) * 259 // 299], 1)
    for window in (-1.0, 0.2):
        for squared in (True, False):
            full = _kernels.accumulated_cost(point_cost_matrix(x, y, M, squared), window)
            stored = _pruned.accumulated_segment_cost(fx, fy, segments, squared, window,
                                                       np.inf)  # fmt: skip
            np.testing.assert_array_equal(dense(stored, 300, 260), full)
            best = np.asarray(_kernels.backtrack(full), dtype=np.int64).reshape(-1, 2)
            for guide in (best, diagonal, staircase):
                path, cost = path_indices(x, y, M, window, squared, guide)
                np.testing.assert_array_equal(path, best)
                assert cost == full[-1, -1]
                bound = _point_costs.path_cost(fx, fy, guide, segments, squared)
                rows = _pruned.accumulated_segment_cost(fx, fy, segments, squared, window,
                                                         bound)  # fmt: skip
                pruned = dense(rows, 300, 260)
                under = full <= bound
                np.testing.assert_array_equal(pruned[under], full[under])
                assert np.all(pruned[~under] >= full[~under])
            bound = _point_costs.path_cost(fx, fy, best, segments, squared)
            assert bound == full[-1, -1]  # the recursion's value of its own path
            rows = _pruned.accumulated_segment_cost(fx, fy, segments, squared, window, bound)
            if window < 0:  # without a band: 28-60 % of the cells here (0.4 % at T = 4,000)
                assert len(rows[0]) < 0.7 * np.isfinite(full).sum()


def test_pairwise_distances_with_bounds_equal_those_without(rng):
    """Bounds from any path (close, poor, or too low to be a path's cost) give the same
    distances: a bound under the distance is detected and the pair computed again."""
    from sk_rtw.dtw import _point_costs, _pruned

    Q = Quaternion()
    X = np.stack([random_walk(Q, 40, seed) for seed in range(5)])
    lengths, segments = np.full(5, 40), _point_costs.segment_codes(Q)
    for window in (None, 0.3):
        plain = dtw_pairwise_distance(X, manifold=Q, squared=True, window=window)
        w = -1.0 if window is None else window
        for scale in (1.0, 1.5, 0.5, 0.0):
            bounds = plain * scale + (rng.random(plain.shape) * 1e-3 if scale else 0.0)
            got = _pruned.pairwise_segments(X, lengths, X, lengths, segments, True, w, True,
                                             bounds, 0.0)  # fmt: skip
            np.testing.assert_array_equal(got, plain)
    low = plain[0, 1] * 0.5
    assert _pruned.pruned_distance(X[0], X[1], segments, True, -1.0, low) > low


def test_long_pairs_are_bounded_by_their_coarse_to_fine_path_with_the_same_result():
    """Past 2**20 cells without a band, dtw_distance, dtw_path and dtw_pairwise_distance
    bound each pair by its coarse-to-fine path (two rows of memory, most cells skipped)
    and return what the full recursion returns, bit for bit."""
    from sk_rtw.datasets import make_warped_signals
    from sk_rtw.dtw import _point_costs, _pruned
    from sk_rtw.dtw._band import guide_bound

    Q = Quaternion()
    X = np.asarray(make_warped_signals("quaternion", 3, 1100, random_state=2).signals)
    X = [X[0], X[1][:1050], X[2]]
    segments = _point_costs.segment_codes(Q)
    full = np.array([[_pruned.pruned_distance(a, b, segments, False, -1.0, np.inf)
                      for b in X] for a in X])  # fmt: skip
    assert np.isfinite(guide_bound(X[0], X[1], Q, -1.0, False))  # long: a guide is used
    assert guide_bound(X[0], X[1], Q, 0.5, False) == np.inf  # in a band: none
    assert dtw_distance(X[0], X[1], Q) == full[0, 1]
    path, cost = dtw_path(X[0], X[1], Q)
    assert cost == full[0, 1] and path[0] == (0, 0) and path[-1] == (1099, 1049)
    symmetric = np.triu(full, 1) + np.triu(full, 1).T  # X against itself: the upper pairs
    np.testing.assert_array_equal(dtw_pairwise_distance(X, manifold=Q), symmetric)
    np.testing.assert_array_equal(dtw_pairwise_distance(X, X[:2], manifold=Q), full[:, :2])


def _plain_recursion(x, y, lo, hi, exponent, penalty):
    """DTW (amerced by ``penalty``) of univariate ``x`` and ``y`` in the staircase band
    ``[lo[i], hi[i])``, cell by cell in Python: the point cost ``|a - b| ** exponent``."""
    D = np.full((len(x) + 1, len(y) + 1), np.inf)
    D[0, 0] = 0.0
    for i in range(len(x)):
        for j in range(lo[i], hi[i]):
            cost = abs(x[i] - y[j]) ** exponent
            D[i + 1, j + 1] = cost + min(D[i, j], D[i, j + 1] + penalty, D[i + 1, j] + penalty)
    return D[-1, -1]


def test_bounded_univariate_distance_is_the_recursions_within_its_bound(rng):
    """The univariate pruned distance (two rows side by side, each pruned by the bound)
    returns the plain recursion's value bit for bit whenever it is at most the bound, and
    a value above the bound otherwise: every point cost, DTW and amerced DTW, bands,
    unequal lengths, ties (integer series), bounds at, under and over the distance."""
    from sk_rtw.dtw import _point_costs, _pruned
    from sk_rtw.dtw._kernels import sakoe_chiba_rows
    from sk_rtw.manifolds import Euclidean

    segments = _point_costs.segment_codes(Euclidean(1))
    costs = ((True, False, 2.0), (False, False, 1.0), (False, True, 0.5))
    for case in range(500):
        nx = int(rng.integers(1, 24))
        ny = nx if case % 2 else int(rng.integers(1, 24))
        if case % 3 == 0:  # ties everywhere
            x, y = rng.integers(0, 3, nx).astype(float), rng.integers(0, 3, ny).astype(float)
        else:
            x, y = np.cumsum(rng.normal(size=nx)), np.cumsum(rng.normal(size=ny))
        window = (-1.0, 1.0, 0.0, float(rng.random()), 0.1)[case % 5]
        squared, root, exponent = costs[case % 3 if case % 7 else (case // 7) % 3]
        penalty = (0.0, float(rng.random()), 1e-3)[case % 3 if case % 4 else 0]
        X, Y = x[:, None].copy(), y[:, None].copy()
        exact = _pruned.pruned_distance(X, Y, segments, squared, window, np.inf, penalty, root)
        if case < 60:  # the compiled recursion against Python's, cell by cell
            lo, hi = sakoe_chiba_rows(nx, ny, window)
            assert exact == pytest.approx(_plain_recursion(x, y, lo, hi, exponent, penalty),
                                          rel=1e-12, abs=1e-12)  # fmt: skip
        for bound in (exact * 0.3, exact * 0.9, exact * (1 - 1e-15), exact, exact * (1 + 1e-15),
                      exact * (1 + 1e-12), exact * 1.5):
            got = _pruned.pruned_distance(X, Y, segments, squared, window, bound, penalty, root)
            if exact <= bound:
                assert got == exact, (case, bound)
            else:
                assert got > bound, (case, bound)


@pytest.mark.parametrize(("squared", "root", "exponent"),
                         [(True, False, 2.0), (False, False, 1.0), (False, True, 0.5)])
def test_diagonal_cost_pairs_every_step_of_the_longer_series(rng, squared, root, exponent):
    """The diagonal (upper) bound pairs step ``t`` of the longer series with sample
    ``floor(t n / m)`` of the shorter, summed in the recursion's order: bit for bit the
    multivariate path's value (the univariate path computes it without a division per
    step), and a path's cost that bounds DTW from above."""
    from sk_rtw.dtw import _point_costs, _pruned
    from sk_rtw.manifolds import Euclidean

    univariate = _point_costs.segment_codes(Euclidean(1))
    generic = _point_costs.segment_codes(Euclidean(2))
    for nx, ny in [(7, 7), (5, 9), (9, 5), (1, 6), (6, 1), (13, 4), (4, 6), (9, 6), (8, 20)]:
        x, y = np.cumsum(rng.normal(size=nx)), np.cumsum(rng.normal(size=ny))
        steps = max(nx, ny)
        t = np.arange(steps)
        expected = 0.0
        for gap in np.abs(x[t * nx // steps] - y[t * ny // steps]):
            expected = gap**exponent + expected
        got = _point_costs.diagonal_cost(x[:, None], y[:, None], univariate, squared, root)
        assert got == pytest.approx(expected, rel=1e-13)
        # the same pairs through the generic segments (a zero second coordinate)
        pad = np.zeros((1, 1))
        xx = np.hstack([x[:, None], np.repeat(pad, nx, 0)])
        yy = np.hstack([y[:, None], np.repeat(pad, ny, 0)])
        assert got == _point_costs.diagonal_cost(xx, yy, generic, squared, root)
        exact = _pruned.pruned_distance(x[:, None], y[:, None], univariate, squared, -1.0,
                                        np.inf, 0.0, root)  # fmt: skip
        assert exact <= got * (1 + 1e-12)
