"""The DTW start: path warps, their smoothing and centring, the start of a fit, given
starting warps, and the compiled pass that reads many pairs' paths."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from sk_rtw.align import align
from sk_rtw.datasets import make_warped_signals
from sk_rtw.metrics import alignment_quality


# ----------------------------------------------------- starts and presets
def test_path_warp_is_the_mean_matched_position():
    from sk_rtw.align._start import path_warp

    path = np.array([[0, 0], [1, 1], [1, 2], [1, 3], [2, 4], [3, 4], [4, 5]])
    expected = np.array([0.0, 2.0, 4.0, 4.0, 5.0]) / 5
    np.testing.assert_allclose(path_warp(path, 5, 6, smoothing=0), expected)


def test_smoothed_path_warps_stay_monotone_from_zero_to_one(rng):
    from sk_rtw.align._start import path_warp

    matched = np.sort(rng.integers(0, 80, 60))  # a staircase with flat and steep parts
    matched[0], matched[-1] = 0, 79
    path = np.stack([np.arange(60), matched], axis=1)
    raw, smooth = path_warp(path, 60, 80, 0), path_warp(path, 60, 80, 2.0)
    assert smooth[0] == 0.0 and smooth[-1] == 1.0
    assert np.all(np.diff(smooth) >= 0)
    assert np.abs(np.diff(smooth, 2)).max() < np.abs(np.diff(raw, 2)).max()  # fewer corners
    assert np.abs(smooth - raw).max() < 5 / 79  # within a few samples of the path
    short = path_warp(np.array([[0, 0], [1, 2], [2, 2], [3, 3], [4, 4]]), 5, 5, 2.0)
    assert short.shape == (5,) and short[0] == 0.0 and short[-1] == 1.0  # radius > length
    assert np.all(np.diff(short) >= 0)


def test_centred_warps_average_to_the_identity(rng):
    from sk_rtw.align._start import centred_warps

    raw = np.sort(rng.uniform(0, 1, (5, 40)), axis=1)
    raw[:, 0], raw[:, -1] = 0.0, 1.0
    warps = centred_warps(raw, 73)
    np.testing.assert_allclose(warps.mean(0), np.linspace(0, 1, 73), atol=1e-6)
    assert np.all(np.diff(warps, axis=1) >= -1e-12)
    # the same common time change for every series: pairwise relations are kept
    grid = np.linspace(0, 1, 40)
    times = np.interp(warps[0], raw[0], grid)  # reference time of every output time
    np.testing.assert_allclose(warps[1], np.interp(times, grid, raw[1]), atol=1e-6)


def test_compose_warps_equals_numpy_interp(rng):
    from sk_rtw.align._warps import compose_warps

    outer = np.sort(rng.uniform(0, 1, (3, 11)), axis=1)
    inner = rng.uniform(0, 1, (3, 30))
    got = compose_warps(torch.as_tensor(outer), torch.as_tensor(inner)).numpy()
    grid = np.linspace(0, 1, 11)
    expected = np.stack([np.interp(i, grid, o) for o, i in zip(outer, inner, strict=True)])
    np.testing.assert_allclose(got, expected, atol=1e-14)


@pytest.mark.parametrize("manifold", ["euclidean", "sphere", "quaternion", "spd"])
def test_dtw_start_aligns_before_any_training(manifold):
    data = make_warped_signals(manifold, 6, 60, 3, strength=0.9)
    M = data.manifold
    start = align(data.signals, manifold=M, warp_start="dtw", n_epochs=0, random_state=0)
    plain = align(data.signals, manifold=M, warp_start="identity", n_epochs=0, random_state=0)
    assert start.config.warp_start == "dtw"
    good = alignment_quality(start.aligned, start.mean, M)
    bad = alignment_quality(plain.aligned, plain.mean, M)
    assert good < bad / 3, (good, bad)
    np.testing.assert_allclose(start.warps.mean(0), np.linspace(0, 1, 240), atol=1e-6)


def test_identical_series_get_identity_starting_warps():
    x = make_warped_signals("sphere", 1, 40, 1).original
    result = align(
        np.stack([x, x, x]), manifold="sphere", n_epochs=0, output_length=40, random_state=0
    )
    np.testing.assert_allclose(result.warps, np.tile(np.linspace(0, 1, 40), (3, 1)), atol=1e-9)
    np.testing.assert_allclose(result.mean, x, atol=1e-9)


def test_given_starting_warps_are_used_and_checked(rng):
    data = make_warped_signals("euclidean", 3, 30, 2)
    warps = np.stack([np.linspace(0, 1, 45) ** p for p in (0.9, 1.0, 1.1)])
    result = align(data.signals, warp_start=warps, n_epochs=0, random_state=0)
    assert result.config.warp_start == "given" and result.config.output_length == 45
    np.testing.assert_allclose(result.warps, warps, atol=1e-12)  # zero-readout: start kept
    with pytest.raises(ValueError, match="shape"):
        align(data.signals, warp_start=warps[:2])
    with pytest.raises(ValueError, match="non-decreasing"):
        align(data.signals, warp_start=warps[:, ::-1])
    with pytest.raises(ValueError, match="from 0 to 1"):
        align(data.signals, warp_start=0.5 * warps)
    with pytest.raises(ValueError, match="output_length"):
        align(data.signals, warp_start=warps, output_length=30)
    with pytest.raises(ValueError, match="warp_start"):
        align(data.signals, warp_start="medoid")


def test_training_from_the_dtw_start_never_ends_above_it():
    data = make_warped_signals("sphere", 5, 50, 4)
    result = align(data.signals, manifold="sphere", n_epochs=40, random_state=0)
    assert result.loss_history[result.best_epoch] <= result.loss_history[0]
    assert np.all(np.diff(result.warps, axis=1) >= -1e-9)  # composition stays monotone

@pytest.mark.parametrize("manifold", ["euclidean", "quaternion", "spd"])
@pytest.mark.parametrize("window", [None, 0.2])
def test_the_dtw_starts_path_warps_are_those_of_each_pairs_path(manifold, window):
    """The DTW start reads the warps of the exact pairs off one compiled pass; they equal,
    value for value, path_warp of each pair's path (multiscale_path without a band,
    path_indices in one), with groups of unequal reference lengths, and the smoothing
    equals np.pad's odd reflection."""
    from sk_rtw.align._start import _path_warps, _smooth_monotone, path_warp
    from sk_rtw.dtw import multiscale_path, path_indices

    data = make_warped_signals(manifold, 5, 50, 3, strength=0.9)
    M, series = data.manifold, [s[: 50 - 3 * n] for n, s in enumerate(data.signals)]
    references = [data.signals[0][:44], data.signals[1][::2]]
    codes = np.array([0, 1, 0, 1, 1])
    stacked = np.zeros((5, 50, int(np.prod(series[0].shape[1:]))))
    for n, s in enumerate(series):
        stacked[n, : len(s)] = s.reshape(len(s), -1)
    lengths = np.array([len(s) for s in series])
    got = _path_warps(references, series, (stacked, lengths), codes, M, window, None)
    for n, s in enumerate(series):
        reference = references[codes[n]]
        if window is None:
            path = multiscale_path(reference, s, M, squared=True)[0]
        else:
            path = path_indices(reference, s, M, window, squared=True)[0]
        np.testing.assert_array_equal(got[n], path_warp(path, len(reference), len(s)))
    warp = np.sort(np.random.default_rng(0).random(9))
    for sigma in (0.7, 2.0, 5.0):  # radius 3, 6 and capped at len - 1
        radius = min(int(np.ceil(3 * sigma)), 8)
        kernel = np.exp(-0.5 * (np.arange(-radius, radius + 1) / sigma) ** 2)
        smooth = np.convolve(np.pad(warp, radius, mode="reflect", reflect_type="odd"),
                             kernel / kernel.sum(), mode="valid")  # fmt: skip
        smooth = np.maximum.accumulate(
            np.clip((smooth - smooth[0]) / (smooth[-1] - smooth[0]), 0.0, 1.0)
        )
        np.testing.assert_array_equal(_smooth_monotone(warp, sigma), smooth)


