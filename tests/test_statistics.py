"""Tangent coordinates of every manifold, and the statistics of an aligned set."""

from __future__ import annotations

import numpy as np
import pytest
import torch
from scipy.stats import chi2

from sk_rtw import SPD, Euclidean, Product, Quaternion, Sphere, align, aligned_statistics
from sk_rtw.baselines import dba_average
from sk_rtw.datasets import make_warped_signals

from .conftest import CURVED, MANIFOLDS, manifold_id


# ---------------------------------------------------------- tangent coordinates
@pytest.mark.parametrize("manifold", MANIFOLDS, ids=manifold_id)
def test_coordinates_are_orthonormal_and_invertible(manifold, rng):
    p = manifold.random_point(7, random_state=1)
    v = manifold.random_tangent(p, 0.8, random_state=2)
    w = manifold.random_tangent(p, 0.8, random_state=3)
    c = manifold.to_coordinates(p, v)
    assert c.shape == (7, manifold.intrinsic_dim)
    np.testing.assert_allclose(manifold.from_coordinates(p, c), v, atol=1e-10)
    np.testing.assert_allclose(np.linalg.norm(c, axis=-1), manifold.norm(p, v), atol=1e-10)
    # linear, and the inner product is the metric's (polarisation of the norm)
    cw = manifold.to_coordinates(p, w)
    np.testing.assert_allclose(manifold.to_coordinates(p, v + 2 * w), c + 2 * cw, atol=1e-10)
    metric = (manifold.norm(p, v + w) ** 2 - manifold.norm(p, v - w) ** 2) / 4
    np.testing.assert_allclose((c * cw).sum(-1), metric, atol=1e-9)
    # every coordinate vector is a tangent vector: exp of it is a point
    back = manifold.from_coordinates(p, rng.standard_normal((7, manifold.intrinsic_dim)))
    manifold.validate(manifold.exp(p, 0.3 * back), atol=1e-8)


def test_intrinsic_dimensions():
    assert [m.intrinsic_dim for m in (Euclidean(3), Sphere(2), Quaternion(), SPD(3))] == [
        3, 2, 3, 6,
    ]  # fmt: skip
    assert Product((Euclidean(3), Quaternion())).intrinsic_dim == 6


def test_spd_coordinates_are_the_whitened_upper_triangle():
    """pyRiemann's ``upper`` of P^-1/2 V P^-1/2 (diagonal, sqrt(2) x the upper entries)."""
    M = SPD(3)
    p = M.random_point(random_state=0)
    v = M.random_tangent(p, 1.0, random_state=1)
    w, U = np.linalg.eigh(p)
    whitened = (U / np.sqrt(w)) @ U.T @ v @ (U / np.sqrt(w)) @ U.T
    rows, cols = np.triu_indices(3)
    expected = whitened[rows, cols] * np.where(rows == cols, 1.0, np.sqrt(2.0))
    np.testing.assert_allclose(M.to_coordinates(p, v), expected, atol=1e-12)


# --------------------------------------------------------------- statistics
def test_flat_statistics_are_the_ordinary_covariance(rng):
    aligned = rng.standard_normal((9, 20, 3)) * [1.0, 2.0, 0.5]
    stats = aligned_statistics(aligned=aligned, manifold=Euclidean(3), reg=0.0)
    np.testing.assert_allclose(stats.mean, aligned.mean(0), atol=1e-12)
    for z in (0, 7, 19):
        np.testing.assert_allclose(stats.covariance[z], np.cov(aligned[:, z], rowvar=False),
                                   atol=1e-12)  # fmt: skip
    assert stats.variance.shape == (20,)


