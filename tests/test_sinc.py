"""The interpolation's numerics: barycentric weights, the CPU kernel, chunks and tables."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

from sk_rtw.align import _sinc, tangent_sinc_interpolate
from sk_rtw.align._sinc import SincInterpolator, barycentric_weights
from sk_rtw.align._sinc_kernel import window_sums_parallel, window_sums_serial
from sk_rtw.datasets import make_warped_signals
from sk_rtw.manifolds import SPD, Euclidean, Product, Quaternion, Sphere

from .conftest import CURVED, MANIFOLDS, CurvedLookingEuclidean, interpolate

SPACES = [
    Euclidean(1),
    Euclidean(3),
    Sphere(1),
    Sphere(2),
    Quaternion(),
    SPD(2),
    Product((Euclidean(3), Quaternion())),
]


def collection(manifold, lengths=(40, 33, 12, 40), n_points=70, seed=0):
    """Padded series of unequal lengths and random sorted warps (ends included)."""
    signals = make_warped_signals(manifold, len(lengths), max(lengths), seed, amplitude=1.5)
    data = torch.as_tensor(np.asarray(signals.signals))
    rng = np.random.default_rng(seed)
    warps = np.sort(rng.uniform(0, 1, (len(lengths), n_points)), axis=1)
    warps[:, 0], warps[:, -1] = 0.0, 1.0
    if len(lengths) > 1 and lengths[1] == 33:
        warps[1, 7] = 10 / 32  # tau = 10 exactly: the centre tap alone
    return data, torch.tensor(lengths), torch.as_tensor(warps)


@pytest.mark.parametrize("frac", [0.0, 1e-13, 0.3, 0.5, 0.999999])
def test_barycentric_weights_are_the_normalised_sinc(frac):
    k = torch.arange(-10, 11, dtype=torch.float64)
    weights, derivatives = barycentric_weights(k, torch.tensor([frac]))
    expected = np.sinc(k.numpy() - frac)
    np.testing.assert_allclose(
        (weights / weights.sum()).numpy()[0], expected / expected.sum(), atol=1e-12
    )
    eps = 1e-7
    if frac < 0.99:  # the derivative by central differences (near f = 1 it is ~1/(1-f)^2)
        up, _ = barycentric_weights(k, torch.tensor([frac + eps]))
        down, _ = barycentric_weights(k, torch.tensor([max(frac - eps, 0.0)]))
        step = frac + eps - max(frac - eps, 0.0)
        np.testing.assert_allclose(
            derivatives.numpy(), ((up - down) / step).numpy(), rtol=1e-5, atol=1e-5
        )


@pytest.mark.parametrize("manifold", SPACES, ids=repr)
@pytest.mark.parametrize("window", [10, 2, None])
@pytest.mark.parametrize("refinements", [0, 2])
def test_cpu_kernel_equals_the_torch_path(manifold, window, refinements):
    data, lengths, warps = collection(manifold)
    interpolator = SincInterpolator(manifold, data, lengths, window, refinements)
    base, frac = interpolator.positions(warps)
    anchors = None if manifold.is_flat else interpolator.anchors(base, frac)
    kernel = interpolator.window_sums(base, frac, anchors)  # CPU: the numba kernel
    reference = (torch.empty_like(kernel[0]), torch.empty_like(kernel[1]))
    interpolator._window_sums_torch(base, frac, anchors, *reference)
    for got, expected in zip(kernel, reference, strict=True):
        np.testing.assert_allclose(got.numpy(), expected.numpy(), rtol=1e-10, atol=1e-11)


def test_parallel_kernel_equals_the_serial_one():
    rng = np.random.default_rng(1)
    values = rng.standard_normal((7, 50, 21, 3))
    base = rng.integers(0, 50, (7, 90))
    frac = rng.uniform(0, 1, (7, 90))
    lengths = np.full(7, 50)
    outputs = []
    for kernel in (window_sums_serial, window_sums_parallel):
        u, du = np.empty((7, 90, 3)), np.empty((7, 90, 3))
        kernel(values, base, base, frac, lengths, 10, u, du)
        outputs.append((u, du))
    np.testing.assert_array_equal(outputs[0][0], outputs[1][0])
    np.testing.assert_array_equal(outputs[0][1], outputs[1][1])


@pytest.mark.parametrize("manifold", MANIFOLDS, ids=repr)
@pytest.mark.parametrize("window", [10, None])
def test_chunks_and_table_budget_do_not_change_the_result(manifold, window, monkeypatch):
    data, lengths, warps = collection(manifold)
    whole = SincInterpolator(manifold, data, lengths, window)(warps)
    monkeypatch.setattr(_sinc, "CHUNK_ELEMENTS", 50)  # many chunks
    monkeypatch.setattr(_sinc, "table_budget", lambda device: 0)  # no precomputed table
    interpolator = SincInterpolator(manifold, data, lengths, window)
    assert interpolator.table is None
    np.testing.assert_allclose(interpolator(warps).numpy(), whole.numpy(), atol=1e-13)
    base, frac = interpolator.positions(warps)
    anchors = None if manifold.is_flat else interpolator.anchors(base, frac)
    u, du = torch.empty(2, *warps.shape, interpolator.point_size)
    interpolator._window_sums_torch(base, frac, anchors, u, du)  # chunked torch path too
    reference = interpolator.window_sums(base, frac, anchors)
    np.testing.assert_allclose(u.numpy(), reference[0].numpy(), atol=1e-12)


@pytest.mark.parametrize("manifold", MANIFOLDS, ids=repr)
@pytest.mark.parametrize("window", [10, None])
def test_gradient_without_refinement_matches_finite_differences(manifold, window):
    """Without refinement the chart is fixed per window: the derivative is exact."""
    data, lengths, _ = collection(manifold, lengths=(25,), n_points=6)
    warps = torch.tensor([[0.01, 0.13, 0.371, 0.52, 0.8666, 0.995]])
    interpolator = SincInterpolator(manifold, data, lengths, window, refinements=0)
    jacobian = torch.autograd.functional.jacobian(interpolator, warps)
    eps = 1e-6
    finite = torch.zeros_like(jacobian)
    for z in range(warps.shape[1]):
        step = torch.zeros_like(warps)
        step[0, z] = eps
        finite[..., 0, z] = (interpolator(warps + step) - interpolator(warps - step)) / (2 * eps)
    assert finite.abs().max() > 0.1
    assert (jacobian - finite).abs().max() / finite.abs().max() < 1e-7


def test_refinement_changes_interpolated_points_by_a_tiny_fraction_of_a_sample():
    """The documented default: the centre sample as tangent point is as good as the
    refined one, to a small fraction of the sample spacing on a smooth S^2 signal."""
    M = Sphere(2)
    data, lengths, warps = collection(M, lengths=(100, 100), n_points=300)
    plain = SincInterpolator(M, data, lengths, 10, refinements=0)(warps).numpy()
    refined = SincInterpolator(M, data, lengths, 10, refinements=3)(warps).numpy()
    spacing = np.median(M.dist(data[:, 1:].numpy(), data[:, :-1].numpy()))
    difference = M.dist(plain, refined)
    assert np.median(difference) < 1e-3 * spacing
    assert difference.max() < 5e-2 * spacing
    assert difference.max() > 0  # the two charts are not the same computation


def test_nan_warps_give_nan_points_not_an_index_error():
    data, lengths, warps = collection(Sphere(2))
    warps[0, 3] = float("nan")
    out = SincInterpolator(Sphere(2), data, lengths)(warps)
    assert torch.isnan(out[0, 3]).all()
    assert torch.isfinite(out[1:]).all()


def test_the_table_may_take_an_eighth_of_the_free_memory_on_the_cpu(monkeypatch):
    monkeypatch.setattr(_sinc, "available_memory", lambda: 64 * 2**30)
    assert _sinc.table_budget(torch.device("cpu")) == 8 * 2**30
    monkeypatch.setattr(_sinc, "available_memory", lambda: 2**30)
    assert _sinc.table_budget(torch.device("cpu")) == _sinc.TABLE_BYTES
    assert _sinc.table_budget(torch.device("meta")) == _sinc.TABLE_BYTES  # not host memory


def reference_windowed_sinc(x, positions, window):
    """Normalised windowed sinc with clamped indices, written with plain loops."""
    out = []
    T = len(x)
    for tau in positions:
        base = math.floor(tau)
        num, den = 0.0, 0.0
        for k in range(-window, window + 1):
            m = min(max(base + k, 0), T - 1)
            s = np.sinc(base + k - tau)
            num, den = num + s * x[m], den + s
        out.append(num / den)
    return np.array(out)


# ------------------------------------------------------------ interpolation
@pytest.mark.parametrize("manifold", MANIFOLDS, ids=repr)
@pytest.mark.parametrize("window", [10, 3, None])
def test_integer_positions_return_the_samples(manifold, window):
    x = make_warped_signals(manifold, 1, 30, 0).original
    warps = np.linspace(0, 1, 30)  # tau = 0, 1, ..., 29
    np.testing.assert_allclose(interpolate(manifold, x, warps, window), x, atol=1e-9)


@pytest.mark.parametrize("window", [10, 2, None])
def test_euclidean_equals_plain_windowed_sinc(window, rng):
    x = rng.standard_normal(40)
    warps = np.sort(rng.uniform(0, 1, 25))
    full = window if window is not None else 40
    expected = reference_windowed_sinc(x, warps * 39, full)
    if window is None:  # full sinc: only real samples, no clamped repeats
        expected = np.array(
            [
                (np.sinc(np.arange(40) - t) @ x) / np.sinc(np.arange(40) - t).sum()
                for t in warps * 39
            ]
        )
    got = interpolate(Euclidean(1), x[:, None], warps, window)[:, 0]
    np.testing.assert_allclose(got, expected, atol=1e-12)


def test_band_limited_signal_is_reconstructed_between_samples():
    t = np.arange(64)
    x = np.sin(2 * np.pi * 3 * t / 64)
    positions = np.linspace(20, 44, 97)  # interior, away from the clamped ends
    got = interpolate(Euclidean(1), x[:, None], positions / 63)[:, 0]
    np.testing.assert_allclose(got, np.sin(2 * np.pi * 3 * positions / 64), atol=5e-3)


def test_manifold_path_equals_euclidean_special_case(rng):
    x = rng.standard_normal((30, 3))
    warps = np.sort(rng.uniform(0, 1, 50))
    flat = interpolate(Euclidean(3), x, warps)
    general = interpolate(CurvedLookingEuclidean(3), x, warps, refinements=3)
    np.testing.assert_allclose(general, flat, atol=1e-12)


# The tangent-point refinement runs without gradient tracking (it is a choice of chart),
# so the autograd derivative is exact for flat spaces and S^1 and within a fraction of a
# percent elsewhere (the refinement contracts by ~100x per step).
@pytest.mark.parametrize("manifold", MANIFOLDS, ids=repr)
def test_interpolation_gradient_matches_finite_differences(manifold):
    rtol = 1e-7 if manifold.is_flat or manifold == Sphere(1) else 1e-2
    x = torch.as_tensor(make_warped_signals(manifold, 1, 25, 1, amplitude=2.0).original)[None]
    # non-integer positions: at integer ones the windowed kernel has a kink (a tap enters
    # the window with zero weight but non-zero slope), so one-sided derivatives differ
    warps = torch.tensor([[0.01, 0.13, 0.371, 0.52, 0.8666, 0.995]], dtype=torch.float64)

    def f(w):
        return tangent_sinc_interpolate(manifold, x, torch.tensor([25]), w, 10, 2)

    jacobian = torch.autograd.functional.jacobian(f, warps)
    finite = torch.zeros_like(jacobian)
    eps = 1e-6
    for z in range(warps.shape[1]):
        step = torch.zeros_like(warps)
        step[0, z] = eps
        finite[..., 0, z] = (f(warps + step) - f(warps - step)) / (2 * eps)
    error = (jacobian - finite).abs().max() / finite.abs().max()
    assert error < rtol, float(error)
    assert finite.abs().max() > 0.1  # the test looks at a real slope


@pytest.mark.parametrize("manifold", CURVED, ids=repr)
def test_interpolated_point_balances_the_weighted_window(manifold):
    """The refined tangent point is the weighted Fréchet mean of the window:
    ``sum_m s_m Log_x(x_m) = 0`` (within the Gauss–Newton tolerance after 2 refinements)."""
    x = make_warped_signals(manifold, 1, 30, 3, amplitude=2.0).original
    w = np.random.default_rng(0).uniform(0.05, 0.95, 40)
    out = interpolate(manifold, x, w, 10, refinements=2)
    tau = w * 29
    base = np.floor(tau)
    k = np.arange(-10, 11)
    idx = np.clip(base[:, None] + k, 0, 29).astype(int)
    s = np.sinc(k - (tau - base)[:, None])
    s /= s.sum(1, keepdims=True)
    residual = (
        s.reshape(*s.shape, *([1] * manifold.point_ndim)) * manifold.log(out[:, None], x[idx])
    ).sum(1)
    assert np.abs(residual).max() < 1e-5


def test_interpolated_sphere_points_stay_on_the_sphere():
    x = make_warped_signals("sphere", 1, 30, 2, dim=2).original
    out = interpolate(Sphere(2), x, np.random.default_rng(0).uniform(0, 1, 200))
    np.testing.assert_allclose(np.linalg.norm(out, axis=-1), 1.0, atol=1e-12)


def test_series_shorter_than_the_window_are_clamped(rng):
    x = rng.standard_normal((4, 1))
    out = interpolate(Euclidean(1), x, np.linspace(0, 1, 13))
    assert np.all(np.isfinite(out))
    np.testing.assert_allclose(out[[0, -1]], x[[0, -1]], atol=1e-12)
