"""Soft-DTW and the soft-DTW barycentre refinement, against independent references."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from sk_rtw import dtw_pairwise_distance
from sk_rtw.align._refine import refine_mean
from sk_rtw.dtw._kernels import accumulated_cost
from sk_rtw.dtw._soft import soft_dtw, soft_dtw_batch

from .conftest import MANIFOLDS, manifold_id
from .test_dtw import random_walk


def torch_soft_dtw(cost: torch.Tensor, gamma: float) -> torch.Tensor:
    """The recursion written with torch (autograd gives the reference gradient)."""
    m, n = cost.shape
    inf = torch.tensor(float("inf"), dtype=cost.dtype)
    R = [[inf] * (n + 1) for _ in range(m + 1)]
    R[0][0] = torch.zeros((), dtype=cost.dtype)
    for i in range(1, m + 1):
        for j in range(1, n + 1):
            previous = torch.stack([R[i - 1][j - 1], R[i - 1][j], R[i][j - 1]])
            R[i][j] = cost[i - 1, j - 1] - gamma * torch.logsumexp(-previous / gamma, 0)
    return R[m][n]


@pytest.mark.parametrize(("m", "n", "gamma"), [(5, 7, 1.0), (8, 6, 0.1), (11, 11, 0.01)])
def test_value_and_gradient_match_autograd(m, n, gamma, rng):
    cost = torch.tensor(rng.uniform(0, 2, (m, n)), requires_grad=True)
    reference = torch_soft_dtw(cost, gamma)
    reference.backward()
    value, E = soft_dtw(cost.detach().numpy(), gamma, -1.0)
    assert value == pytest.approx(reference.item(), rel=1e-12)
    np.testing.assert_allclose(E, cost.grad.numpy(), atol=1e-12)


def test_small_gamma_is_hard_dtw_and_the_alignment_its_path(rng):
    cost = rng.uniform(0, 2, (30, 25))
    value, E = soft_dtw(cost, 1e-4, -1.0)
    assert value == pytest.approx(accumulated_cost(cost, -1.0)[-1, -1], rel=1e-6)
    assert set(np.unique(np.round(E, 6))) <= {0.0, 1.0}  # the indicator of one path
    assert E[0, 0] == pytest.approx(1.0) and E[-1, -1] == pytest.approx(1.0)


def test_a_band_excludes_its_outside_and_batches_equal_single_calls(rng):
    costs = rng.uniform(0, 2, (3, 20, 24))
    values, E = soft_dtw_batch(costs, np.array([20, 15, 20]), np.array([24, 24, 11]), 0.3, 0.2)
    for k, (m, n) in enumerate(((20, 24), (15, 24), (20, 11))):
        value, e = soft_dtw(costs[k, :m, :n], 0.3, 0.2)
        assert values[k] == value
        np.testing.assert_array_equal(E[k, :m, :n], e)
        assert E[k, m:].sum() == 0 and E[k, :, n:].sum() == 0
    banded = E[0]
    assert banded[0, -1] == 0 and banded[-1, 0] == 0 and banded.sum(1).min() >= 1 - 1e-12


@pytest.mark.parametrize("M", MANIFOLDS, ids=manifold_id)
def test_refinement_never_raises_the_dtw_cost_and_stays_on_the_manifold(M):
    series = [random_walk(M, length, seed) for seed, length in enumerate((18, 22, 20, 19))]
    start = series[0]
    refined = refine_mean(series, start, M, steps=1, gammas=(0.3, 0.03))
    M.validate(refined.mean, atol=1e-8)
    assert refined.mean.shape == start.shape and refined.steps == 2
    cost = dtw_pairwise_distance(series, refined.mean[None], M, squared=True).sum()
    assert cost == pytest.approx(refined.cost, rel=1e-10)
    assert refined.cost <= refined.start_cost + 1e-12


def test_the_refined_mean_lowers_the_dtw_cost_below_the_medoids(rng):
    """A class of time-shifted bumps: from one member, the soft-DTW steps find a mean
    closer (in squared-cost DTW) to every member than any member is."""
    t = np.linspace(0, 1, 40)
    series = [np.exp(-((t - c) ** 2) / 0.005)[:, None] + 0.05 * rng.standard_normal((40, 1))
              for c in (0.35, 0.45, 0.5, 0.55, 0.65)]  # fmt: skip
    E = MANIFOLDS[0]
    refined = refine_mean(series, series[0], E, steps=3)
    pairwise = dtw_pairwise_distance(series, squared=True).sum(1)
    assert refined.cost < pairwise.min()


def test_the_engines_refine_steps_lower_the_dtw_cost_of_the_returned_mean():
    from sk_rtw import RTW, RTWAverager, Sphere, align
    from sk_rtw.datasets import make_warped_signals

    S = Sphere(1)
    X = make_warped_signals(S, 5, 30, random_state=0).signals
    plain = align(X, manifold=S, n_epochs=3, random_state=0)
    refined = align(X, manifold=S, n_epochs=3, refine_steps=2, random_state=0)
    assert refined.config.refine_steps == 2
    cost = [
        dtw_pairwise_distance(X, r.mean[None], S, squared=True).sum() for r in (plain, refined)
    ]
    assert cost[1] < cost[0]
    # warps and aligned series describe the returned mean: each series along its DTW path
    assert np.all(np.diff(refined.warps, axis=1) >= 0) and refined.warps[:, -1].min() == 1.0
    to_mean = [S.dist(r.aligned, r.mean[None]).mean() for r in (plain, refined)]
    assert to_mean[1] < S.dist(plain.aligned, refined.mean[None]).mean()
    S.validate(refined.mean)
    clf = RTWAverager(manifold=S, method=RTW(n_epochs=3, refine_steps=1)).fit(X)
    assert clf.alignments_[0].config.refine_steps == 1
