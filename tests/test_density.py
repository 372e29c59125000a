"""Density-weighted means: the stretch representatives and their gradients."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from sk_rtw.align import align, tangent_sinc_interpolate
from sk_rtw.datasets import make_warped_signals
from sk_rtw.manifolds import Euclidean, Sphere

from .conftest import CURVED


# ------------------------------------------------------------ density-weighted means
def _density(manifold, series, warps):
    from sk_rtw.align._density import density_representatives

    t_max = max(len(s) for s in series)
    padded = [np.concatenate([s, np.repeat(s[-1:], t_max - len(s), 0)]) for s in series]
    data = torch.as_tensor(np.stack(padded))
    lengths = torch.as_tensor([len(s) for s in series])
    warps = torch.as_tensor(warps)
    aligned = tangent_sinc_interpolate(manifold, data, lengths, warps)
    v, w = density_representatives(manifold, data, lengths, warps, aligned)
    return v, w, aligned


def test_density_representatives_average_the_samples_each_output_time_covers(rng):
    """Euclidean: every representative is the count-weighted average of its stretch
    (samples inside it, topped up to one sample with the aligned point)."""
    from sk_rtw.align._density import HALF_WIDTH

    E = Euclidean(2)
    series = [rng.standard_normal((37, 2)), rng.standard_normal((23, 2))]
    z = np.linspace(0, 1, 30)
    warps = np.stack([z**1.7, np.sqrt(z)])  # compressed and stretched parts
    v, w, aligned = _density(E, series, warps)
    for n, s in enumerate(series):
        tau = warps[n] * (len(s) - 1)
        bounds = np.concatenate([[-0.5], (tau[:-1] + tau[1:]) / 2, [len(s) - 0.5]])
        for k in range(len(z)):
            lo, hi = bounds[k], bounds[k + 1]
            i = np.arange(len(s))
            mass = np.clip(np.minimum(i + HALF_WIDTH, hi) - np.maximum(i - HALF_WIDTH, lo),
                           0, None) / (2 * HALF_WIDTH)  # fmt: skip
            count = max(mass.sum(), 1.0)
            expected = (mass @ s + (count - mass.sum()) * aligned[n, k].numpy()) / count
            np.testing.assert_allclose(v[n, k].numpy(), expected, atol=1e-12)
            assert w[n, k].item() == pytest.approx(count)
        assert w[n].sum() >= len(s) - 1e-9  # every sample counted once, empty stretches once


def test_density_mean_from_dtw_runs_is_dbas_update(rng):
    """A DTW path matching every mean sample to its own run of series samples: warps read
    off it (no smoothing) give stretches equal to the runs, and the density-weighted mean
    equals DBA's update, the average of every matched sample."""
    from sk_rtw.align._start import path_warp
    from sk_rtw.manifolds._mean import frechet_mean

    E = Euclidean(3)
    n_mean = 25
    series, paths = [], []
    for _ in range(4):
        # runs of 1 to 5 samples whose neighbours differ by at most one, one at the ends
        walk = np.clip(np.cumsum(rng.integers(-1, 2, n_mean)) + 3, 1, 5)
        edge = np.minimum(np.arange(1, n_mean + 1), np.arange(n_mean, 0, -1))
        runs = np.minimum(walk, edge).tolist()
        starts = np.concatenate([[0], np.cumsum(runs)[:-1]])
        series.append(rng.standard_normal((sum(runs), 3)))
        paths.append(np.array([(m, j) for m, (a, r) in enumerate(zip(starts, runs, strict=True))
                               for j in range(a, a + r)]))  # fmt: skip
    warps = np.stack(
        [path_warp(p, n_mean, len(s), smoothing=0) for p, s in zip(paths, series, strict=True)]
    )
    v, w, _ = _density(E, series, warps)
    mean = frechet_mean(E, v, w)[0].numpy()
    sums, counts = np.zeros((n_mean, 3)), np.zeros(n_mean)
    for p, s in zip(paths, series, strict=True):
        np.add.at(sums, p[:, 0], s[p[:, 1]])
        np.add.at(counts, p[:, 0], 1)
    np.testing.assert_allclose(mean, sums / counts[:, None], atol=1e-12)


@pytest.mark.parametrize("manifold", CURVED, ids=repr)
def test_density_representatives_on_curved_manifolds(manifold):
    """Curved spaces: a stretch of one sample gives that sample back; a stretch of many
    gives the tangent-space average at the aligned point (an independent loop here), on
    the manifold."""
    data = make_warped_signals(manifold, 2, 30, 3)
    series = list(data.signals)
    z = np.linspace(0, 1, 20)
    warps = np.stack([z**3.0, z])
    v, w, aligned = _density(manifold, series, warps)
    manifold.validate(v.numpy(), atol=1e-8)
    tau = warps[0] * 29
    bounds = np.concatenate([[-0.5], (tau[:-1] + tau[1:]) / 2, [29.5]])
    k = int(np.argmax(w[0].numpy()))  # the compressed end: a stretch of many samples
    inside = np.flatnonzero((np.arange(30) > bounds[k]) & (np.arange(30) < bounds[k + 1]))
    assert len(inside) > 3 and w[0, k].item() == pytest.approx(len(inside))
    anchor = aligned[0, k].numpy()
    logs = np.stack([manifold.log(anchor, series[0][i]) for i in inside])
    np.testing.assert_allclose(v[0, k].numpy(), manifold.exp(anchor, logs.mean(0)), atol=1e-10)
    # the identity warp of a series of 20 samples at 20 output times: one sample each
    same = np.linspace(0, 1, 20)
    v1, w1, _ = _density(manifold, [series[1][:20]], same[None])
    np.testing.assert_allclose(w1.numpy(), 1.0)
    np.testing.assert_allclose(v1[0].numpy(), series[1][:20], atol=1e-10)


def test_density_weighted_alignment_and_its_gradient():
    data = make_warped_signals("sphere", 5, 40, 2)
    result = align(data.signals, manifold="sphere", mean_weights="density", n_epochs=20,
                   random_state=0)  # fmt: skip
    assert result.config.mean_weights == "density"
    Sphere(1).validate(result.mean)
    assert np.nanmin(result.loss_history) <= result.loss_history[0]
    with pytest.raises(ValueError, match="mean_weights"):
        align(data.signals, mean_weights="counts")
