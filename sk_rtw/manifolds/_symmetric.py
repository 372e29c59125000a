"""Functions of symmetric matrices through one eigendecomposition, with a stable gradient.

``torch.linalg.eigh`` has a gradient with ``1 / (lambda_i - lambda_j)`` terms, which is
infinite for repeated eigenvalues -- exactly the case ``p == x`` on the SPD manifold, where
``p^{-1/2} x p^{-1/2}`` is the identity. The backward pass here uses the Daleckii-Krein
formula instead: for ``F = U f(L) U^T`` the derivative is ``U (G * (U^T dS U)) U^T`` with
the first divided differences ``G_ij = (f(l_i) - f(l_j)) / (l_i - l_j)`` and ``G_ii = f'(l_i)``,
which stays finite when eigenvalues coincide.

Several functions of the same matrices (``sqrt`` and ``invsqrt`` of a tangent point) share
one decomposition. ``2 x 2`` matrices are decomposed in closed form by one Jacobi rotation
(elementwise operations over the whole batch, on any device), ``3 x 3`` to ``6 x 6`` on the
CPU by the compiled cyclic Jacobi method (:mod:`~sk_rtw.manifolds._jacobi`);
``torch.linalg.eigh`` runs a LAPACK call per matrix, whose overhead is most of the cost at
these sizes.
"""

from __future__ import annotations

import torch

from ._compiled import compiled_enabled
from ._jacobi import jacobi_eigh

_NAMES = ("exp", "log", "sqrt", "invsqrt")


def _apply(name: str, w: torch.Tensor) -> torch.Tensor:
    if name == "exp":
        return torch.exp(w)
    if name == "log":
        return torch.log(w)
    if name == "sqrt":
        return torch.sqrt(w)
    return torch.rsqrt(w)


def _derivative(name: str, w: torch.Tensor) -> torch.Tensor:
    if name == "exp":
        return torch.exp(w)
    if name == "log":
        return 1.0 / w
    if name == "sqrt":
        return 0.5 * torch.rsqrt(w)
    return -0.5 * w.pow(-1.5)


def _divided_differences(name: str, w: torch.Tensor, fw: torch.Tensor) -> torch.Tensor:
    wi, wj = w.unsqueeze(-1), w.unsqueeze(-2)
    fi, fj = fw.unsqueeze(-1), fw.unsqueeze(-2)
    diff = wi - wj
    scale = torch.maximum(wi.abs(), wj.abs()).clamp_min(1.0)
    close = diff.abs() <= 1e-7 * scale
    safe_diff = torch.where(close, torch.ones_like(diff), diff)
    if name == "exp":
        # (e^a - e^b) / (a - b) = e^b * expm1(a - b) / (a - b): no cancellation.
        quotient = fj * torch.expm1(safe_diff) / safe_diff
    else:
        quotient = (fi - fj) / safe_diff
    return torch.where(close, _derivative(name, 0.5 * (wi + wj)), quotient)


