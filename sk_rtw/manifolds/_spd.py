"""Symmetric positive definite matrices with the affine-invariant metric."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from .._backend import safe_norm
from ._base import EXTREME_EXPONENT, Manifold, power_of_two_scale
from ._euclidean import _check_dim
from ._symmetric import sym, symmetric_function


@dataclass(frozen=True)
class SPD(Manifold):
    """SPD(k): symmetric positive definite ``k x k`` matrices, affine-invariant metric.

    ``Exp_P(V) = P^½ expm(P^-½ V P^-½) P^½``, ``Log_P(X) = P^½ logm(P^-½ X P^-½) P^½`` and
    ``dist(P, X) = ||logm(P^-½ X P^-½)||_F``. Every matrix function goes through one
    symmetric eigendecomposition, with a gradient that stays finite for repeated
    eigenvalues (``P = X``).

    Parameters
    ----------
    dim : int, default=2
        Matrix size ``k``; points have shape ``(k, k)``.
    """

    dim: int = 2
    name = "spd"

    def __post_init__(self):
        _check_dim(self.dim, "SPD", minimum=1)

    @property
    def point_shape(self) -> tuple[int, ...]:
        return (self.dim, self.dim)

    def _whiten(self, p):
        return symmetric_function(p, "sqrt"), symmetric_function(p, "invsqrt")

    def _exp(self, p, v):
        s, si = self._whiten(p)
        return sym(s @ symmetric_function(si @ v @ si, "exp") @ s)

    def _log(self, p, x):
        s, si = self._whiten(p)
        return sym(s @ symmetric_function(si @ x @ si, "log") @ s)

    def _dist(self, p, x):
        si = symmetric_function(p, "invsqrt")
        return safe_norm(symmetric_function(si @ x @ si, "log"), dim=(-2, -1))

    def _norm(self, p, v):
        si = symmetric_function(p, "invsqrt")
        return safe_norm(si @ v @ si, dim=(-2, -1))

    def _pairwise_dist(self, A, B):
        # Whiten each point of A once, not once per pair.
        si = symmetric_function(A, "invsqrt").unsqueeze(-3)
        inner = si @ B.unsqueeze(-4) @ si
        return safe_norm(symmetric_function(inner, "log"), dim=(-2, -1))

    def extreme_scale(self, points):
        eigenvalues = np.linalg.eigvalsh(points)
        if not np.all(eigenvalues > 0):
            return None
        largest, smallest = float(eigenvalues.max()), float(eigenvalues.min())
        if largest < 10.0**EXTREME_EXPONENT and smallest > 10.0**-EXTREME_EXPONENT:
            return None
        return power_of_two_scale(float(np.exp(np.log(eigenvalues).mean())))

    def _project(self, x):
        w, U = torch.linalg.eigh(sym(x))
        floor = (w.abs().amax(-1, keepdim=True) * 1e-10).clamp_min(1e-12)
        return sym((U * w.clamp_min(floor).unsqueeze(-2)) @ U.mT)

    def _point_problems(self, x, atol):
        scale = x.abs().amax(dim=(-2, -1)).clamp_min(1.0)
        asymmetry = (x - x.mT).abs().amax(dim=(-2, -1)) / scale
        not_symmetric = asymmetry > atol
        w = torch.linalg.eigvalsh(sym(x))
        not_pd = (w[..., 0] <= 0) & ~not_symmetric
        return [
            (not_symmetric, "the matrix is not symmetric"),
            (not_pd, "the matrix is not positive definite (an eigenvalue is <= 0)"),
        ]

    def _random_point(self, leading, rng):
        k = self.dim
        q, _ = np.linalg.qr(rng.standard_normal((*leading, k, k)))
        eig = np.exp(0.5 * rng.standard_normal((*leading, k)))
        return (q * eig[..., None, :]) @ np.swapaxes(q, -1, -2)

    def _random_tangent(self, p, scale, rng):
        a = scale * rng.standard_normal(p.shape)
        s = 0.5 * (a + np.swapaxes(a, -1, -2))
        w, U = np.linalg.eigh(p)
        root = (U * np.sqrt(w)[..., None, :]) @ np.swapaxes(U, -1, -2)
        return root @ s @ root
