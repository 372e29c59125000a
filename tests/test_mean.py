"""The one weighted, batched Fréchet mean: its definition, and every caller agreeing on it."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import torch
from sklearn.exceptions import ConvergenceWarning

from sk_rtw import Euclidean, Sphere, align, aligned_statistics
from sk_rtw.baselines._dba import MEAN_STEPS, _matched_means
from sk_rtw.datasets import make_warped_signals
from sk_rtw.manifolds._mean import frechet_mean

from .conftest import MANIFOLDS, manifold_id

parametrize_manifolds = pytest.mark.parametrize("M", MANIFOLDS, ids=manifold_id)


def clustered(M, leading, seed, spread=0.3):
    """Points around one base point (so every mean converges well)."""
    base = M.random_point(random_state=seed)
    base = np.broadcast_to(base, (*leading, *M.point_shape))
    return M.exp(base, spread * M.random_tangent(base, random_state=seed + 1))


def weighted_objective(M, y, points, weights):
    return float((weights * M.dist(np.broadcast_to(y, points.shape), points) ** 2).sum())


@parametrize_manifolds
def test_the_mean_minimises_the_weighted_sum_of_squared_distances(M, rng):
    points = clustered(M, (9,), 3)
    weights = rng.uniform(0.2, 2.0, 9)
    mean = M.mean(points, weights)
    best = weighted_objective(M, mean, points, weights)
    for k in range(8):  # no nearby point does better (a property, not a reimplementation)
        other = M.exp(mean, 0.05 * M.random_tangent(mean, random_state=10 + k))
        assert weighted_objective(M, other, points, weights) >= best - 1e-12
    # the weighted tangent vectors at the mean sum to zero: the first-order condition
    logs = M.log(np.broadcast_to(mean, points.shape), points)
    gradient = (weights.reshape(-1, *[1] * M.point_ndim) * logs).sum(0)
    np.testing.assert_allclose(gradient, 0.0, atol=1e-8)


@parametrize_manifolds
def test_groups_in_one_call_equal_one_call_per_group(M, rng):
    points = clustered(M, (11, 3), 5)
    groups = np.array([2, 0, 1, 2, 0, 0, 1, 2, 2, 1, 0])
    weights = rng.uniform(0.5, 2.0, (11, 3))
    batch = M.mean(points, weights, groups=groups)
    for g in range(3):
        alone = M.mean(points[groups == g], weights[groups == g])
        np.testing.assert_allclose(batch[g], alone, rtol=0, atol=1e-14)  # to rounding


@parametrize_manifolds
def test_every_caller_computes_the_same_mean(M, rng):
    """Manifold.mean, the engine's returned mean, the statistics' default mean and DBA's
    update all come from one kernel: they agree on every manifold."""
    aligned = clustered(M, (5, 12), 7, spread=0.2)  # 5 aligned series of 12 samples
    expected = M.mean(aligned)
    # the statistics of an aligned set, mean not given
    stats = aligned_statistics(aligned=aligned, manifold=M)
    np.testing.assert_allclose(stats.mean, expected, atol=1e-9)
    # the kernel on tensors, one group per output time through the groups argument
    per_time = torch.as_tensor(np.swapaxes(aligned, 0, 1).reshape(60, *M.point_shape))
    codes = torch.as_tensor(np.repeat(np.arange(12), 5))
    kernel = frechet_mean(M, per_time, codes=codes, differentiate="none")
    np.testing.assert_allclose(kernel.numpy(), expected, atol=1e-9)
    # DBA's update: every sample of the average from the points matched to it
    series = [aligned[n] for n in range(5)]
    paths = [np.stack([np.arange(12), np.arange(12)], 1)] * 5
    start = aligned[0]
    dba = _matched_means(M, series, paths, start)
    same_steps = M.mean(per_time.numpy(), groups=codes.numpy(), start=start, max_iter=MEAN_STEPS,
                        tol=0.0)  # fmt: skip
    np.testing.assert_allclose(dba, same_steps, atol=1e-12)
    np.testing.assert_allclose(dba, expected, atol=1e-6)  # 8 steps from a close start


@pytest.mark.parametrize("M", [m for m in MANIFOLDS if m.point_shape in ((3,), (4,))],
                         ids=manifold_id)  # fmt: skip
def test_the_engines_mean_is_the_mean_of_its_aligned_series(M):
    data = make_warped_signals(M, 4, 25, random_state=1)
    result = align(data.signals, manifold=M, n_epochs=2, random_state=0)
    np.testing.assert_allclose(result.mean, M.mean(result.aligned), atol=1e-8)


def test_flat_means_are_exact_from_any_start_and_the_last_step_has_the_exact_gradient(rng):
    E = Euclidean(2)
    x = torch.as_tensor(rng.standard_normal((7, 4, 2)))
    codes = torch.as_tensor([1, 0, 1, 1, 0, 2, 1])
    w = torch.as_tensor(rng.uniform(0.5, 2.0, (7, 4)))
    flat = frechet_mean(E, x, w, codes, start=torch.full((3, 4, 2), 5.0))
    for g in range(3):
        idx = codes == g
        expected = (w[idx][..., None] * x[idx]).sum(0) / w[idx].sum(0)[..., None]
        torch.testing.assert_close(flat[g], expected)
    x.requires_grad_(True)
    (frechet_mean(E, x, w, codes, start=flat.detach(), differentiate="last") ** 2).sum().backward()
    grad_last = x.grad.clone()
    x.grad = None
    (frechet_mean(E, x, w, codes) ** 2).sum().backward()
    torch.testing.assert_close(grad_last, x.grad)


def test_the_last_step_gradient_matches_finite_differences_on_the_sphere():
    S = Sphere(2)
    points = torch.as_tensor(clustered(S, (6,), 11, spread=0.2))
    start = frechet_mean(S, points, differentiate="none")
    direction = torch.as_tensor(S.random_tangent(points.numpy(), random_state=3))

    def value(t):
        moved = S._exp(points, t * direction)
        return float(frechet_mean(S, moved, differentiate="none")[0, 0])

    points.requires_grad_(True)
    out = frechet_mean(S, points, start=start, max_iter=1, differentiate="last")[0, 0]
    out.backward()
    analytic = float((points.grad * direction).sum())
    numeric = (value(1e-6) - value(-1e-6)) / 2e-6
    assert analytic == pytest.approx(numeric, rel=0.05, abs=1e-6)


def test_one_warning_when_a_group_does_not_converge_and_none_for_a_fixed_budget():
    S = Sphere(2)
    spread = S.random_point(7, random_state=5)
    with pytest.warns(ConvergenceWarning, match="did not converge") as record:
        S.mean(np.stack([spread, spread]), axis=1, max_iter=2)
    assert len([w for w in record if w.category is ConvergenceWarning]) == 1
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        S.mean(spread, max_iter=2, tol=0.0)
        frechet_mean(S, torch.as_tensor(spread), max_iter=2, tol=0.0)


def _far_apart_spd6():
    """Three SPD(6) matrices whose log-eigenvalues spread over 4.6-6.8 units, in unrelated
    eigenbases: the full Gauss–Newton step still moves by 2.6 after 64 steps."""
    rng = np.random.default_rng(3)
    q, _ = np.linalg.qr(rng.standard_normal((3, 6, 6)))
    return (q * np.exp(rng.uniform(-6, 6, (3, 1, 6)))) @ np.swapaxes(q, 1, 2)


def _karcher_reference(points, step=0.2, n_iter=400):
    """The Karcher mean by short fixed steps (a contraction for these points), numpy."""

    def function(S, f):
        w, U = np.linalg.eigh(0.5 * (S + S.T))
        return (U * f(w)) @ U.T

    mean = points[0]
    for _ in range(n_iter):
        root, inverse = function(mean, np.sqrt), function(mean, lambda w: 1 / np.sqrt(w))
        tangent = np.mean([function(inverse @ p @ inverse, np.log) for p in points], axis=0)
        mean = root @ function(step * tangent, np.exp) @ root
    return mean


def test_far_apart_points_get_their_mean_where_the_full_step_cycles(monkeypatch):
    from sk_rtw.manifolds import SPD, _mean

    points = _far_apart_spd6()
    calls = []
    descend = _mean._descend
    monkeypatch.setattr(_mean, "_descend", lambda *a: calls.append(1) or descend(*a))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mean = np.asarray(SPD(6).mean(points, axis=0))
    assert calls, "the full Gauss–Newton steps converged: the case tests nothing"
    reference = _karcher_reference(points)
    np.testing.assert_allclose(mean, reference, rtol=0, atol=1e-8 * np.abs(reference).max())
    logs = np.asarray(SPD(6).log(np.broadcast_to(mean, points.shape), points))
    assert np.abs(logs.mean(0)).max() < 1e-9  # the first-order condition


def test_means_that_converge_never_take_the_line_searched_steps(monkeypatch):
    from sk_rtw.manifolds import SPD, Quaternion, _mean

    def refuse(*args):
        raise AssertionError("a converging mean took the fallback")

    monkeypatch.setattr(_mean, "_descend", refuse)
    rng = np.random.default_rng(4)
    for manifold in (SPD(3), Sphere(2), Quaternion()):
        centre = manifold.random_point(1, random_state=rng)
        steps = np.stack([manifold.random_tangent(centre[0], 0.3, random_state=rng)
                          for _ in range(12)])  # fmt: skip
        manifold.mean(np.asarray(manifold.exp(np.broadcast_to(centre, (12, *centre.shape[1:])),
                                              steps)), axis=0)  # fmt: skip


def test_bad_groups_weights_and_starts_are_named():
    S = Sphere(2)
    points = clustered(S, (6,), 2)
    with pytest.raises(ValueError, match=r"groups .* no sample"):
        S.mean(points, groups=[0, 0, 2, 2, 0, 2])
    with pytest.raises(ValueError, match="one entry per sample"):
        S.mean(points, groups=[0, 1])
    with pytest.raises(ValueError, match="in any group"):
        S.mean(points, [1, 1, 1, 0, 0, 0], groups=[0, 0, 0, 1, 1, 1])
    with pytest.raises(ValueError, match="start must have shape"):
        S.mean(points, start=np.ones(4) / 2)
