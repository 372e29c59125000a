"""Functions of symmetric matrices through one eigendecomposition, with a stable gradient.

``torch.linalg.eigh`` has a gradient with ``1 / (lambda_i - lambda_j)`` terms, which is
infinite for repeated eigenvalues -- exactly the case ``p == x`` on the SPD manifold, where
``p^{-1/2} x p^{-1/2}`` is the identity. The backward pass here uses the Daleckii-Krein
formula instead: for ``F = U f(L) U^T`` the derivative is ``U (G * (U^T dS U)) U^T`` with
the first divided differences ``G_ij = (f(l_i) - f(l_j)) / (l_i - l_j)`` and ``G_ii = f'(l_i)``,
which stays finite when eigenvalues coincide.
"""

from __future__ import annotations

import torch

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


class _SymmetricFunction(torch.autograd.Function):
    @staticmethod
    def forward(ctx, S: torch.Tensor, name: str) -> torch.Tensor:
        w, U = torch.linalg.eigh(S)
        fw = _apply(name, w)
        ctx.save_for_backward(w, U, fw)
        ctx.name = name
        return (U * fw.unsqueeze(-2)) @ U.mT

    @staticmethod
    def backward(ctx, grad: torch.Tensor):
        w, U, fw = ctx.saved_tensors
        G = _divided_differences(ctx.name, w, fw)
        sym = 0.5 * (grad + grad.mT)
        inner = U.mT @ sym @ U
        return U @ (G * inner) @ U.mT, None


def symmetric_function(S: torch.Tensor, name: str) -> torch.Tensor:
    """Apply ``exp``, ``log``, ``sqrt`` or ``invsqrt`` to symmetric matrices ``S`` (..., k, k)."""
    if name not in _NAMES:
        raise ValueError(f"unknown matrix function {name!r}; expected one of {_NAMES}")
    return _SymmetricFunction.apply(sym(S), name)


def sym(S: torch.Tensor) -> torch.Tensor:
    """Symmetric part of ``S``."""
    return 0.5 * (S + S.mT)