@pytest.mark.parametrize("manifold", CURVED, ids=manifold_id)
def test_curved_statistics_are_the_covariance_of_logs_at_the_mean(manifold):
    data = make_warped_signals(manifold, 6, 30, 0, amplitude=0.8)
    result = align(data.signals, manifold=manifold, n_epochs=3, random_state=0)
    stats = aligned_statistics(result, reg=1e-6)
    assert stats.covariance.shape == (len(result.mean), manifold.intrinsic_dim,
                                      manifold.intrinsic_dim)  # fmt: skip
    for z in (0, len(result.mean) // 2, len(result.mean) - 1):
        logs = np.stack([manifold.log(result.mean[z], x) for x in result.aligned[:, z]])
        coords = manifold.to_coordinates(np.broadcast_to(result.mean[z], logs.shape), logs)
        expected = coords.T @ coords / (len(coords) - 1) + 1e-6 * np.eye(coords.shape[1])
        np.testing.assert_allclose(stats.covariance[z], expected, atol=1e-10)
    # the aligned series themselves are inside a wide tube
    inside = stats.mahalanobis(result.aligned) <= stats.tube(0.999).radius
    assert inside.mean() > 0.95


def test_samples_have_the_covariance_and_the_tube_its_coverage():
    S2 = Sphere(2)
    data = make_warped_signals(S2, 40, 25, 1, amplitude=0.6)
    noisy = S2.exp(data.signals, S2.random_tangent(data.signals, 0.05, random_state=4))
    result = dba_average(noisy, S2)  # a baseline's result works too
    stats = aligned_statistics(result)
    samples = stats.sample(4000, random_state=0)
    S2.validate(samples)
    base = np.broadcast_to(stats.mean, samples.shape)
    coords = S2.to_coordinates(base, S2.log(base, samples))
    for z in (3, 12):
        np.testing.assert_allclose(np.cov(coords[:, z], rowvar=False, bias=True),
                                   stats.covariance[z], rtol=0.1, atol=1e-4)  # fmt: skip
    # N - 1 = 39 > D = 2: the sampled tangent vectors are close to Gaussian
    tube = stats.tube(0.9)
    assert tube.radius == pytest.approx(np.sqrt(chi2.ppf(0.9, 2)))
    coverage = (stats.mahalanobis(samples) <= tube.radius).mean()
    assert coverage == pytest.approx(0.9, abs=0.03)
    # the half-widths are the radius times the principal standard deviations
    z = 5
    values = np.linalg.eigvalsh(stats.covariance[z])
    np.testing.assert_allclose(tube.half_widths[z], tube.radius * np.sqrt(values), rtol=1e-10)
    np.testing.assert_allclose(S2.norm(np.broadcast_to(stats.mean[z], tube.axes[z].shape),
                                       tube.axes[z]), 1.0, atol=1e-10)  # fmt: skip
    ring = tube.boundary(S2, 12)
    assert ring.shape == (len(stats.mean), 12, 3)
    S2.validate(ring)


def test_factor_statistics_of_a_pose():
    pose = Product((Euclidean(3), Quaternion()))
    data = make_warped_signals(pose, 5, 30, 2)
    stats = aligned_statistics(align(data.signals, manifold=pose, n_epochs=2, random_state=0))
    orientation = stats.factor(1)
    assert orientation.manifold == Quaternion() and orientation.covariance.shape[1:] == (3, 3)
    np.testing.assert_allclose(orientation.covariance, stats.covariance[:, 3:, 3:])
    Quaternion().validate(orientation.sample(3, random_state=0))
    with pytest.raises(IndexError):
        stats.factor(2)
    with pytest.raises(TypeError, match="Product"):
        orientation.factor(0)


def test_bad_inputs_of_the_statistics():
    E = Euclidean(1)
    with pytest.raises(ValueError, match="more than ddof"):
        aligned_statistics(aligned=np.zeros((1, 5, 1)), manifold=E)
    with pytest.raises(ValueError, match="shape"):
        aligned_statistics(aligned=np.zeros((3, 5)), manifold=E)
    with pytest.raises(TypeError, match="alignment result"):
        aligned_statistics(aligned=np.zeros((3, 5, 1)))
    with pytest.raises(ValueError, match="not a point"):
        aligned_statistics(aligned=np.ones((3, 5, 3)), manifold=Sphere(2))
    stats = aligned_statistics(aligned=np.random.default_rng(0).random((4, 5, 1)), manifold=E)
    with pytest.raises(ValueError, match="level"):
        stats.tube(1.5)
    with pytest.raises(ValueError, match="n_samples"):
        stats.sample(0)
    with pytest.raises(ValueError, match="shape"):
        stats.mahalanobis(np.zeros((2, 4, 1)))
    with pytest.raises(ValueError, match="entries"):
        E.from_coordinates(np.zeros((2, 1)), torch.zeros(2, 3))


def test_a_centroid_of_one_series_says_what_to_do():
    from sk_rtw import RTWNearestCentroid

    X = make_warped_signals("euclidean", 6, 30, random_state=0).signals
    y = np.array([0, 0, 0, 0, 0, 1])  # class 1: one series, its own centroid
    model = RTWNearestCentroid(n_centroids=1, dtw_window=None, method="dba").fit(X, y)
    single = model.alignments_[int(np.flatnonzero(model.centroid_classes_ == 1)[0])]
    with pytest.raises(ValueError, match=r"centroid of one training series.*ddof=0"):
        aligned_statistics(single)
    assert np.all(aligned_statistics(single, ddof=0, reg=0.0).covariance == 0.0)
