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
