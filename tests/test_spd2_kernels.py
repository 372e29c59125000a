"""The compiled SPD(2) maps (sk_rtw.manifolds._spd2_kernels) against the torch closed
forms they compile (values and autograd gradients, in every branch of the formulas), and
their hand-written gradients against finite differences."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from sk_rtw.manifolds import _spd2
from sk_rtw.manifolds import _spd2_kernels as kernels


def _points(n, rng, log_spread=0.5):
    q, _ = np.linalg.qr(rng.standard_normal((n, 2, 2)))
    values = np.exp(log_spread * rng.standard_normal((n, 2)))
    return torch.tensor((q * values[:, None, :]) @ np.swapaxes(q, 1, 2))


def _symmetric(n, rng, scale):
    a = rng.standard_normal((n, 2, 2))
    return torch.tensor(scale * (a + np.swapaxes(a, 1, 2)) / 2)


@pytest.fixture
def torch_formulas(monkeypatch):
    """Run the maps through the torch formulas instead of the kernels."""

    def use_torch(call, *args):
        with monkeypatch.context() as patch:
            patch.setattr(_spd2, "compiled", lambda p, x: False)
            return call(*args)

    return use_torch


def _near(P, rng, size):
    """Points at geodesic distance about ``size`` from ``P``: every series regime of the
    formulas (``q / m^2`` of order ``size^2``)."""
    V = _symmetric(P.shape[0], rng, size)
    return _spd2.exp(P, P @ V @ P).detach()


def _pairs(rng):
    P = _points(40, rng)
    yield "generic", P, _points(40, rng)
    yield "far", P, _points(40, rng, log_spread=3.0)  # r / m near 1
    for size in (1e-1, 1e-2, 3e-4, 1e-5):  # q / m^2 across both series thresholds
        yield f"near {size:g}", P, _near(P, rng, size)
    yield "coincident", P, P.clone()
    yield "multiple", P, 2.5 * P  # r = 0 exactly


@pytest.mark.parametrize("name", ["log", "dist"])
def test_log_and_distance_equal_the_torch_formulas(name, torch_formulas):
    rng = np.random.default_rng(0)
    function = getattr(_spd2, name)
    for label, P, X in _pairs(rng):
        P, X = P.clone().requires_grad_(), X.clone().requires_grad_()
        weights = torch.tensor(rng.standard_normal(function(P, X).shape))
        ours = function(P, X)
        reference = torch_formulas(function, P, X)
        torch.testing.assert_close(ours, reference, rtol=1e-13, atol=1e-15, msg=label)
        grads = torch.autograd.grad((weights * ours).sum(), (P, X))
        expected = torch.autograd.grad((weights * reference).sum(), (P, X))
        for a, b in zip(grads, expected, strict=True):
            scale = float(b.abs().max())
            torch.testing.assert_close(a, b, rtol=1e-8, atol=1e-10 * scale, msg=label)


def test_exp_equals_the_torch_formulas(torch_formulas):
    rng = np.random.default_rng(1)
    P = _points(40, rng)
    for size in (3.0, 0.5, 1e-2, 1e-4, 1e-7, 0.0):  # q above and below both thresholds
        V = (P @ _symmetric(40, rng, size) @ P).requires_grad_()
        Pg = P.clone().requires_grad_()
        weights = torch.tensor(rng.standard_normal((40, 2, 2)))
        ours, reference = _spd2.exp(Pg, V), torch_formulas(_spd2.exp, Pg, V)
        torch.testing.assert_close(ours, reference, rtol=1e-13, atol=0, msg=str(size))
        grads = torch.autograd.grad((weights * ours).sum(), (Pg, V))
        expected = torch.autograd.grad((weights * reference).sum(), (Pg, V))
        for a, b in zip(grads, expected, strict=True):
            torch.testing.assert_close(a, b, rtol=1e-9, atol=1e-12, msg=str(size))


@pytest.mark.parametrize("regime", ["far", "near 1e-2", "near 3e-4", "near 1e-5", "multiple"])
def test_hand_written_gradients_match_finite_differences(regime):
    rng = np.random.default_rng(2)
    P = _points(3, rng)
    if regime == "far":
        X = _points(3, rng, log_spread=3.0)
    elif regime == "multiple":
        X = 2.5 * P
    else:
        X = _near(P, rng, float(regime.split()[1]))
    P, X = P.requires_grad_(), X.clone().requires_grad_()
    V = (0.5 * (_spd2.log(P, X) + _spd2.log(P, X).mT)).detach().requires_grad_()
    assert torch.autograd.gradcheck(_spd2.log, (P, X))
    assert torch.autograd.gradcheck(_spd2.exp, (P, V))
    # dist is not differentiable where it is zero, and within gradcheck's step (1e-6) of
    # zero its finite differences are not a reference (the torch formulas are, above)
    if regime in ("far", "near 1e-2", "near 3e-4"):
        assert torch.autograd.gradcheck(_spd2.dist, (P, X))


def test_broadcast_points_get_summed_gradients(torch_formulas):
    """A base point broadcast over a batch (a mean over its members, an anchor over its
    taps) receives the sum of its copies' gradients, as in the torch formulas."""
    rng = np.random.default_rng(3)
    P = _points(5, rng).reshape(1, 5, 2, 2).requires_grad_()
    X = _points(15, rng).reshape(3, 5, 2, 2).requires_grad_()
    for function in (_spd2.log, _spd2.exp, _spd2.dist):
        argument = X if function is not _spd2.exp else (0.1 * (X + X.mT)).detach()
        ours = torch.autograd.grad(function(P.expand(3, -1, -1, -1), argument).sum(), P)[0]
        theirs = torch.autograd.grad(torch_formulas(function, P, argument).sum(), P)[0]
        assert ours.shape == P.shape
        torch.testing.assert_close(ours, theirs, rtol=1e-9, atol=1e-12)


