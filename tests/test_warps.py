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