def _eigh_2x2(S: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """Ascending eigenvalues and eigenvectors of symmetric 2 x 2 matrices, in closed form.

    The Jacobi rotation ``t = sign(tau) / (|tau| + sqrt(1 + tau^2))``,
    ``tau = (c - a) / (2 b)``, diagonalises ``[[a, b], [b, c]]`` to ``a - t b`` and
    ``c + t b`` (Golub & Van Loan, section 8.5): each eigenvalue to a few units of rounding
    of ``|S|``, a diagonal matrix exactly, of any conditioning.
    """
    a, b, c = S[..., 0, 0], S[..., 0, 1], S[..., 1, 1]
    off = b != 0
    safe_b = torch.where(off, b, torch.ones_like(b))
    tau = (c - a) / (2.0 * safe_b)
    one = torch.ones_like(tau)
    t = torch.copysign(one, tau) / (tau.abs() + torch.hypot(one, tau))
    t = torch.where(off, t, torch.zeros_like(t))
    cos = torch.rsqrt(1.0 + t * t)
    sin = t * cos
    first, second = a - t * b, c + t * b
    # columns (cos, -sin) for ``first`` and (sin, cos) for ``second``; ascending order
    swap = first > second
    w = torch.stack((torch.where(swap, second, first), torch.where(swap, first, second)), -1)
    u0 = torch.stack((cos, -sin), -1)
    u1 = torch.stack((sin, cos), -1)
    lower = torch.where(swap.unsqueeze(-1), u1, u0)
    upper = torch.where(swap.unsqueeze(-1), u0, u1)
    return w, torch.stack((lower, upper), -1)


#: Largest size decomposed by the compiled Jacobi method on the CPU (3 x 3: a fifth of a
#: LAPACK call's time per matrix, 6 x 6 still ahead, beyond that LAPACK).
JACOBI_MAX_SIZE = 6


def _compiled(S: torch.Tensor) -> bool:
    return (
        compiled_enabled() and 3 <= S.shape[-1] <= JACOBI_MAX_SIZE
        and S.device.type == "cpu" and S.dtype == torch.float64
    )  # fmt: skip


def _eigh_jacobi(S: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """:func:`~sk_rtw.manifolds._jacobi.jacobi_eigh` over a batch; a matrix it does not
    converge on (NaN among them) goes to LAPACK, which answers or raises as before."""
    k = S.shape[-1]
    flat = S.detach().reshape(-1, k, k).contiguous()
    w = torch.empty(flat.shape[:-1], dtype=S.dtype)
    U = torch.empty_like(flat)
    failed = torch.from_numpy(jacobi_eigh(flat.numpy(), w.numpy(), U.numpy()))
    if bool(failed.any()):
        w[failed], U[failed] = torch.linalg.eigh(flat[failed])
    return w.reshape(S.shape[:-1]), U.reshape(S.shape)


def eigh(S: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """Ascending eigenvalues and orthonormal eigenvectors (columns) of symmetric ``S``; no
    gradient (the callers' backward passes use them). ``2 x 2`` in closed form, up to
    ``JACOBI_MAX_SIZE`` compiled on the CPU, else LAPACK."""
    if S.shape[-1] == 2:
        return _eigh_2x2(S)
    if _compiled(S):
        return _eigh_jacobi(S)
    return torch.linalg.eigh(S)


class _SymmetricFunctions(torch.autograd.Function):
    @staticmethod
    def forward(ctx, S: torch.Tensor, names: tuple[str, ...]):
        ctx.set_materialize_grads(False)
        w, U = eigh(S)
        values = [_apply(name, w) for name in names]
        ctx.save_for_backward(w, U, *values)
        ctx.names = names
        return tuple((U * fw.unsqueeze(-2)) @ U.mT for fw in values)

    @staticmethod
    def backward(ctx, *grads: torch.Tensor):
        w, U, *values = ctx.saved_tensors
        total = None
        for name, fw, grad in zip(ctx.names, values, grads, strict=True):
            if grad is None:
                continue
            inner = U.mT @ sym(grad) @ U
            term = _divided_differences(name, w, fw) * inner
            total = term if total is None else total + term
        if total is None:
            return None, None
        return U @ total @ U.mT, None


class _Eigenvalues(torch.autograd.Function):
    """Eigenvalues from :func:`eigh`; gradient ``U diag(g) U^T``."""

    @staticmethod
    def forward(ctx, S: torch.Tensor):
        w, U = eigh(S)
        ctx.save_for_backward(U)
        return w

    @staticmethod
    def backward(ctx, grad: torch.Tensor):
        (U,) = ctx.saved_tensors
        return (U * grad.unsqueeze(-2)) @ U.mT


def symmetric_functions(S: torch.Tensor, *names: str) -> tuple[torch.Tensor, ...]:
    """Apply each of ``exp``, ``log``, ``sqrt``, ``invsqrt`` named in ``names`` to symmetric
    matrices ``S`` (..., k, k), through one eigendecomposition."""
    for name in names:
        if name not in _NAMES:
            raise ValueError(f"unknown matrix function {name!r}; expected one of {_NAMES}")
    return _SymmetricFunctions.apply(sym(S), names)


def symmetric_function(S: torch.Tensor, name: str) -> torch.Tensor:
    """Apply ``exp``, ``log``, ``sqrt`` or ``invsqrt`` to symmetric matrices ``S`` (..., k, k)."""
    return symmetric_functions(S, name)[0]


def eigenvalues(S: torch.Tensor) -> torch.Tensor:
    """Ascending eigenvalues of symmetric matrices ``S`` (..., k, k), differentiable (the
    gradient of a function of distinct or repeated eigenvalues stays finite)."""
    S = sym(S)
    if S.shape[-1] == 2 or _compiled(S):
        return _Eigenvalues.apply(S)
    return torch.linalg.eigvalsh(S)


def sym(S: torch.Tensor) -> torch.Tensor:
    """Symmetric part of ``S``."""
    return 0.5 * (S + S.mT)


def distinct(p: torch.Tensor) -> torch.Tensor:
    """Matrices ``p`` (..., k, k) without their broadcast copies: leading dimensions of
    stride 0 (``expand``) cut to length 1, so that what is computed from ``p`` is computed
    once and broadcast back."""
    for dim in range(p.ndim - 2):
        if p.stride(dim) == 0 and p.shape[dim] > 1:
            p = p.narrow(dim, 0, 1)
    return p
