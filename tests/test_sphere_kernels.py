"""The compiled sphere maps (sk_rtw.manifolds._sphere_kernels) against the torch formulas
they compile (values and autograd gradients, in every branch: generic, the Taylor series,
coincident points, the cut locus, the quaternions' hemisphere flip), and their
hand-written gradients against finite differences."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from sk_rtw._numba import numba_threads
from sk_rtw.manifolds import Quaternion, Sphere, _sphere
from sk_rtw.manifolds import _sphere_kernels as kernels

MAPS = {"log": _sphere._sphere_log, "dist": _sphere._sphere_dist}
TORCH = {"log": _sphere._torch_log, "dist": _sphere._torch_dist}


def _unit(a):
    return a / np.linalg.norm(a, axis=-1, keepdims=True)


def _towards(p, rng, angle):
    """Points at geodesic distance ``angle`` from the rows of ``p``."""
    v = rng.standard_normal(p.shape)
    v -= (v * p).sum(-1, keepdims=True) * p
    v = _unit(v)
    return np.cos(angle) * p + np.sin(angle) * v


def _pairs(k, rng, n=30):
    """``(label, p, x, condition)``: the direction ``u / |u|`` (``u = x - <p, x> p``) of
    the log near the antipode and of the distance's gradient near ``p`` carries the rounding
    of ``u`` times ``1 / |u|`` (``condition``, per map; 1 where absent)."""
    p = _unit(rng.standard_normal((n, k)))
    yield "generic", p, _unit(rng.standard_normal((n, k))), {}
    # squared tangent norms across the series threshold (1e-12) and down to rounding
    for angle in (1.0, 1e-3, 1.2e-6, 8e-7, 1e-9):
        yield f"near {angle:g}", p, _towards(p, rng, angle), {"dist": 1.0 / angle}
    for angle in (1e-3, 2e-6, 5e-7):  # near the antipode (a quaternion's "near")
        condition = {"log": 1.0 / angle, "dist": 1.0 / angle}
        yield f"near antipode {angle:g}", p, -_towards(p, rng, angle), condition
    # the distance is not differentiable where x = p or -p (the quaternions' x = p): its
    # gradient there is rounding
    yield "coincident", p, p.copy(), {"dist": None}
    yield "antipodal", p, -p, {"dist": None}
    axis = np.zeros((n, k))
    axis[:, 0] = 1.0
    yield "axis and its antipode", axis, -axis, {}  # ties in the cut-locus axis


def _check(name, k, sign_invariant, rng):
    for label, p, x, conditions in _pairs(k, rng):
        condition = conditions.get(name, 1.0)
        P = torch.tensor(p, requires_grad=True)
        X = torch.tensor(x, requires_grad=True)
        ours = MAPS[name](P, X, sign_invariant)
        reference = TORCH[name](P, X, sign_invariant)
        message = f"{name} k={k} sign_invariant={sign_invariant}: {label}"
        torch.testing.assert_close(ours, reference, rtol=1e-13, atol=1e-15 * (condition or 1.0),
                                   msg=message)  # fmt: skip
        if condition is None:
            continue
        weights = torch.tensor(rng.standard_normal(ours.shape))
        grads = torch.autograd.grad((weights * ours).sum(), (P, X))
        expected = torch.autograd.grad((weights * reference).sum(), (P, X))
        # near the antipode the gradients grow like 1 / |u| (1e6 here): rounding of that
        # size moves the smaller entries
        scale = max(max(float(b.abs().max()) for b in expected), 1.0)
        for a, b in zip(grads, expected, strict=True):
            torch.testing.assert_close(a, b, rtol=1e-9, atol=1e-13 * scale * condition,
                                       msg=message)  # fmt: skip


@pytest.mark.parametrize("name", ["log", "dist"])
@pytest.mark.parametrize("k", [2, 3, 4])
@pytest.mark.parametrize("sign_invariant", [False, True])
def test_log_and_distance_equal_the_torch_formulas(name, k, sign_invariant):
    _check(name, k, sign_invariant, np.random.default_rng(k))


@pytest.mark.parametrize("k", [2, 4])
def test_exp_equals_the_torch_formulas(k):
    rng = np.random.default_rng(k)
    p = _unit(rng.standard_normal((30, k)))
    for size in (3.0, 0.5, 1e-3, 1.2e-6, 8e-7, 1e-9, 0.0):  # |v|^2 across 1e-12
        v = rng.standard_normal((30, k))
        v -= (v * p).sum(-1, keepdims=True) * p
        v = size * _unit(v) if size > 0 else 0.0 * v
        P = torch.tensor(p, requires_grad=True)
        V = torch.tensor(v, requires_grad=True)
        ours, reference = _sphere._sphere_exp(P, V), _sphere._torch_exp(P, V)
        torch.testing.assert_close(ours, reference, rtol=1e-13, atol=1e-15, msg=str(size))
        weights = torch.tensor(rng.standard_normal(ours.shape))
        grads = torch.autograd.grad((weights * ours).sum(), (P, V))
        expected = torch.autograd.grad((weights * reference).sum(), (P, V))
        for a, b in zip(grads, expected, strict=True):
            torch.testing.assert_close(a, b, rtol=1e-12, atol=1e-14, msg=str(size))


@pytest.mark.parametrize(
    "name, sign_invariant",
    [("log", False), ("log", True), ("dist", False), ("dist", True), ("exp", False)],
)
def test_hand_written_gradients_pass_gradcheck(name, sign_invariant):
    """Finite differences of the kernels themselves (points off the sphere included: the
    formulas are differentiated as written, not along the manifold)."""
    rng = np.random.default_rng(3)
    p = _unit(rng.standard_normal((6, 4))) * 1.1
    x = _unit(rng.standard_normal((6, 4))) * 0.9
    if name == "exp":
        x = 0.7 * x
    P = torch.tensor(p, requires_grad=True)
    X = torch.tensor(x, requires_grad=True)

    def kernel(P, X):
        return _sphere._KernelMap.apply(name, sign_invariant, P, X)

    assert torch.autograd.gradcheck(kernel, (P, X))


def test_cut_locus_gradient_by_finite_differences():
    """At ``x = -p`` the log is the fixed direction of ``p`` alone: its gradient in ``p``
    against central differences of ``q -> log(q, -q)`` along tangent directions."""
    rng = np.random.default_rng(4)
    p = _unit(rng.standard_normal((5, 3)))
    P = torch.tensor(p, requires_grad=True)
    weights = torch.tensor(rng.standard_normal((5, 3)))
    out = _sphere._sphere_log(P, torch.tensor(-p))
    (grad,) = torch.autograd.grad((weights * out).sum(), (P,))
    step = 1e-6
    for _ in range(3):
        t = rng.standard_normal((5, 3))
        t -= (t * p).sum(-1, keepdims=True) * p
        moved = [_unit(p + sign * step * t) for sign in (1.0, -1.0)]
        plus, minus = (_sphere._torch_log(torch.tensor(q), torch.tensor(-q)) for q in moved)
        numeric = ((weights * (plus - minus)).sum(-1) / (2 * step)).numpy()
        np.testing.assert_allclose((grad.numpy() * t).sum(-1), numeric, rtol=1e-5, atol=1e-7)


def test_broadcast_base_points_get_summed_gradients():
    rng = np.random.default_rng(5)
    mean = torch.tensor(_unit(rng.standard_normal((7, 4))), requires_grad=True)
    series = torch.tensor(_unit(rng.standard_normal((3, 7, 4))), requires_grad=True)
    for sign_invariant in (False, True):
        ours = _sphere._sphere_log(mean, series, sign_invariant)
        reference = _sphere._torch_log(mean, series, sign_invariant)
        torch.testing.assert_close(ours, reference, rtol=1e-13, atol=1e-15)
        (a,) = torch.autograd.grad(ours.sum(), (mean,))
        (b,) = torch.autograd.grad(reference.sum(), (mean,))
        torch.testing.assert_close(a, b, rtol=1e-10, atol=1e-12)


def test_manifolds_take_the_compiled_path_only_for_cpu_float64(monkeypatch):
    calls = []
    original = kernels.run
    monkeypatch.setattr(kernels, "run", lambda *a: (calls.append(a[0]), original(*a)))
    rng = np.random.default_rng(6)
    for manifold in (Sphere(2), Quaternion()):
        p, x = (torch.tensor(manifold.random_point((4,), rng)) for _ in range(2))
        for dtype, compiled in ((torch.float64, True), (torch.float32, False)):
            calls.clear()
            manifold.log(p.to(dtype), x.to(dtype))
            manifold.exp(p.to(dtype), 0.1 * x.to(dtype))
            manifold.dist(p.to(dtype), x.to(dtype))
            assert calls == (["log", "exp", "dist"] if compiled else [])


def test_nan_inputs_give_nan():
    p = torch.tensor([[1.0, 0.0, 0.0], [np.nan, 0.0, 1.0]], dtype=torch.float64)
    x = torch.tensor([[0.0, 1.0, 0.0], [0.0, 1.0, 0.0]], dtype=torch.float64)
    for name in ("log", "dist"):
        for sign_invariant in (False, True):
            out = MAPS[name](p, x, sign_invariant)
            reference = TORCH[name](p, x, sign_invariant)
            assert torch.isnan(out[1]).all() and torch.isnan(reference[1]).all()
            assert torch.isfinite(out[0]).all()
    out, reference = _sphere._sphere_exp(p, x), _sphere._torch_exp(p, x)
    assert torch.equal(torch.isnan(out), torch.isnan(reference)) and torch.isnan(out[1]).any()


@pytest.mark.parametrize("name", ["log", "exp", "dist"])
def test_second_derivatives_equal_the_torch_formulas(name):
    rng = np.random.default_rng(7)
    p = _unit(rng.standard_normal((5, 3)))
    x = _unit(rng.standard_normal((5, 3)))
    if name == "exp":
        x = 0.5 * x
    results = []
    for function in (_sphere._compiled_map, None):
        P = torch.tensor(p, requires_grad=True)
        X = torch.tensor(x, requires_grad=True)
        if function is None:
            out = _sphere._TORCH_MAPS[name](P, X, False)
        else:
            out = function(name, P, X, False)
        (g,) = torch.autograd.grad(out.sum(), (X,), create_graph=True)
        results.append(torch.autograd.grad((g * g).sum(), (P, X)))
    for a, b in zip(*results, strict=True):
        torch.testing.assert_close(a, b, rtol=1e-10, atol=1e-12)


def test_threaded_build_equals_serial(monkeypatch):
    rng = np.random.default_rng(8)
    p = torch.tensor(_unit(rng.standard_normal((5000, 4))), requires_grad=True)
    x = torch.tensor(_unit(rng.standard_normal((5000, 4))), requires_grad=True)
    results = []
    for threshold in (10**9, 1):
        monkeypatch.setattr(kernels, "PARALLEL_ROWS", threshold)
        with numba_threads(2):
            out = _sphere._sphere_log(p, x, True)
            grads = torch.autograd.grad((out * out).sum(), (p, x))
        results.append((out, *grads))
    for a, b in zip(*results, strict=True):
        assert torch.equal(a, b)
