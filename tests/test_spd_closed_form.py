"""SPD(2) geometry in closed form (sk_rtw.manifolds._spd2) and the closed-form 2 x 2
eigendecomposition (sk_rtw.manifolds._symmetric) against independent references: LAPACK's
``eigh`` route, 50-digit arithmetic, finite differences."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from sk_rtw.manifolds import SPD, _spd2
from sk_rtw.manifolds._symmetric import distinct, eigenvalues, eigh, symmetric_functions


def _points(n, rng, spread="moderate"):
    q, _ = np.linalg.qr(rng.standard_normal((n, 2, 2)))
    if spread == "wide":  # eigenvalues over 1e-4 .. 1e4
        values = 10.0 ** rng.uniform(-4, 4, (n, 2))
    else:
        values = np.exp(0.5 * rng.standard_normal((n, 2)))
    return torch.tensor((q * values[:, None, :]) @ np.swapaxes(q, 1, 2))


def _lapack_function(S, f):
    w, U = torch.linalg.eigh(0.5 * (S + S.mT))
    return (U * f(w).unsqueeze(-2)) @ U.mT


def _lapack_log(p, x):
    s, si = _lapack_function(p, torch.sqrt), _lapack_function(p, torch.rsqrt)
    return s @ _lapack_function(si @ x @ si, torch.log) @ s


def _lapack_exp(p, v):
    s, si = _lapack_function(p, torch.sqrt), _lapack_function(p, torch.rsqrt)
    return s @ _lapack_function(si @ v @ si, torch.exp) @ s


def _lapack_dist(p, x):
    si = _lapack_function(p, torch.rsqrt)
    return torch.log(torch.linalg.eigvalsh(si @ x @ si)).norm(dim=-1)


# ------------------------------------------------------------------ eigendecomposition
@pytest.mark.parametrize("kind", ["spd", "indefinite", "wide"])
def test_closed_form_eigh_matches_lapack(kind):
    rng = np.random.default_rng(0)
    if kind == "indefinite":
        a = rng.standard_normal((500, 2, 2))
        S = torch.tensor(a + np.swapaxes(a, 1, 2))
    else:
        S = _points(500, rng, "wide" if kind == "wide" else "moderate")
    w, U = eigh(S)
    w_ref = torch.linalg.eigvalsh(S)
    scale = S.abs().amax(dim=(-2, -1), keepdim=True).squeeze(-1)
    assert torch.all(w[:, 0] <= w[:, 1])
    torch.testing.assert_close(w, w_ref, rtol=0, atol=float(1e-14 * scale.max()))
    torch.testing.assert_close(U.mT @ U, torch.eye(2, dtype=S.dtype).expand_as(S))
    rebuilt = (U * w.unsqueeze(-2)) @ U.mT
    assert float(((rebuilt - S).abs() / scale.unsqueeze(-1)).max()) < 1e-14


def test_closed_form_eigh_is_exact_on_diagonal_matrices_of_any_conditioning():
    S = torch.tensor([[[1e-16, 0.0], [0.0, 1.0]], [[3.0, 0.0], [0.0, 1e-300]],
                      [[2.0, 0.0], [0.0, 2.0]], [[0.0, 0.0], [0.0, 0.0]]])  # fmt: skip
    w, U = eigh(S)
    expected = torch.tensor([[1e-16, 1.0], [1e-300, 3.0], [2.0, 2.0], [0.0, 0.0]])
    assert torch.equal(w, expected)
    assert torch.equal((U * w.unsqueeze(-2)) @ U.mT, S)


def test_eigenvalues_gradient_is_finite_at_repeated_eigenvalues():
    S = torch.eye(2, dtype=torch.float64).requires_grad_()
    assert torch.autograd.gradcheck(lambda s: eigenvalues(s).pow(2).sum(), (S,))
    S = _points(1, np.random.default_rng(1)).requires_grad_()
    assert torch.autograd.gradcheck(lambda s: eigenvalues(s), (S,))


@pytest.mark.parametrize("k", [2, 3])
def test_functions_sharing_one_decomposition_and_their_gradient(k):
    rng = np.random.default_rng(2)
    q, _ = np.linalg.qr(rng.standard_normal((3, k, k)))
    P = torch.tensor((q * np.exp(rng.standard_normal((3, 1, k)))) @ np.swapaxes(q, 1, 2))
    root, inverse_root = symmetric_functions(P, "sqrt", "invsqrt")
    eye = torch.eye(k, dtype=P.dtype).expand_as(P)
    torch.testing.assert_close(root @ inverse_root, eye)
    torch.testing.assert_close(root @ root, P)
    weights = torch.tensor(rng.standard_normal((2, 3, k, k)))

    def combined(p):
        s, si = symmetric_functions(p, "sqrt", "invsqrt")
        return (weights[0] * s).sum() + (weights[1] * si).sum()

    def inverse_root_only(p):  # an unused output (no gradient flows into it)
        return (weights[1] * symmetric_functions(p, "sqrt", "invsqrt")[1]).sum()

    assert torch.autograd.gradcheck(combined, (P.clone().requires_grad_(),))
    assert torch.autograd.gradcheck(inverse_root_only, (P.clone().requires_grad_(),))
    repeated = torch.eye(k, dtype=torch.float64).mul(2.0).requires_grad_()
    assert torch.autograd.gradcheck(combined, (repeated,))


def test_distinct_cuts_broadcast_copies_only():
    p = torch.arange(4.0).reshape(1, 2, 2)
    assert distinct(p.expand(5, 2, 2)).shape == (1, 2, 2)
    assert distinct(p.expand(5, 2, 2).unsqueeze(1).expand(5, 3, 2, 2)).shape == (1, 1, 2, 2)
    full = torch.arange(20.0).reshape(5, 2, 2)
    assert distinct(full) is full
    assert distinct(torch.zeros(2, 2).expand(3, 2, 2)).shape == (1, 2, 2)


# ------------------------------------------------------------------ SPD(2) geometry
def test_log_exp_and_distance_match_the_lapack_route():
    rng = np.random.default_rng(3)
    P, X = _points(400, rng), _points(400, rng)
    log = _spd2.log(P, X)
    reference = _lapack_log(P, X)
    scale = reference.abs().amax(dim=(-2, -1), keepdim=True)
    assert float(((log - reference).abs() / scale).max()) < 1e-13
    torch.testing.assert_close(_spd2.dist(P, X), _lapack_dist(P, X), rtol=1e-13, atol=0)
    exp = _spd2.exp(P, reference)
    reference = _lapack_exp(P, reference)
    scale = reference.abs().amax(dim=(-2, -1), keepdim=True)
    assert float(((exp - reference).abs() / scale).max()) < 1e-13


def _log_50_digits(P, X):
    mp = pytest.importorskip("mpmath")
    mp.mp.dps = 50

    def function(S, f):
        values, vectors = mp.eigsy((S + S.T) / 2)
        return vectors * mp.diag([f(v) for v in values]) * vectors.T

    A, B = mp.matrix(P.tolist()), mp.matrix(X.tolist())
    root, inverse_root = function(A, mp.sqrt), function(A, lambda v: 1 / mp.sqrt(v))
    log = root * function(inverse_root * B * inverse_root, mp.log) * root
    return torch.tensor([[float(log[i, j]) for j in range(2)] for i in range(2)])


def test_log_and_exp_of_widely_spread_points_match_50_digit_arithmetic():
    """Eigenvalues over 1e-4 .. 1e4 (whitened pairs conditioned up to 1e16): within 1e-6
    of the largest entry (LAPACK's eigh route is off by up to 7e-5 on these)."""
    rng = np.random.default_rng(3)
    P, X = _points(40, rng, "wide"), _points(40, rng, "wide")
    log = _spd2.log(P, X)
    for n in range(40):
        reference = _log_50_digits(P[n], X[n])
        scale = float(reference.abs().max())
        assert float((log[n] - reference).abs().max()) <= 1e-6 * scale
        back = _spd2.exp(P[n], reference)
        assert float((back - X[n]).abs().max()) <= 1e-6 * float(X[n].abs().max())


def test_exp_of_small_and_scaled_tangents_uses_the_series_exactly():
    """Tangents that are multiples of P (equal eigenvalues: the series branch) and tiny
    ones: Exp_P(c P) = e^c P, Exp_P(0) = P."""
    P = _points(6, np.random.default_rng(4))
    c = torch.linspace(-3.0, 3.0, 6, dtype=P.dtype).reshape(6, 1, 1)
    torch.testing.assert_close(_spd2.exp(P, c * P), torch.exp(c) * P, rtol=1e-14, atol=0)
    torch.testing.assert_close(_spd2.exp(P, 0 * P), P, rtol=1e-15, atol=0)
    torch.testing.assert_close(_spd2.log(P, torch.exp(c) * P), c * P, rtol=1e-13, atol=1e-15)


def test_distance_matches_50_digit_arithmetic():
    mp = pytest.importorskip("mpmath")
    mp.mp.dps = 50
    rng = np.random.default_rng(5)
    for spread, rtol in (("moderate", 1e-12), ("wide", 1e-8)):
        P, X = _points(30, rng, spread), _points(30, rng, spread)
        ours = _spd2.dist(P, X).numpy()
        for n in range(30):
            A, B = mp.matrix(P[n].tolist()), mp.matrix(X[n].tolist())
            # eigenvalues of A^-1 B from the characteristic polynomial, in 50 digits
            M = mp.inverse(A) * B
            half_trace, det = (M[0, 0] + M[1, 1]) / 2, mp.det(M)
            root = mp.sqrt(half_trace**2 - det)
            exact = mp.sqrt(mp.log(half_trace - root) ** 2 + mp.log(half_trace + root) ** 2)
            assert abs(ours[n] - float(exact)) <= rtol * float(exact)


def test_nearby_points_keep_their_distance_in_absolute_terms():
    P = _points(20, np.random.default_rng(6))
    for size in (1e-4, 1e-7, 1e-10):
        X = _spd2.exp(P, size * _spd2.log(P, _points(20, np.random.default_rng(7))))
        torch.testing.assert_close(_spd2.dist(P, X), _lapack_dist(P, X), rtol=0, atol=1e-14)


def test_a_diagonal_base_and_a_diagonal_to_rounding_point_give_a_diagonal_log():
    P = torch.tensor([[1e-9, 0.0], [0.0, 1e9]], dtype=torch.float64)
    X = torch.tensor([[1.0, -2e-17], [-2e-17, 1.0]], dtype=torch.float64)
    log = _spd2.log(P, X)
    assert log[0, 1] == 0 and log[1, 0] == 0
    torch.testing.assert_close(log.diagonal(), torch.tensor([-1e-9 * np.log(1e-9),
                                                             -1e9 * np.log(1e9)]))  # fmt: skip


@pytest.mark.parametrize("where", ["generic", "coincident"])
def test_gradients_match_finite_differences(where):
    rng = np.random.default_rng(8)
    P = _points(2, rng).requires_grad_()
    X = (P.detach().clone() if where == "coincident" else _points(2, rng)).requires_grad_()
    V = (torch.zeros_like(P) if where == "coincident" else _lapack_log(P, X)).detach()
    V = (0.5 * (V + V.mT)).requires_grad_()
    assert torch.autograd.gradcheck(_spd2.log, (P, X))
    assert torch.autograd.gradcheck(_spd2.exp, (P, V))
    assert torch.autograd.gradcheck(_spd2.squared_dist, (P, X))
    if where == "generic":
        assert torch.autograd.gradcheck(_spd2.dist, (P, X))
    else:  # a subgradient at the minimum (rounding decides which), never NaN
        (grad,) = torch.autograd.grad(_spd2.dist(P, X).sum(), X)
        assert torch.isfinite(grad).all()
        (grad,) = torch.autograd.grad(_spd2.dist(P, P.detach()).sum(), P)
        assert torch.equal(grad, torch.zeros_like(grad))  # the same tensor: exactly zero


def test_gradients_match_the_lapack_route():
    rng = np.random.default_rng(9)
    P, X = _points(50, rng).requires_grad_(), _points(50, rng).requires_grad_()
    weights = torch.tensor(rng.standard_normal((50, 2, 2)))
    for ours, reference, weight in ((_spd2.log, _lapack_log, weights),
                                    (_spd2.dist, _lapack_dist, weights[:, 0, 0])):  # fmt: skip
        mine = torch.autograd.grad((weight * ours(P, X)).sum(), (P, X))
        theirs = torch.autograd.grad((weight * reference(P, X)).sum(), (P, X))
        for a, b in zip(mine, theirs, strict=True):
            torch.testing.assert_close(a, b, rtol=1e-10, atol=1e-12)


def _embed(S, corner):
    out = torch.zeros(S.shape[0], 3, 3, dtype=S.dtype)
    out[:, :2, :2] = S
    out[:, 2, 2] = corner
    return out


def test_the_manifold_uses_the_closed_form_and_agrees_with_a_larger_size():
    """SPD(2) as a block of SPD(3) (third eigenvalue 1): the same distance, log and exp
    as SPD(3)'s eigendecomposition route."""
    rng = np.random.default_rng(10)
    P, X = _points(10, rng), _points(10, rng)
    two, three = SPD(2), SPD(3)
    big_P, big_X = _embed(P, 1.0), _embed(X, 1.0)
    torch.testing.assert_close(two._dist(P, X), three._dist(big_P, big_X))
    torch.testing.assert_close(two._pairwise_dist(P, X), three._pairwise_dist(big_P, big_X))
    log = two._log(P, X)
    torch.testing.assert_close(_embed(log, 0.0), three._log(big_P, big_X))
    torch.testing.assert_close(_embed(two._exp(P, log), 1.0), three._exp(big_P, _embed(log, 0.0)))


# ------------------------------------------------------------------ compiled Jacobi
@pytest.mark.parametrize("k", [3, 4, 6])
@pytest.mark.parametrize("spread", ["moderate", "wide", "indefinite"])
def test_compiled_jacobi_matches_lapack(k, spread):
    from sk_rtw.manifolds._symmetric import JACOBI_MAX_SIZE

    assert k <= JACOBI_MAX_SIZE
    rng = np.random.default_rng(k)
    q, _ = np.linalg.qr(rng.standard_normal((300, k, k)))
    if spread == "indefinite":
        values = rng.standard_normal((300, k))
    else:
        values = 10.0 ** rng.uniform(-4, 4, (300, k)) if spread == "wide" else np.exp(
            rng.standard_normal((300, k)))  # fmt: skip
    S = torch.tensor((q * values[:, None, :]) @ np.swapaxes(q, 1, 2)).reshape(3, 100, k, k)
    S = 0.5 * (S + S.mT)
    w, U = eigh(S)
    assert w.shape == (3, 100, k) and U.shape == (3, 100, k, k)
    assert torch.all(w[..., :-1] <= w[..., 1:])
    scale = S.abs().amax(dim=(-2, -1))
    torch.testing.assert_close(w, torch.linalg.eigvalsh(S), rtol=0,
                               atol=float(1e-14 * scale.max()))  # fmt: skip
    torch.testing.assert_close(U.mT @ U, torch.eye(k, dtype=S.dtype).expand_as(S))
    rebuilt = (U * w.unsqueeze(-2)) @ U.mT
    assert float(((rebuilt - S).abs().amax(dim=(-2, -1)) / scale).max()) < 1e-14
    if spread != "indefinite":  # positive definite: eigenvalues to high relative accuracy
        exact = np.sort(values, 1).reshape(3, 100, k)
        assert float((abs(w.numpy() - exact) / exact).max()) < 1e-8


def test_compiled_jacobi_on_repeated_and_diagonal_spectra():
    spread = torch.diag(torch.tensor([3.0, 1e-12, 1e12]))
    S = torch.stack([torch.eye(3), 2.0 * torch.eye(3), spread, torch.zeros(3, 3)]).double()
    w, U = eigh(S)
    expected = torch.tensor([[1.0] * 3, [2.0] * 3, [1e-12, 3.0, 1e12], [0.0] * 3]).double()
    assert torch.equal(w, expected)
    assert torch.equal((U * w.unsqueeze(-2)) @ U.mT, S)


def test_what_jacobi_does_not_converge_on_goes_to_lapack():
    """NaN makes every sweep rotate: the matrix is handed to LAPACK, whose answer it gets
    (the others keep Jacobi's)."""
    S = torch.eye(3, dtype=torch.float64).repeat(2, 1, 1)
    S[1, 0, 1] = S[1, 1, 0] = float("nan")
    w, U = eigh(S)
    w_lapack, U_lapack = torch.linalg.eigh(S[1])
    torch.testing.assert_close(w[1], w_lapack, equal_nan=True)
    torch.testing.assert_close(U[1], U_lapack, equal_nan=True)
    assert torch.equal(w[0], torch.ones(3, dtype=torch.float64))


def test_spd3_geometry_and_gradients_through_jacobi_match_lapack():
    rng = np.random.default_rng(12)
    q, _ = np.linalg.qr(rng.standard_normal((2, 40, 3, 3)))
    P, X = (torch.tensor((q[i] * np.exp(rng.standard_normal((40, 1, 3)))) @ q[i].swapaxes(1, 2))
            for i in range(2))  # fmt: skip
    P, X = (0.5 * (P + P.mT)).requires_grad_(), (0.5 * (X + X.mT)).requires_grad_()
    M = SPD(3)
    weights = torch.tensor(rng.standard_normal((40, 3, 3)))
    for ours, reference, weight in ((M._log, _lapack_log, weights),
                                    (M._dist, _lapack_dist, weights[:, 0, 0])):  # fmt: skip
        torch.testing.assert_close(ours(P, X), reference(P, X), rtol=1e-12, atol=1e-13)
        mine = torch.autograd.grad((weight * ours(P, X)).sum(), (P, X))
        theirs = torch.autograd.grad((weight * reference(P, X)).sum(), (P, X))
        for a, b in zip(mine, theirs, strict=True):
            torch.testing.assert_close(a, b, rtol=1e-9, atol=1e-11)
    same = P.detach().clone().requires_grad_()
    assert torch.autograd.gradcheck(lambda x: M._dist(P.detach(), x).pow(2).sum(), (same,))
