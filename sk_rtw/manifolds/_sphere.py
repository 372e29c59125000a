"""Unit spheres S^d and unit quaternions S^3 / {±1}."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import torch

from .._backend import inner, safe_norm
from . import _sphere_kernels as kernels
from ._base import Manifold
from ._compiled import compiled_enabled
from ._euclidean import _check_dim

# Below this squared norm the closed forms are replaced by their Taylor expansions, so
# that values and gradients stay finite (and exact to double precision) at zero.
_TAYLOR_SQ = 1e-12


def _sphere_exp(p: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
    if compiled(p, v):
        return _compiled_map("exp", p, v)
    return _torch_exp(p, v)


def _torch_exp(p: torch.Tensor, v: torch.Tensor, sign_invariant: bool = False) -> torch.Tensor:
    # sign_invariant: unused, the maps' common signature (:data:`_TORCH_MAPS`)
    sq = inner(v, v, keepdim=True)
    small = sq < _TAYLOR_SQ
    safe_sq = torch.where(small, torch.ones_like(sq), sq)
    n = torch.sqrt(safe_sq)
    cos = torch.where(small, 1.0 - sq / 2.0 + sq * sq / 24.0, torch.cos(n))
    sinc = torch.where(small, 1.0 - sq / 6.0 + sq * sq / 120.0, torch.sin(n) / n)
    return cos * p + sinc * v


def _antipodal_direction(p: torch.Tensor) -> torch.Tensor:
    """A unit tangent vector at ``p``: the coordinate axis least aligned with ``p``,
    made orthogonal to it (deterministic, so ``log(p, -p)`` is reproducible)."""
    axis = torch.nn.functional.one_hot(p.abs().argmin(-1), p.shape[-1]).to(p.dtype)
    d = axis - inner(axis, p, keepdim=True) * p
    return d / torch.sqrt(inner(d, d, keepdim=True))


def _sphere_log(p: torch.Tensor, x: torch.Tensor, sign_invariant: bool = False) -> torch.Tensor:
    """``Log_p(x)``; ``sign_invariant``: of the representative of ``x`` in the hemisphere
    of ``p`` (the quaternions')."""
    if compiled(p, x):
        return _compiled_map("log", p, x, sign_invariant)
    return _torch_log(p, x, sign_invariant)


def _torch_log(p: torch.Tensor, x: torch.Tensor, sign_invariant: bool = False) -> torch.Tensor:
    if sign_invariant:
        x = torch.where(inner(p, x, keepdim=True) < 0, -1.0, 1.0) * x
    c = inner(p, x, keepdim=True)
    u = x - c * p
    sq = inner(u, u, keepdim=True)
    # theta / sin(theta) with sin(theta) = |u|, cos(theta) = c; Taylor near theta = 0.
    small = (sq < _TAYLOR_SQ) & (c > 0)
    safe_sq = torch.where(small, torch.ones_like(sq), sq.clamp_min(1e-300))
    s = torch.sqrt(safe_sq)
    factor = torch.where(small, 1.0 + sq / 6.0, torch.atan2(s, c) / s)
    v = factor * u
    # cut locus: x = -p has a geodesic of length pi in every direction; take a fixed one
    antipodal = (sq < _TAYLOR_SQ) & (c < 0)
    # on a CPU reading the flags is free, and the direction is most of the cost of a log
    # (long quaternion series: 3.3 of 5.5 s); on a GPU the branch is always computed (no
    # host synchronisation, and CUDA graphs stay capturable)
    if antipodal.device.type == "cpu" and not bool(antipodal.any()):
        return v
    return torch.where(antipodal, math.pi * _antipodal_direction(p).expand_as(v), v)


def _reflector(p: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """Householder vector ``u`` (and ``2 / u.u``) of the reflection that maps the first
    axis onto ``-+p``: its other columns are an orthonormal basis of the tangent space."""
    sign = torch.where(p[..., :1] >= 0, 1.0, -1.0)
    u = p + sign * torch.nn.functional.one_hot(
        torch.zeros(p.shape[:-1], dtype=torch.long, device=p.device), p.shape[-1]
    ).to(p.dtype)
    return u, 2.0 / inner(u, u, keepdim=True)


def _sphere_to_coordinates(p: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
    u, scale = _reflector(p)
    return (v - scale * inner(u, v, keepdim=True) * u)[..., 1:]


def _sphere_from_coordinates(p: torch.Tensor, c: torch.Tensor) -> torch.Tensor:
    u, scale = _reflector(p)
    padded = torch.nn.functional.pad(c, (1, 0))
    return padded - scale * inner(u, padded, keepdim=True) * u


def _sphere_dist(p: torch.Tensor, x: torch.Tensor, sign_invariant: bool = False) -> torch.Tensor:
    if compiled(p, x):
        return _compiled_map("dist", p, x, sign_invariant)
    return _torch_dist(p, x, sign_invariant)


def _torch_dist(p: torch.Tensor, x: torch.Tensor, sign_invariant: bool = False) -> torch.Tensor:
    c = inner(p, x)
    u = x - c.unsqueeze(-1) * p
    if sign_invariant:
        c = c.abs()
    return torch.atan2(safe_norm(u), c)


# ----------------------------------------------------------------- compiled (CPU, float64)
def compiled(p: torch.Tensor, x: torch.Tensor) -> bool:
    """Whether the maps of these arguments run compiled (:mod:`._sphere_kernels`): both
    float64 on the CPU."""
    return compiled_enabled() and all(
        t.device.type == "cpu" and t.dtype == torch.float64 for t in (p, x)
    )


def _compiled_map(name: str, p: torch.Tensor, x: torch.Tensor, sign_invariant: bool = False):
    """``log``, ``exp`` (``(..., k)``) or ``dist`` (``(...)``) by the kernels; one autograd
    node when a gradient is recorded (broadcasting is torch's, so its gradient sums over
    the broadcast axes)."""
    shape = torch.broadcast_shapes(p.shape, x.shape)
    P = p.expand(shape).reshape(-1, shape[-1]).contiguous()
    X = x.expand(shape).reshape(-1, shape[-1]).contiguous()
    if torch.is_grad_enabled() and (P.requires_grad or X.requires_grad):
        out = _KernelMap.apply(name, sign_invariant, P, X)
    else:
        out = _forward(name, P, X, sign_invariant)
    return out.reshape(shape[:-1] if name == "dist" else shape)


def _forward(name: str, P: torch.Tensor, X: torch.Tensor, sign_invariant: bool) -> torch.Tensor:
    p, x = P.detach().numpy(), X.detach().numpy()
    out = np.empty(p.shape[0]) if name == "dist" else np.empty_like(p)
    kernels.run(name, p, x, out, *(() if name == "exp" else (sign_invariant,)))
    return torch.from_numpy(out)


class _KernelMap(torch.autograd.Function):
    """A compiled sphere map of ``(n, k)`` rows with its closed-form gradient."""

    @staticmethod
    def forward(ctx, name, sign_invariant, P, X):
        ctx.name, ctx.sign_invariant = name, sign_invariant
        ctx.save_for_backward(P, X)
        return _forward(name, P, X, sign_invariant)

    @staticmethod
    def backward(ctx, grad):
        P, X = ctx.saved_tensors
        if torch.is_grad_enabled():  # create_graph: a differentiable backward, the torch one
            return None, None, *_torch_vjp(ctx.name, P, X, grad, ctx.sign_invariant)
        P, X = P.detach(), X.detach()
        gp, gx = torch.empty_like(P), torch.empty_like(X)
        extra = () if ctx.name == "exp" else (ctx.sign_invariant,)
        kernels.run(f"{ctx.name}_backward", P.numpy(), X.numpy(), grad.contiguous().numpy(),
                    gp.numpy(), gx.numpy(), *extra)  # fmt: skip
        return None, None, gp, gx


_TORCH_MAPS = {"log": _torch_log, "exp": _torch_exp, "dist": _torch_dist}


def _torch_vjp(name, P, X, grad, sign_invariant):
    """The gradients of the torch formulas, with their graph (higher derivatives)."""
    inputs = [t for t in (P, X) if t.requires_grad]
    out = _TORCH_MAPS[name](P, X, sign_invariant)
    grads = iter(torch.autograd.grad(out, inputs, grad, create_graph=True))
    return tuple(next(grads) if t.requires_grad else None for t in (P, X))


@dataclass(frozen=True)
class Sphere(Manifold):
    """Unit sphere S^d embedded in R^(d+1), with the great-circle metric.

    At the cut locus (``x = -p``) every direction leads to ``x`` along a geodesic of
    length pi; ``log(p, -p)`` returns the one along the coordinate axis least aligned
    with ``p`` (made tangent), so that ``exp(p, log(p, -p)) = -p``.

    Parameters
    ----------
    dim : int, default=2
        Intrinsic dimension ``d``; points have shape ``(d + 1,)`` (S^1: circle in R^2,
        S^2: sphere in R^3).
    """

    dim: int = 2
    name = "sphere"

    def __post_init__(self):
        _check_dim(self.dim, type(self).__name__, minimum=1)

    @property
    def point_shape(self) -> tuple[int, ...]:
        return (self.dim + 1,)

    @property
    def injectivity_radius(self) -> float:
        return math.pi

    @property
    def distance_segments(self):
        return ((0, self.dim + 1, "sphere"),)

    @property
    def intrinsic_dim(self) -> int:
        return self.dim

    @property
    def velocity_dim(self) -> int:
        return 1 if self.dim == 1 else self.dim + 1

    def _velocity(self, p, x):
        v = self._log(p, x)
        if self.dim > 1:  # the ambient vector: S^2 has no continuous frame
            return v
        # S^1: the component along the circle's own direction J p = (-p_1, p_0)
        return (p[..., :1] * v[..., 1:] - p[..., 1:] * v[..., :1]).expand(*v.shape[:-1], 1)

    def _to_coordinates(self, p, v):
        return _sphere_to_coordinates(*torch.broadcast_tensors(p, v))

    def _from_coordinates(self, p, c):
        lead = torch.broadcast_shapes(p.shape[:-1], c.shape[:-1])
        return _sphere_from_coordinates(p.expand(*lead, p.shape[-1]), c.expand(*lead, c.shape[-1]))

    def _exp(self, p, v):
        return _sphere_exp(p, v)

    def _log(self, p, x):
        return _sphere_log(p, x)

    def _dist(self, p, x):
        return _sphere_dist(p, x)

    def _norm(self, p, v):
        return safe_norm(v)

    def _project(self, x):
        n = torch.linalg.vector_norm(x, dim=-1, keepdim=True)
        if bool((n == 0).any()):
            raise ValueError("cannot project the zero vector onto the sphere")
        return x / n

    def _point_problems(self, x, atol):
        norm_error = (torch.linalg.vector_norm(x, dim=-1) - 1.0).abs()
        return [(norm_error > atol, "its Euclidean norm differs from 1")]

    def _random_point(self, leading, rng):
        x = rng.standard_normal((*leading, self.dim + 1))
        return x / np.linalg.norm(x, axis=-1, keepdims=True)

    def _random_tangent(self, p, scale, rng):
        v = scale * rng.standard_normal(p.shape)
        return v - (v * p).sum(-1, keepdims=True) * p


@dataclass(frozen=True)
class Quaternion(Sphere):
    """Unit quaternions ``(w, x, y, z)`` (w first) as orientations: S^3 with q ~ -q.

    ``log`` and ``dist`` use the representative of ``x`` in the hemisphere of ``p``, so the
    distance is invariant to ``q -> -q`` (it is half the rotation angle). Hence ``mean``
    aligns every sample with the hemisphere of the current estimate at each Gauss–Newton
    step, and series that flip sign between samples are interpolated without jumps.

    Points have shape ``(4,)``; a series is ``(T, 4)``.
    """

    dim: int = 3
    name = "quaternion"

    def __post_init__(self):
        if self.dim != 3:
            raise ValueError(f"Quaternion is S^3; dim must be 3, got {self.dim!r}")

    @property
    def injectivity_radius(self) -> float:
        return math.pi / 2

    @property
    def distance_segments(self):
        return ((0, 4, "sign-invariant sphere"),)

    def __repr__(self) -> str:
        return "Quaternion()"

    def continuous(self, series):
        series = np.array(series, dtype=np.float64)
        if series.ndim < 2 or series.shape[-2] < 2:
            return series
        dots = (series[..., 1:, :] * series[..., :-1, :]).sum(-1)
        signs = np.cumprod(np.where(dots < 0, -1.0, 1.0), axis=-1)
        series[..., 1:, :] *= signs[..., None]
        return series

    def _log(self, p, x):
        return _sphere_log(p, x, sign_invariant=True)

    def _dist(self, p, x):
        return _sphere_dist(p, x, sign_invariant=True)

    @property
    def normalised_space(self):
        return self

    def normalise_windows(self, windows):
        # the chordal mean m (top eigenvector of sum q q^T: sign-free, and g m for the
        # window g q), then conj(m) q: the same for a window in any world frame
        q = np.asarray(windows, dtype=np.float64)
        scatter = np.einsum("...ki,...kj->...ij", q, q)
        mean = np.linalg.eigh(scatter)[1][..., :, -1][..., None, :]
        return quaternion_product(quaternion_conjugate(mean), q)

    @property
    def velocity_dim(self) -> int:
        return 3

    def _velocity(self, p, x):
        # log_p(x) (x's representative in p's hemisphere) moved to the identity by p^-1:
        # the vector part of conj(p) * v; twice it is the rotation vector of p^-1 x
        v = self._log(p, x)
        w, a = p[..., :1], p[..., 1:]
        v0, b = v[..., :1], v[..., 1:]
        return 2.0 * (w * b - v0 * a - torch.linalg.cross(a.expand_as(b), b, dim=-1))


def quaternion_conjugate(q: np.ndarray) -> np.ndarray:
    """``(w, -x, -y, -z)``: the inverse of a unit quaternion."""
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def quaternion_product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton products ``a b`` of quaternions ``(w, x, y, z)``, broadcast."""
    w1, v1 = a[..., :1], a[..., 1:]
    w2, v2 = b[..., :1], b[..., 1:]
    w = w1 * w2 - (v1 * v2).sum(-1, keepdims=True)
    v = w1 * v2 + w2 * v1 + np.cross(v1, v2)
    lead = np.broadcast_shapes(w.shape[:-1], v.shape[:-1])
    return np.concatenate([np.broadcast_to(w, (*lead, 1)), np.broadcast_to(v, (*lead, 3))],
                          axis=-1)  # fmt: skip
