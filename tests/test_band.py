"""Coarse-to-fine banded DTW paths against the exact recursion."""

from __future__ import annotations

import numpy as np
import pytest

from sk_rtw.dtw import path_indices
from sk_rtw.dtw._band import band_from_path, halve, multiscale_path
from sk_rtw.manifolds import SPD, Euclidean, Sphere

from .conftest import MANIFOLDS


def smooth_walk(rng, n, dim):
    steps = rng.standard_normal((n, dim))
    return np.cumsum(np.cumsum(steps, 0), 0) / n


@pytest.mark.parametrize("manifold", MANIFOLDS, ids=repr)
def test_multiscale_path_matches_the_exact_path_on_smooth_series(manifold, rng):
    base = rng.standard_normal(manifold.point_shape)
    p = manifold.project(base) if not isinstance(manifold, SPD) else np.eye(manifold.dim)
    t = np.linspace(0, 1, 900)
    tangent = manifold.random_tangent(p, 1.0, random_state=1)

    def curve(times):
        return manifold.exp(
            np.broadcast_to(p, (len(times), *p.shape)),
            np.einsum("t,...->t...", np.sin(6 * times), tangent),
        )

    x, y = curve(t), curve(t[:800] ** 1.3)
    _, exact_cost = path_indices(x, y, manifold, squared=True)
    band, band_cost = multiscale_path(x, y, manifold, squared=True, exact_cells=1000)
    assert band[0].tolist() == [0, 0] and band[-1].tolist() == [len(x) - 1, len(y) - 1]
    assert np.all(np.diff(band, axis=0) >= 0) and np.all(np.diff(band, axis=0).sum(1) >= 1)
    assert band_cost == pytest.approx(exact_cost, rel=1e-9)


def test_multiscale_path_is_close_on_rough_series(rng):
    x, y = rng.standard_normal((700, 1)).cumsum(0), rng.standard_normal((650, 1)).cumsum(0)
    _, exact_cost = path_indices(x, y, Euclidean(1))
    _, band_cost = multiscale_path(x, y, Euclidean(1), exact_cells=1000)
    assert exact_cost <= band_cost <= 1.01 * exact_cost
    # small problems are solved exactly
    small, _ = multiscale_path(x[:100], y[:90], Euclidean(1))
    np.testing.assert_array_equal(small, path_indices(x[:100], y[:90], Euclidean(1))[0])


def test_band_covers_the_projected_path_as_a_staircase():
    coarse = np.array([[0, 0], [1, 0], [2, 1], [3, 2], [3, 3]])
    lo, hi = band_from_path(coarse, 8, 8, 1)
    assert lo[0] == 0 and hi[-1] == 8
    assert np.all(np.diff(lo) >= 0) and np.all(np.diff(hi) >= 0) and np.all(lo < hi)
    for i, j in coarse:
        for di in (0, 1):
            for dj in (0, 1):
                assert lo[2 * i + di] <= 2 * j + dj < hi[2 * i + di]


def test_halving_takes_geodesic_midpoints():
    S1 = Sphere(1)
    angles = np.array([0.0, 0.4, 1.0, 1.2, 2.0])
    x = np.stack([np.cos(angles), np.sin(angles)], 1)
    mid = halve(x, S1)
    np.testing.assert_allclose(np.arctan2(mid[:, 1], mid[:, 0]), [0.2, 1.1, 2.0], atol=1e-12)


def _reference_band_dtw(cost, lo, hi):
    """The DTW recursion in plain Python with ``inf`` outside the band, and the path
    backtracked with ties broken diagonal, then up, then left."""
    nx, ny = cost.shape
    D = np.full((nx + 1, ny + 1), np.inf)
    D[0, 0] = 0.0
    for i in range(nx):
        for j in range(lo[i], hi[i]):
            D[i + 1, j + 1] = cost[i, j] + min(D[i, j], D[i, j + 1], D[i + 1, j])
    i, j, path = nx - 1, ny - 1, [(nx - 1, ny - 1)]
    while i > 0 or j > 0:
        if i == 0:
            j -= 1
        elif j == 0:
            i -= 1
        else:
            diag, up, left = D[i, j], D[i, j + 1], D[i + 1, j]
            if diag <= up and diag <= left:
                i, j = i - 1, j - 1
            elif up <= left:
                i -= 1
            else:
                j -= 1
        path.append((i, j))
    return D[1:, 1:], np.array(path[::-1])


