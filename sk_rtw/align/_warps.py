"""Parameterised warping functions ``w_n : {1..Z} -> [0, 1]`` (boundary constraint exact).

* :class:`NeuralWarps` (RTW, NTW, paper eq. 6):
  ``w_n(z) = zhat sqrt(N) e_1[n] + zhat (1 - zhat) sum_k phi_theta(zhat)_k e_{k+1}[n]`` with
  ``zhat = (z - 1) / (Z - 1)`` and an orthonormal basis ``e_1 = 1 / sqrt(N), e_2..e_N`` of
  R^N. The basis is the ``Q`` of the QR decomposition of the all-ones column, held as one
  Householder reflector, so applying it costs O(N) rather than O(N^2) per time index.
  Because ``e_2..e_N`` are orthogonal to ``1``, the mean warp is the identity.
  ``phi_theta`` is the network 1-512-512-(1025)-(N-1): two hidden ReLU layers of 512 and a
  linear output layer that reads the skip-concatenation ``[h2, h1, zhat]`` (1025 values),
  i.e. ``263680 + 1025 (N - 1) + (N - 1)`` parameters as in the paper. RTW initialises
  the weights with Xavier (symmetry breaking), NTW with zeros.
* :class:`SineWarps` (TTW, paper eq. 21): ``w_n = zhat + sum_k a_{n,k} sin(pi k zhat)``
  with the coefficients centred across signals; monotonicity is restored as in the TTW
  reference: values clamped to [0, 1], then every decrease replaced by the previous value
  (a running maximum).

The returned warps are clamped to [0, 1]; ``raw`` warps (before clamping) feed the
monotonicity penalty.

``knots``: the network may be evaluated at ``knots`` equally spaced times only and its
output interpolated linearly to the ``Z`` output times (a ReLU network of one input is
piecewise linear anyway). The network then costs ``knots / Z`` of its full price, which is
most of an epoch's work on a CPU; ``None`` evaluates it at every output time (the paper).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Protocol, runtime_checkable

import torch
from torch import nn

#: Network initialisations: Xavier everywhere (RTW), zeros everywhere (NTW), or Xavier
#: hidden layers with a zero readout (the warps start exactly at the identity while the
#: hidden units differ, so the network is not confined to a linear function as with zeros).
INITS = ("xavier", "zeros", "zero-readout")


@runtime_checkable
class WarpModel(Protocol):
    """What the engine needs of a warp model (:class:`NeuralWarps`, :class:`SineWarps`).

    A new family of warps is a ``torch.nn.Module`` with these three members; the engine
    trains its parameters with Adam against the method's loss.
    """

    def __call__(self, zhat: torch.Tensor) -> torch.Tensor:
        """Raw warps (N, Z) at the unit times ``zhat`` (Z,); the penalty reads them."""
        ...

    def finalise(self, raw: torch.Tensor) -> torch.Tensor:
        """Warps in [0, 1] (N, Z), non-decreasing where the family guarantees it."""
        ...

    def parameters(self, recurse: bool = True) -> Iterator[nn.Parameter]:
        """The trainable parameters."""
        ...


def unit_time(n_points: int, dtype=torch.float64, device=None) -> torch.Tensor:
    """``zhat`` = ``(z - 1) / (Z - 1)`` for ``z = 1..Z``, shape (Z,)."""
    return torch.linspace(0.0, 1.0, n_points, dtype=dtype, device=device)


class HouseholderBasis(nn.Module):
    """Orthonormal basis of R^N whose first vector is ``1 / sqrt(N)``, applied in O(N).

    ``H = I - 2 u u^T / (u^T u)`` with ``u = e_1 - 1 / sqrt(N)`` maps ``e_1`` to the
    normalised all-ones vector; its columns are the basis ``e_1, ..., e_N``.
    """

    def __init__(self, n_signals: int, dtype=torch.float64):
        super().__init__()
        u = torch.full((n_signals,), -1.0 / math.sqrt(n_signals), dtype=dtype)
        u[0] += 1.0
        norm_sq = float(u @ u)
        self.u: torch.Tensor
        self.register_buffer("u", u)
        self.scale = 2.0 / norm_sq if norm_sq > 0 else 0.0

    def combine(self, coefficients: torch.Tensor) -> torch.Tensor:
        """``sum_k c_k e_{k+1}`` for ``coefficients`` (..., N-1); returns (..., N)."""
        padded = torch.nn.functional.pad(coefficients, (1, 0))
        return padded - self.scale * (padded @ self.u).unsqueeze(-1) * self.u

    def matrix(self) -> torch.Tensor:
        """The basis as the columns of an N x N matrix (for inspection and tests)."""
        eye = torch.eye(self.u.numel(), dtype=self.u.dtype, device=self.u.device)
        return eye - self.scale * torch.outer(self.u, self.u)


class SkipMLP(nn.Module):
    """``phi_theta``: 1 -> 512 -> 512 -> linear readout of ``[h2, h1, zhat]`` (1025)."""

    def __init__(
        self, n_outputs: int, hidden: int = 512, init: str = "xavier", dtype=torch.float64
    ):
        super().__init__()
        self.hidden1 = nn.Linear(1, hidden, dtype=dtype)
        self.hidden2 = nn.Linear(hidden, hidden, dtype=dtype)
        self.readout = nn.Linear(2 * hidden + 1, n_outputs, dtype=dtype)
        if init not in INITS:
            raise ValueError(f"init must be one of {INITS}, got {init!r}")
        for layer in (self.hidden1, self.hidden2, self.readout):
            if init == "zeros" or (init == "zero-readout" and layer is self.readout):
                nn.init.zeros_(layer.weight)
            else:
                nn.init.xavier_uniform_(layer.weight)
            nn.init.zeros_(layer.bias)

    def forward(self, zhat: torch.Tensor) -> torch.Tensor:
        x = zhat.unsqueeze(-1)
        h1 = torch.relu(self.hidden1(x))
        h2 = torch.relu(self.hidden2(h1))
        return self.readout(torch.cat([h2, h1, x], dim=-1))


def compose_warps(outer: torch.Tensor, inner: torch.Tensor) -> torch.Tensor:
    """``outer_n(inner_n(z))`` for warps sampled on a uniform grid of [0, 1].

    ``outer`` is linear between its samples; the result is differentiable in ``inner``.

    Parameters
    ----------
    outer : torch.Tensor, shape (N, J)
        Warps at the times ``j / (J - 1)``, ``J >= 2``.
    inner : torch.Tensor, shape (N, Z)
        Times in [0, 1] at which to evaluate each row of ``outer``.

    Returns
    -------
    torch.Tensor, shape (N, Z)
    """
    position = inner.clamp(0.0, 1.0) * (outer.shape[1] - 1)
    left = torch.floor(position).detach().long().clamp(0, outer.shape[1] - 2)
    low, high = torch.gather(outer, 1, left), torch.gather(outer, 1, left + 1)
    return low + (position - left) * (high - low)


def resample_linear(values: torch.Tensor, times: torch.Tensor) -> torch.Tensor:
    """Linear interpolation of ``values`` (J, ...) given at J equally spaced times of [0, 1].

    Parameters
    ----------
    values : torch.Tensor, shape (J, ...)
        Values at the times ``j / (J - 1)``, ``J >= 2``.
    times : torch.Tensor, shape (Z,)
        Times in [0, 1].

    Returns
    -------
    torch.Tensor, shape (Z, ...)
    """
    position = times * (values.shape[0] - 1)
    left = torch.floor(position).long().clamp(0, values.shape[0] - 2)
    weight = (position - left).reshape(-1, *([1] * (values.ndim - 1)))
    return torch.lerp(values[left], values[left + 1], weight.to(values.dtype))


class NeuralWarps(nn.Module):
    """RTW/NTW warps: identity plus ``zhat (1 - zhat)`` times a network on the basis.

    Parameters
    ----------
    n_signals : int
    hidden : int, default=512
        Width of the two hidden layers.
    init : {"xavier", "zeros"}, default="xavier"
    knots : int or None, default=None
        Evaluate the network at this many equally spaced times and interpolate linearly
        (None: at every output time).
    """

    def __init__(
        self,
        n_signals: int,
        hidden: int = 512,
        init: str = "xavier",
        knots: int | None = None,
        dtype=torch.float64,
    ):
        super().__init__()
        if knots is not None and knots < 2:
            raise ValueError(f"knots must be None or an integer >= 2, got {knots!r}")
        self.n_signals = n_signals
        self.knots = knots
        self.basis = HouseholderBasis(n_signals, dtype=dtype)
        self.phi = SkipMLP(n_signals - 1, hidden, init, dtype) if n_signals > 1 else None

    def offsets(self, zhat: torch.Tensor) -> torch.Tensor:
        """``sum_k phi_theta(zhat)_k e_{k+1}``, shape (Z, N)."""
        if self.phi is None:
            raise RuntimeError("one signal has no warp offsets")
        if self.knots is None or self.knots >= zhat.shape[0]:
            return self.basis.combine(self.phi(zhat))
        grid = unit_time(self.knots, dtype=zhat.dtype, device=zhat.device)
        return resample_linear(self.basis.combine(self.phi(grid)), zhat)

    def forward(self, zhat: torch.Tensor) -> torch.Tensor:
        """Raw warps, shape (N, Z)."""
        identity = zhat.expand(self.n_signals, -1)
        if self.phi is None:
            return identity
        return identity + (zhat * (1.0 - zhat)).unsqueeze(0) * self.offsets(zhat).T

    @staticmethod
    def finalise(raw: torch.Tensor) -> torch.Tensor:
        return raw.clamp(0.0, 1.0)


class SineWarps(nn.Module):
    """TTW warps from ``n_components`` discrete-sine-transform coefficients per signal."""

    def __init__(self, n_signals: int, n_components: int = 8, dtype=torch.float64):
        super().__init__()
        if n_components < 1:
            raise ValueError(f"n_components must be >= 1, got {n_components}")
        self.coefficients = nn.Parameter(torch.zeros(n_signals, n_components, dtype=dtype))

    def forward(self, zhat: torch.Tensor) -> torch.Tensor:
        k = torch.arange(1, self.coefficients.shape[1] + 1, dtype=zhat.dtype, device=zhat.device)
        basis = torch.sin(math.pi * k.unsqueeze(-1) * zhat)  # (K, Z)
        # sin(pi k) is ~1e-16 in floating point: make the end points exact
        basis = basis * ((zhat > 0) & (zhat < 1)).to(basis.dtype)
        centred = self.coefficients - self.coefficients.mean(0, keepdim=True)
        return zhat + centred @ basis

    @staticmethod
    def finalise(raw: torch.Tensor) -> torch.Tensor:
        return torch.cummax(raw.clamp(0.0, 1.0), dim=-1).values