def test_a_diagonal_base_and_a_diagonal_to_rounding_point_stay_diagonal():
    P = torch.tensor([[1e-9, 0.0], [0.0, 1e9]], dtype=torch.float64)
    X = torch.tensor([[1.0, -2e-17], [-2e-17, 1.0]], dtype=torch.float64)
    assert _spd2.compiled(P, X)
    log = _spd2.log(P, X)
    assert log[0, 1] == 0 and log[1, 0] == 0
    assert float(_spd2.dist(P, P)) == 0.0
    assert torch.equal(_spd2.log(P, P), torch.zeros_like(P))


def test_only_float64_cpu_points_run_compiled():
    P = torch.eye(2, dtype=torch.float64)
    assert _spd2.compiled(P, P)
    assert not _spd2.compiled(P.float(), P.float())
    assert not _spd2.compiled(_spd2.chart(P), P)
    torch.testing.assert_close(_spd2.log(P.float(), 2 * P.float()),
                               np.log(2.0) * P.float())  # fmt: skip


def test_second_derivatives_follow_the_torch_formulas(torch_formulas):
    """``create_graph=True`` (a Hessian-vector product) differentiates the torch formulas'
    gradient: the same second derivatives as without the kernels."""
    rng = np.random.default_rng(5)
    P, X = _points(4, rng).requires_grad_(), _points(4, rng).requires_grad_()
    direction = torch.tensor(rng.standard_normal((4, 2, 2)))

    def second(call):
        grads = torch.autograd.grad(call().sum(), (P, X), create_graph=True)
        return torch.autograd.grad(sum((g * direction).sum() for g in grads), (P, X))

    for function in (_spd2.log, _spd2.dist):
        ours = second(lambda f=function: f(P, X))
        theirs = second(lambda f=function: torch_formulas(f, P, X))
        for a, b in zip(ours, theirs, strict=True):
            torch.testing.assert_close(a, b, rtol=1e-10, atol=1e-12)
    assert torch.autograd.gradgradcheck(_spd2.log, (P, X))


def test_nan_and_non_positive_inputs_give_nan_like_the_torch_formulas(torch_formulas):
    P = torch.eye(2, dtype=torch.float64).expand(3, 2, 2)
    X = torch.tensor([[[np.nan, 0.0], [0.0, 1.0]], [[1.0, 2.0], [2.0, 1.0]],
                      [[2.0, 0.0], [0.0, 3.0]]], dtype=torch.float64)  # fmt: skip
    for function in (_spd2.log, _spd2.dist):
        ours, theirs = function(P, X), torch_formulas(function, P, X)
        assert torch.equal(torch.isnan(ours), torch.isnan(theirs))
        assert bool(torch.isfinite(ours[2]).all())


def test_threaded_build_gives_the_serial_result(monkeypatch):
    rng = np.random.default_rng(4)
    P, X = _points(64, rng), _points(64, rng)
    serial = _spd2.log(P, X)
    monkeypatch.setattr(kernels, "PARALLEL_ROWS", 1)
    import numba

    previous = numba.get_num_threads()
    numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
    try:
        assert torch.equal(_spd2.log(P, X), serial)
    finally:
        numba.set_num_threads(previous)