@pytest.mark.parametrize("compiled", [True, False], ids=["kernel costs", "given costs"])
def test_band_rows_match_a_reference_recursion(compiled, rng):
    from sk_rtw.dtw import point_cost_matrix
    from sk_rtw.dtw._costs import kernel_form
    from sk_rtw.dtw._point_costs import segment_codes
    from sk_rtw.dtw._pruned import (
        band_accumulated_cost,
        band_segment_cost,
        ragged_backtrack,
        ragged_value,
    )

    manifold = Sphere(2)
    x = manifold.project(rng.standard_normal((41, 3)))
    y = manifold.project(rng.standard_normal((37, 3)))
    coarse = [(0, 0)]  # a warping path of the half-length problem, random steps
    while coarse[-1] != (20, 18):
        i, j = coarse[-1]
        step = [(1, 1), (1, 0), (0, 1)][rng.integers(3)]
        coarse.append((min(i + step[0], 20), min(j + step[1], 18)))
    coarse = np.array(coarse)
    lo, hi = band_from_path(coarse, len(x), len(y), 2)
    cost = np.round(point_cost_matrix(x, y, manifold, squared=True), 1)  # ties on purpose
    if compiled:
        cost = point_cost_matrix(x, y, manifold, squared=True)
        rows = band_segment_cost(kernel_form(x, manifold), kernel_form(y, manifold),
                                 segment_codes(manifold), True, lo, hi)  # fmt: skip
    else:
        band_values = np.concatenate([cost[i, lo[i] : hi[i]] for i in range(len(x))])
        rows = band_accumulated_cost(band_values, lo, hi)
    D, path = _reference_band_dtw(cost, lo, hi)
    for i in range(len(x)):
        for j in range(len(y)):
            expected = D[i, j] if lo[i] <= j < hi[i] else np.inf
            assert ragged_value(*rows, i, j) == expected
    np.testing.assert_array_equal(ragged_backtrack(*rows, len(y)), path)


def test_mean_matched_positions_are_the_paths_mean_positions(rng):
    from sk_rtw.dtw import has_compiled_costs, mean_matched_positions

    manifold = Euclidean(2)
    references = [rng.standard_normal((n, 2)).cumsum(0) for n in (30, 24)]
    series = [rng.standard_normal((n, 2)).cumsum(0) for n in (28, 35, 19)]
    codes = np.array([0, 1, 0])

    def padded(arrays):
        out = np.stack([np.concatenate([a, np.repeat(a[-1:], 35 - len(a), 0)]) for a in arrays])
        return out

    assert has_compiled_costs(manifold) and not has_compiled_costs(SPD(13))
    positions = mean_matched_positions(
        padded(references), np.array([30, 24]), padded(series), np.array([28, 35, 19]), codes,
        manifold, window=0.5,
    )  # fmt: skip
    for n, s in enumerate(series):
        reference = references[codes[n]]
        path, _ = path_indices(reference, s, manifold, 0.5, squared=True)
        expected = [path[path[:, 0] == i, 1].mean() for i in range(len(reference))]
        np.testing.assert_allclose(positions[n, : len(reference)], expected, rtol=0, atol=1e-12)
        assert not positions[n, len(reference) :].any()
    with pytest.raises(ValueError, match="no compiled point costs"):
        mean_matched_positions(padded(references), np.array([30, 24]), padded(series),
                               np.array([28, 35, 19]), codes, SPD(13))  # fmt: skip


@pytest.mark.parametrize("manifold", MANIFOLDS, ids=repr)
@pytest.mark.parametrize("smooth", [True, False], ids=["smooth", "rough"])
def test_exact_pairs_guided_by_a_coarse_path_equal_the_full_matrix(manifold, smooth, rng):
    """The pairs multiscale_path solves exactly skip the cells a coarse-to-fine guide
    rules out: the same path and cost, bit for bit, as the full matrix (smooth pairs,
    where the guide prunes most cells, and rough ones, where it prunes few)."""
    from sk_rtw.dtw import _band
    from sk_rtw.dtw._costs import optimal_path, point_cost_matrix

    if smooth:
        p = manifold.random_point((), rng)
        tangent = manifold.random_tangent(p, 1.0, random_state=2)

        def curve(times):
            return manifold.exp(
                np.broadcast_to(p, (len(times), *p.shape)),
                np.einsum("t,...->t...", np.sin(6 * times), tangent),
            )

        t = np.linspace(0, 1, 400)
        x, y = curve(t), curve(np.linspace(0, 1, 330) ** 1.3)
    else:
        x, y = manifold.random_point((400,), rng), manifold.random_point((330,), rng)
    assert len(x) * len(y) > _band.GUIDED_CELLS
    for squared in (False, True):
        path, cost = multiscale_path(x, y, manifold, squared=squared)
        expected, expected_cost = optimal_path(point_cost_matrix(x, y, manifold, squared))
        np.testing.assert_array_equal(path, expected)
        assert cost == expected_cost


def test_thin_exact_pairs_are_solved_on_the_full_matrix(monkeypatch, rng):
    """A pair too thin for a band (one series of at most 2 radius + 2 samples) has no
    coarser guide: the full matrix, without recursion."""
    from sk_rtw.dtw import _band

    monkeypatch.setattr(_band, "_guided_path", lambda *a: pytest.fail("guided a thin pair"))
    x, y = smooth_walk(rng, 30, 2), smooth_walk(rng, 5000, 2)
    path, _ = multiscale_path(x, y, Euclidean(2), squared=True)
    assert path[-1].tolist() == [29, 4999]
