"""The warp models: the Householder basis, the paper's network, warps on knots, sine warps,
composition and the zero-readout start."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from sk_rtw.align._warps import (
    HouseholderBasis,
    NeuralWarps,
    SineWarps,
    resample_linear,
    unit_time,
)


# -------------------------------------------------------------------- warps
@pytest.mark.parametrize("n", [2, 3, 7, 30])
def test_householder_basis_is_orthonormal_with_constant_first_vector(n):
    basis = HouseholderBasis(n)
    Q = basis.matrix()
    np.testing.assert_allclose((Q.T @ Q).numpy(), np.eye(n), atol=1e-12)
    np.testing.assert_allclose(Q[:, 0].numpy(), np.full(n, 1 / np.sqrt(n)), atol=1e-12)
    c = torch.randn(5, n - 1, dtype=torch.float64)
    np.testing.assert_allclose(basis.combine(c).numpy(), (c @ Q[:, 1:].T).numpy(), atol=1e-12)


def test_neural_warps_match_the_paper_architecture():
    n = 6
    model = NeuralWarps(n, hidden=512, init="xavier")
    n_params = sum(p.numel() for p in model.parameters())
    assert n_params == 263680 + 1025 * (n - 1) + (n - 1)
    zhat = unit_time(50)
    raw = model(zhat).detach()
    np.testing.assert_array_equal(raw[:, 0].numpy(), 0.0)
    np.testing.assert_array_equal(raw[:, -1].numpy(), 1.0)
    np.testing.assert_allclose(raw.mean(0).numpy(), zhat.numpy(), atol=1e-12)  # mean warp
    assert raw.std(0).max() > 1e-3  # Xavier init breaks the symmetry
    zero = NeuralWarps(n, hidden=512, init="zeros")
    np.testing.assert_array_equal(zero(zhat).detach().numpy(), zhat.expand(n, -1).numpy())


def test_linear_resampling_equals_numpy_interp(rng):
    values = torch.as_tensor(rng.standard_normal((9, 3)))
    times = torch.as_tensor(np.concatenate([[0.0, 1.0], rng.uniform(0, 1, 40)]))
    knots = np.linspace(0, 1, 9)
    expected = np.stack([np.interp(times, knots, values[:, j]) for j in range(3)], axis=1)
    np.testing.assert_allclose(resample_linear(values, times).numpy(), expected, atol=1e-14)


def test_warps_on_knots_interpolate_the_network_between_them():
    torch.manual_seed(0)
    exact = NeuralWarps(5, hidden=32, init="xavier", knots=None)
    knotted = NeuralWarps(5, hidden=32, init="xavier", knots=11)
    knotted.load_state_dict(exact.state_dict())
    zhat = unit_time(101)
    at_knots = unit_time(11)
    # at the knot times both are the same function
    np.testing.assert_allclose(
        knotted.offsets(zhat)[:, ::10].detach().numpy(),
        exact.offsets(at_knots).detach().numpy(),
        atol=1e-14,
    )
    raw = knotted(zhat).detach()
    np.testing.assert_array_equal(raw[:, 0].numpy(), 0.0)  # boundary constraint exact
    np.testing.assert_array_equal(raw[:, -1].numpy(), 1.0)
    np.testing.assert_allclose(raw.mean(0).numpy(), zhat.numpy(), atol=1e-12)
    # at least as many knots as output times: the network at every output time
    full = NeuralWarps(5, hidden=32, init="xavier", knots=200)
    full.load_state_dict(exact.state_dict())
    np.testing.assert_array_equal(full(zhat).detach().numpy(), exact(zhat).detach().numpy())


def test_sine_warps_are_centred_monotone_and_exact_at_the_ends():
    model = SineWarps(5, n_components=4)
    with torch.no_grad():
        model.coefficients.copy_(torch.randn(5, 4, dtype=torch.float64))
    zhat = unit_time(80)
    raw = model(zhat).detach()
    np.testing.assert_allclose(raw.mean(0).numpy(), zhat.numpy(), atol=1e-12)
    warps = model.finalise(raw)
    assert torch.all(warps[:, 1:] >= warps[:, :-1])
    assert torch.all(warps[:, 0] == 0) and torch.all(warps[:, -1] == 1)

def test_zero_readout_init_starts_at_the_identity_with_diverse_hidden_units():
    model = NeuralWarps(4, hidden=16, init="zero-readout")
    zhat = unit_time(30)
    np.testing.assert_array_equal(model(zhat).detach().numpy(), zhat.expand(4, -1).numpy())
    assert model.w2.std() > 0
    weights = torch.randn(4, 30, generator=torch.Generator().manual_seed(0))
    (model(zhat) * weights).sum().backward()
    assert model.w3.grad.abs().sum() > 0


def test_a_single_precision_network_gives_float64_warps_close_to_double():
    zhat = torch.linspace(0.0, 1.0, 300, dtype=torch.float64)
    double = NeuralWarps(6, 32, "xavier", knots=40, seeds=[3])
    single = NeuralWarps(6, 32, "xavier", knots=40, seeds=[3], dtype=torch.float32)
    assert all(p.dtype == torch.float32 for p in single.parameters())
    # the same initial draws, rounded
    torch.testing.assert_close(single.w2.double(), double.w2, rtol=1e-7, atol=1e-7)
    warps = single(zhat)
    assert warps.dtype == torch.float64
    torch.testing.assert_close(warps, double(zhat), rtol=0, atol=1e-6)
    # the identity part stays exact: the ends are 0 and 1 in float64
    assert torch.equal(warps[:, 0], torch.zeros(6, dtype=torch.float64))
    assert torch.equal(warps[:, -1], torch.ones(6, dtype=torch.float64))
    warps.square().sum().backward()
    assert all(p.grad is not None and p.grad.dtype == torch.float32 for p in single.parameters())
    assert all(torch.isfinite(p.grad).all() for p in single.parameters())


@pytest.mark.parametrize("method", ["rtw", "ntw"])
def test_align_in_single_precision_matches_double_within_float32(method):
    from sk_rtw import align
    from sk_rtw.datasets import make_warped_signals

    data = make_warped_signals("euclidean", 8, 60, random_state=0)
    runs = {
        dtype: align(data.signals, method=method, n_epochs=30, random_state=0, warp_dtype=dtype)
        for dtype in ("float64", "float32")
    }
    single, double = runs["float32"], runs["float64"]
    assert single.config.warp_dtype == "float32" and double.config.warp_dtype == "float64"
    assert single.warps.dtype == np.float64 and single.mean.dtype == np.float64
    best = np.nanmin(double.loss_history)
    assert np.nanmin(single.loss_history) == pytest.approx(best, rel=1e-3)
    np.testing.assert_allclose(single.warps, double.warps, atol=1e-3)
