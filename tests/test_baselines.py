"""DTW-family baselines against plain DTW, brute-force references, aeon and invariants."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from aeon.clustering.averaging import elastic_barycenter_average

from sk_rtw.baselines import (
    MultipleAlignment,
    dba_average,
    grid_bytes,
    mmddtw_align,
    pdtw_average,
    qdtw,
    qdtw_align,
    quaternion_cost_matrix,
)
from sk_rtw.dtw import dtw_path
from sk_rtw.manifolds import SPD, Quaternion, Sphere
from sk_rtw.utils import to_aeon

from .conftest import MANIFOLDS
from .test_dtw import random_walk

SPACES = MANIFOLDS


def reference_joint_dtw(series, manifold, squared=False, cost=None):
    """Joint DTW over every index combination, with Python loops (independent of numba)."""
    cost = cost or (lambda p, q: float(manifold.dist(p, q)) ** (2 if squared else 1))
    shape = tuple(len(s) for s in series)
    D = np.full(shape, np.inf)
    steps = [m for m in itertools.product((0, 1), repeat=len(shape)) if any(m)]
    for idx in itertools.product(*(range(t) for t in shape)):
        c = sum(
            cost(series[a][idx[a]], series[b][idx[b]])
            for a, b in itertools.combinations(range(len(shape)), 2)
        )
        prev = [
            D[tuple(i - s for i, s in zip(idx, m, strict=True))]
            for m in steps
            if all(i - s >= 0 for i, s in zip(idx, m, strict=True))
        ]
        D[idx] = c + (min(prev) if prev else 0.0)
    return D[tuple(t - 1 for t in shape)]


def check_joint_path(result: MultipleAlignment, lengths):
    idx = result.indices
    assert idx.shape[0] == len(lengths)
    np.testing.assert_array_equal(idx[:, 0], 0)
    np.testing.assert_array_equal(idx[:, -1], np.array(lengths) - 1)
    steps = np.diff(idx, axis=1)
    assert np.all((steps == 0) | (steps == 1))
    assert np.all(steps.sum(0) >= 1)


@pytest.mark.parametrize("manifold", SPACES, ids=repr)
@pytest.mark.parametrize("lengths", [(12, 12), (9, 14)])
def test_mmddtw_with_two_series_is_plain_dtw(manifold, lengths):
    x, y = (random_walk(manifold, t, seed) for seed, t in enumerate(lengths))
    result = mmddtw_align([x, y], manifold)
    path, distance = dtw_path(x, y, manifold)
    np.testing.assert_array_equal(result.indices.T, np.array(path))
    assert result.cost == pytest.approx(distance, rel=1e-12)


@pytest.mark.parametrize("manifold", MANIFOLDS, ids=repr)
@pytest.mark.parametrize("squared", [False, True])
def test_mmddtw_matches_brute_force_joint_dtw(manifold, squared):
    series = [random_walk(manifold, t, 10 + t) for t in (5, 7, 6)]
    result = mmddtw_align(series, manifold, squared=squared)
    expected = reference_joint_dtw(series, manifold, squared)
    assert result.cost == pytest.approx(expected, rel=1e-12)
    check_joint_path(result, (5, 7, 6))
    along_path = sum(
        float(manifold.dist(result.aligned[a, k], result.aligned[b, k])) ** (1 + squared)
        for k in range(result.indices.shape[1])
        for a, b in itertools.combinations(range(3), 2)
    )
    assert along_path == pytest.approx(result.cost, rel=1e-10)


def test_mmddtw_squared_euclidean_cost_is_n_times_spread_about_the_mean(rng):
    series = rng.standard_normal((4, 8, 2))
    result = mmddtw_align(series, squared=True)
    spread = ((result.aligned - result.mean) ** 2).sum()
    assert result.cost == pytest.approx(4 * spread, rel=1e-12)
    np.testing.assert_allclose(result.mean, result.aligned.mean(0), atol=1e-12)


def test_mmddtw_of_identical_series_is_the_diagonal(rng):
    x = random_walk(Sphere(2), 15, 3)
    result = mmddtw_align(np.stack([x, x, x]), "sphere")
    np.testing.assert_array_equal(result.indices, np.tile(np.arange(15), (3, 1)))
    np.testing.assert_allclose(result.mean, x, atol=1e-12)
    assert result.cost == pytest.approx(0.0, abs=1e-10)
    np.testing.assert_allclose(result.warps[0], np.linspace(0, 1, 15))


def test_mmddtw_window_restricts_the_path_and_cannot_lower_the_cost(rng):
    series = rng.standard_normal((3, 20, 1)).cumsum(1)
    free = mmddtw_align(series)
    banded = mmddtw_align(series, window=0.1)
    assert banded.cost >= free.cost - 1e-12
    rel = banded.warps
    for a, b in itertools.combinations(range(3), 2):
        assert np.all(np.abs(rel[a] - rel[b]) <= 0.1 + 1e-12)
    assert mmddtw_align(series, window=1.0).cost == pytest.approx(free.cost)


def test_mmddtw_reports_the_memory_it_would_need():
    series = np.zeros((3, 50, 1))
    assert grid_bytes([50, 50, 50]) == 8 * 50**3
    with pytest.raises(MemoryError, match=r"50 x 50 x 50 grid.*0\.000931 GiB"):
        mmddtw_align(series, max_memory=10_000)
    with pytest.raises(MemoryError, match="T\\^N"):
        mmddtw_align(np.zeros((12, 100, 1)))  # 8e24 bytes


def test_mmddtw_cholesky_is_euclidean_joint_dtw_of_the_factors():
    M = SPD(2)
    series = [random_walk(M, 10, seed, step=0.4) for seed in range(3)]
    result = mmddtw_align(series, M, metric="cholesky")
    factors = [np.linalg.cholesky(s).reshape(10, -1) for s in series]
    flat = mmddtw_align(factors)
    np.testing.assert_array_equal(result.indices, flat.indices)
    assert result.cost == pytest.approx(flat.cost, rel=1e-12)
    L = np.linalg.cholesky(result.aligned).mean(0)
    np.testing.assert_allclose(result.mean, L @ np.swapaxes(L, -1, -2), rtol=1e-12)
    M.validate(result.mean)
    geodesic = mmddtw_align(series, M)
    assert not np.allclose(geodesic.cost, result.cost)


def test_mmddtw_bad_input():
    with pytest.raises(ValueError, match="minimum of 2"):
        mmddtw_align(np.zeros((1, 5, 1)))
    with pytest.raises(ValueError, match="metric"):
        mmddtw_align(np.zeros((2, 5, 1)), metric="frobenius")
    with pytest.raises(ValueError, match="SPD"):
        mmddtw_align(np.tile([1.0, 0.0], (2, 5, 1)), "sphere", metric="cholesky")
    with pytest.raises(ValueError, match="NaN"):
        mmddtw_align(np.full((2, 5, 1), np.nan))


def test_pdtw_of_identical_series_returns_that_series():
    x = random_walk(Sphere(2), 20, 0)
    result = pdtw_average(np.stack([x] * 5), "sphere")
    np.testing.assert_allclose(result.mean, x, atol=1e-12)
    np.testing.assert_array_equal(result.indices, np.tile(np.arange(20), (5, 1)))


@pytest.mark.parametrize("manifold", MANIFOLDS, ids=repr)
def test_pdtw_of_two_series_is_the_midpoint_of_the_samples_it_matches(manifold):
    x, y = random_walk(manifold, 14, 1), random_walk(manifold, 11, 2)
    result = pdtw_average([x, y], manifold)
    a, b = x[result.indices[0]], y[result.indices[1]]
    np.testing.assert_allclose(manifold.dist(result.mean, a), manifold.dist(result.mean, b),
                               rtol=1e-9, atol=1e-12)  # fmt: skip
    np.testing.assert_allclose(
        manifold.dist(result.mean, a), 0.5 * manifold.dist(a, b), rtol=1e-9, atol=1e-12
    )
    # and the matched samples follow a DTW path between the two series
    path, _ = dtw_path(x, y, manifold)
    steps = set(map(tuple, np.array(path)))
    assert {tuple(pair) for pair in result.indices.T} <= steps | {(0, 0)}


def test_pdtw_running_mean_of_euclidean_constants_is_their_average():
    X = np.stack([np.full((9, 1), v) for v in (1.0, 2.0, 6.0, 3.0)])
    result = pdtw_average(X, output_length=5)
    np.testing.assert_allclose(result.mean, 3.0)
    assert result.mean.shape == (5, 1)
    assert result.aligned.shape == (4, 5, 1)


def test_pdtw_bad_output_length():
    with pytest.raises(ValueError, match="output_length"):
        pdtw_average(np.zeros((2, 5, 1)), output_length=0)


def test_dba_matches_aeon_petitjean_on_euclidean_data(rng):
    X = rng.standard_normal((6, 30)).cumsum(1)
    init = X[2]
    expected = elastic_barycenter_average(
        to_aeon(X), distance="dtw", max_iters=3, tol=0.0, init_barycenter=init[None]
    )
    result = dba_average(X, max_iter=3, init=init, tol=0.0)
    np.testing.assert_allclose(result.mean[:, 0], expected.ravel(), rtol=1e-10)


def test_dba_cost_never_increases_and_identical_series_are_fixed_points(capsys):
    M = Sphere(2)
    X = np.stack([random_walk(M, 25, s) for s in range(5)])
    one = dba_average(X, M, max_iter=1)
    many = dba_average(X, M, max_iter=8, verbose=True)
    costs = [float(line.split()[-1]) for line in capsys.readouterr().err.splitlines()]
    assert costs == sorted(costs, reverse=True) and len(costs) >= 2
    assert many.cost <= one.cost + 1e-12
    M.validate(many.mean)
    same = dba_average(np.stack([X[0]] * 3), M)
    np.testing.assert_allclose(same.mean, X[0], atol=1e-12)
    np.testing.assert_array_equal(same.indices, np.tile(np.arange(25), (3, 1)))


def test_dba_on_unequal_lengths_keeps_the_medoid_length():
    M = SPD(2)
    X = [random_walk(M, t, t) for t in (12, 18, 15)]
    result = dba_average(X, M)
    assert result.mean.shape[0] in (12, 18, 15)
    assert result.aligned.shape == (3, result.mean.shape[0], 2, 2)
    with pytest.raises(ValueError, match="init"):
        dba_average(X, M, init="mean")
    with pytest.raises(ValueError, match="max_iter"):
        dba_average(X, M, max_iter=0)


def test_dba_reports_its_iterations_and_stops_early_when_converged():
    M = Sphere(2)
    X = np.stack([random_walk(M, 25, s) for s in range(5)])
    short = dba_average(X, M, max_iter=2, tol=0.0)
    assert short.n_iter == 2
    converged = dba_average(X, M, max_iter=50, tol=1e-3)
    assert 1 <= converged.n_iter < 50  # stopped when the cost stopped improving
    with pytest.raises(ValueError, match="tol"):
        dba_average(X, M, tol=-1.0)


def test_qdtw_is_invariant_to_sign_flips_and_equals_quaternion_dtw(rng):
    Q = Quaternion()
    x, y = random_walk(Q, 20, 1), random_walk(Q, 16, 2)
    flipped = y * np.where(rng.random(16) < 0.5, -1.0, 1.0)[:, None]
    path, distance = qdtw(x, y)
    path_flipped, distance_flipped = qdtw(x, flipped)
    np.testing.assert_array_equal(path, path_flipped)
    assert distance == pytest.approx(distance_flipped, rel=1e-12)
    expected_path, expected = dtw_path(x, y, Q)
    np.testing.assert_array_equal(path, np.array(expected_path))
    assert distance == pytest.approx(expected, rel=1e-12)


def test_qdtw_dot_cost_against_reference(rng):
    Q = Quaternion()
    x, y = random_walk(Q, 9, 3), random_walk(Q, 7, 4)
    dot = quaternion_cost_matrix(x, y, "dot")
    np.testing.assert_allclose(dot, 1 - np.abs(np.cos(Q.pairwise_dist(x, y))), atol=1e-12)
    expected = reference_joint_dtw([x, y], Q, cost=lambda p, q: 1 - abs(float(p @ q)))
    assert qdtw(x, y, cost="dot")[1] == pytest.approx(expected, rel=1e-12)
    with pytest.raises(ValueError, match="cost"):
        qdtw(x, y, cost="chordal")


def test_qdtw_align_with_two_series_is_qdtw_and_three_match_brute_force():
    Q = Quaternion()
    series = [random_walk(Q, t, t) for t in (6, 5, 7)]
    pair = qdtw_align(series[:2])
    path, distance = qdtw(*series[:2])
    np.testing.assert_array_equal(pair.indices.T, path)
    assert pair.cost == pytest.approx(distance)
    triple = qdtw_align(series, cost="dot")
    expected = reference_joint_dtw(series, Q, cost=lambda p, q: 1 - abs(float(p @ q)))
    assert triple.cost == pytest.approx(expected, rel=1e-12)
    Q.validate(triple.mean)


def test_dba_chooses_the_medoid_of_long_series_on_halved_copies(monkeypatch):
    """Beyond MEDOID_LENGTH samples the all-pairs DTW runs on copies halved to at most
    that length; the series it designates starts DBA (here the same as the full search:
    one series lies between the others)."""
    import sk_rtw.baselines._dba as dba
    from sk_rtw.dtw import medoid_index
    from sk_rtw.utils import check_series_collection

    t = np.linspace(0, 1, 400)
    X = np.stack([np.sin(2 * np.pi * (t + shift)) for shift in (0.0, 0.04, 0.02, 0.1)])
    collection = check_series_collection(X, "euclidean")
    exact = medoid_index(collection)
    calls = []
    original = dba.medoid_index

    def spy(candidates, **kwargs):
        calls.append(candidates.max_length)
        return original(candidates, **kwargs)

    monkeypatch.setattr(dba, "medoid_index", spy)
    monkeypatch.setattr(dba, "MEDOID_LENGTH", 100)
    start = dba._initial_mean(collection, "medoid", None, True)
    assert calls == [100]  # 400 samples halved twice
    np.testing.assert_array_equal(start, collection.series(exact))
    monkeypatch.setattr(dba, "MEDOID_LENGTH", 1000)
    dba._initial_mean(collection, "medoid", None, True)
    assert calls[-1] == 400  # short series: the exact search, as before