def test_long_pairs_give_the_same_start_and_medoid_on_two_threads():
    """Pairs solved coarse to fine one by one (8 x 4 = 32 times the series' length in
    cells, over the exact limit) and the medoid's guide bounds run on threads when the fit
    has several: the same starting warps bit for bit, and the same pairwise distances."""
    from sk_rtw import dtw_pairwise_distance
    from sk_rtw.align._layout import GroupLayout
    from sk_rtw.align._start import dtw_start
    from sk_rtw.dtw import solved_exactly
    from sk_rtw.utils import check_series_collection

    X = np.asarray(make_warped_signals("quaternion", 4, 1100, random_state=1).signals)
    assert not solved_exactly(1100, 4 * 1100) and not solved_exactly(1100, 1100)
    collection = check_series_collection(X, "quaternion")
    layout = GroupLayout.from_codes(torch.zeros(4, dtype=torch.long))

    def start(n_threads):
        return dtw_start(collection, layout, 4 * 1100, 2,
                         lambda warps: torch.as_tensor(np.repeat(X[:1], 4, axis=1)),
                         [np.random.default_rng(0)], n_threads=n_threads)  # fmt: skip

    np.testing.assert_array_equal(start(2), start(1))
    np.testing.assert_array_equal(
        dtw_pairwise_distance(X, manifold="quaternion", squared=True, n_jobs=2),
        dtw_pairwise_distance(X, manifold="quaternion", squared=True, n_jobs=1),
    )
