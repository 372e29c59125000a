"""Parameterised warping functions ``w_n : {1..Z} -> [0, 1]`` (boundary constraint exact).

* :class:`NeuralWarps` (RTW, NTW, paper eq. 6):
  ``w_n(z) = zhat sqrt(N) e_1[n] + zhat (1 - zhat) sum_k phi_theta(zhat)_k e_{k+1}[n]`` with
  ``zhat = (z - 1) / (Z - 1)`` and an orthonormal basis ``e_1 = 1 / sqrt(N), e_2..e_N`` of
  R^N. The basis is the ``Q`` of the QR decomposition of the all-ones column, held as one
  Householder reflector, so applying it costs O(N) rather than O(N^2) per time index.
  Because ``e_2..e_N`` are orthogonal to ``1``, the mean warp is the identity.
  ``phi_theta`` is the network 1-H-H-(2H+1)-(N-1): two hidden ReLU layers of width ``H``
  and a linear output layer that reads the skip-concatenation ``[h2, h1, zhat]``. With the
  paper's ``H = 512`` that is ``263680 + 1025 (N - 1) + (N - 1)`` parameters. RTW
  initialises the weights with Xavier (symmetry breaking), NTW with zeros.
* :class:`SineWarps` (TTW, paper eq. 21): ``w_n = zhat + sum_k a_{n,k} sin(pi k zhat)``
  with the coefficients centred across signals; monotonicity is restored as in the TTW
  reference: values clamped to [0, 1], then every decrease replaced by the previous value
  (a running maximum).

Both hold the warps of several independent groups of series (the classes of an
estimator) in stacked parameters: group ``g`` of ``N_g`` series has its own network (or
coefficients), its own basis of R^{N_g} and its own initialisation seed, so the groups
train exactly as separate fits would (Adam is elementwise). A network's readout is padded
to the largest group; the padded outputs are masked to zero and never move.

The returned warps are clamped to [0, 1]; ``raw`` warps (before clamping) feed the
monotonicity penalty.

``knots``: the network may be evaluated at ``knots`` equally spaced times only and its
output interpolated linearly to the ``Z`` output times (a ReLU network of one input is
piecewise linear anyway). The network then costs ``knots / Z`` of its full price;
``None`` evaluates it at every output time (the paper).
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from typing import Protocol, runtime_checkable

import torch
from torch import nn

from .._settings import INITS
from ._config import AlignmentConfig
from ._layout import GroupLayout

#: Network initialisations: Xavier everywhere (RTW), zeros everywhere (NTW), or Xavier
#: hidden layers with a zero readout (the warps start exactly at the identity while the
#: hidden units differ, so the network is not confined to a linear function as with zeros).


@runtime_checkable
class WarpModel(Protocol):
    """What the engine needs of a warp model (:class:`NeuralWarps`, :class:`SineWarps`).

    A new family of warps is a ``torch.nn.Module`` with these members; the engine trains
    its parameters with Adam against the method's loss.
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

    def parameter_groups(self) -> list[torch.Tensor]:
        """For every parameter (in ``parameters()`` order), the group of each index of its
        leading axis: what the trainer needs to keep each group's best iterate."""
        ...

    def subset(self, groups: torch.Tensor) -> WarpModel:
        """The warps of ``groups`` only (increasing indices): their parameters copied, every
        remaining series computed exactly as in the whole model. The trainer narrows the
        batch to the groups still running with it."""
        ...


def unit_time(n_points: int, dtype=torch.float64, device=None) -> torch.Tensor:
    """``zhat`` = ``(z - 1) / (Z - 1)`` for ``z = 1..Z``, shape (Z,)."""
    return torch.linspace(0.0, 1.0, n_points, dtype=dtype, device=device)


def _layout(groups: int | Sequence[int] | GroupLayout) -> GroupLayout:
    if isinstance(groups, GroupLayout):
        return groups
    if isinstance(groups, int):
        return GroupLayout.single(groups)
    sizes = [int(s) for s in groups]
    return GroupLayout.from_codes([g for g, size in enumerate(sizes) for _ in range(size)])


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


def _linear_stencil(n_values: int, times: torch.Tensor):
    position = times * (n_values - 1)
    left = torch.floor(position).long().clamp(0, n_values - 2)
    return left, (position - left).to(times.dtype)


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
    left, weight = _linear_stencil(values.shape[0], times)
    weight = weight.reshape(-1, *([1] * (values.ndim - 1)))
    return torch.lerp(values[left], values[left + 1], weight)


def _xavier(shape: tuple[int, ...], fan_in: int, fan_out: int, generator) -> torch.Tensor:
    """Xavier-uniform values (Glorot and Bengio, 2010) drawn from ``generator``."""
    bound = math.sqrt(6.0 / (fan_in + fan_out)) if fan_in + fan_out else 0.0
    values = torch.rand(shape, generator=generator, dtype=torch.float64)
    return (2.0 * values - 1.0) * bound


class NeuralWarps(nn.Module):
    """RTW/NTW warps: identity plus ``zhat (1 - zhat)`` times a network on the basis.

    Parameters
    ----------
    groups : int, sequence of int or GroupLayout
        Number of series (one group), the size of every group, or the layout of the
        stacked series.
    hidden : int
        Width ``H`` of the two hidden layers (the ``hidden_size`` knob).
    init : {"xavier", "zeros", "zero-readout"}
        The ``init`` knob.
    knots : int or None, default=None
        Evaluate the network at this many equally spaced times and interpolate linearly
        (None: at every output time).
    seeds : sequence of int, optional
        Seed of every group's initialisation (default: drawn from torch's global
        generator).
    dtype : torch.dtype, default=torch.float64
        Of the weights, the network's inputs and (through the parameters) the Adam
        moments (the ``warp_dtype`` knob); the offsets are returned in the times' dtype.
        The initial weights are the same draws in either precision.
    """

    def __init__(
        self,
        groups: int | Sequence[int] | GroupLayout,
        hidden: int,
        init: str,
        knots: int | None = None,
        seeds: Sequence[int] | None = None,
        dtype=torch.float64,
    ):
        super().__init__()
        self.mask: torch.Tensor
        self.u: torch.Tensor
        self.scale: torch.Tensor
        self._rows: torch.Tensor
        if knots is not None and knots < 2:
            raise ValueError(f"knots must be None or an integer >= 2, got {knots!r}")
        if init not in INITS:
            raise ValueError(f"init must be one of {INITS}, got {init!r}")
        layout = _layout(groups)
        self.layout = layout
        self.n_signals = layout.n_series
        self.knots = knots
        self.hidden = hidden
        sizes = layout.sizes.tolist()
        n_groups, n_out = len(sizes), max(sizes) - 1
        self.n_outputs = n_out
        if seeds is None:
            seeds = torch.randint(2**31 - 1, (n_groups,)).tolist()
        if len(seeds) != n_groups:
            raise ValueError(f"{len(seeds)} seeds for {n_groups} groups")
        w1 = torch.zeros(n_groups, 1, hidden, dtype=dtype)
        w2 = torch.zeros(n_groups, hidden, hidden, dtype=dtype)
        w3 = torch.zeros(n_groups, 2 * hidden + 1, max(n_out, 0), dtype=dtype)
        for g, (size, seed) in enumerate(zip(sizes, seeds, strict=True)):
            generator = torch.Generator().manual_seed(int(seed))
            if init != "zeros":
                w1[g] = _xavier((1, hidden), 1, hidden, generator)
                w2[g] = _xavier((hidden, hidden), hidden, hidden, generator)
            if init == "xavier" and size > 1:
                w3[g, :, : size - 1] = _xavier((2 * hidden + 1, size - 1), 2 * hidden + 1,
                                               size - 1, generator)  # fmt: skip
        self.w1 = nn.Parameter(w1)
        self.b1 = nn.Parameter(torch.zeros(n_groups, 1, hidden, dtype=dtype))
        self.w2 = nn.Parameter(w2)
        self.b2 = nn.Parameter(torch.zeros(n_groups, 1, hidden, dtype=dtype))
        self.w3 = nn.Parameter(w3)
        self.b3 = nn.Parameter(torch.zeros(n_groups, 1, max(n_out, 0), dtype=dtype))
        columns = torch.arange(max(n_out, 0))
        self.register_buffer(
            "mask", (columns < (layout.sizes - 1).unsqueeze(-1)).to(dtype).unsqueeze(1)
        )
        # each group's Householder vector u_g in R^{N_g}, zero-padded to the largest group
        entries = torch.arange(max(sizes))
        size = layout.sizes.to(dtype).unsqueeze(-1)
        u = torch.where(entries < layout.sizes.unsqueeze(-1), -1.0 / torch.sqrt(size), 0.0)
        u[:, 0] += 1.0
        norm_sq = (u * u).sum(-1)
        self.register_buffer("u", u.to(dtype))
        self.register_buffer(
            "scale",
            torch.where(norm_sq > 0, 2.0 / norm_sq.clamp_min(1e-300), 0.0).view(-1, 1, 1),
        )
        self.register_buffer("_rows", layout.codes * max(sizes) + layout.positions)
        self._stencil: tuple | None = None

    def parameter_groups(self) -> list[torch.Tensor]:
        groups = torch.arange(self.layout.n_groups, device=self.w1.device)
        return [groups for _ in self.parameters()]

    def subset(self, groups: torch.Tensor) -> NeuralWarps:
        """The networks of ``groups`` only; the readout keeps its padding, so every
        remaining series is computed exactly as in the whole model."""
        layout, _ = self.layout.to(self.w1.device).subset(groups)
        other = NeuralWarps.__new__(NeuralWarps)
        nn.Module.__init__(other)
        other.layout, other.n_signals = layout, layout.n_series
        other.knots, other.hidden, other.n_outputs = self.knots, self.hidden, self.n_outputs
        for name, parameter in self.named_parameters():
            setattr(other, name, nn.Parameter(parameter.detach()[groups].clone()))
        other.register_buffer("mask", self.mask[groups])
        other.register_buffer("u", self.u[groups])
        other.register_buffer("scale", self.scale[groups])
        other.register_buffer("_rows", layout.codes * self.u.shape[1] + layout.positions)
        other._stencil = self._stencil
        return other

    def network(self, times: torch.Tensor) -> torch.Tensor:
        """``phi_theta`` of every group at ``times`` (K,): shape (n_groups, K, N_max - 1)."""
        x = times.view(1, -1, 1).expand(self.w1.shape[0], -1, 1)
        h1 = torch.relu(torch.baddbmm(self.b1, x, self.w1))
        h2 = torch.relu(torch.baddbmm(self.b2, h1, self.w2))
        features = torch.cat([h2, h1, x], dim=-1)
        return torch.baddbmm(self.b3, features, self.w3) * self.mask

    def offsets(self, zhat: torch.Tensor) -> torch.Tensor:
        """``sum_k phi_theta(zhat)_k e_{k+1}`` of every series, shape (N, Z)."""
        if self.n_outputs < 1:
            raise RuntimeError("groups of one signal have no warp offsets")
        dtype = self.w1.dtype  # the network's (float32 or float64); the offsets: zhat's
        times = zhat.to(dtype)
        resample = self.knots is not None and self.knots < zhat.shape[0]
        if resample:
            assert self.knots is not None
            times = unit_time(self.knots, dtype=dtype, device=zhat.device)
        padded = torch.nn.functional.pad(self.network(times), (1, 0))  # (G, K, N_max)
        dot = padded @ self.u.unsqueeze(-1)  # (G, K, 1)
        combined = padded - self.scale * dot * self.u.unsqueeze(1)
        per_series = combined.transpose(1, 2).reshape(-1, times.shape[0])[self._rows]
        per_series = per_series.to(zhat.dtype)
        if not resample:
            return per_series
        left, weight = self._knot_stencil(zhat)
        return torch.lerp(per_series[:, left], per_series[:, left + 1], weight)

    def _knot_stencil(self, zhat: torch.Tensor):
        key = (zhat.shape[0], zhat.device)
        if self._stencil is None or self._stencil[0] != key:
            assert self.knots is not None
            self._stencil = (key, *_linear_stencil(self.knots, zhat))
        return self._stencil[1], self._stencil[2]

    def forward(self, zhat: torch.Tensor) -> torch.Tensor:
        """Raw warps, shape (N, Z)."""
        identity = zhat.expand(self.n_signals, -1)
        if self.n_outputs < 1:
            return identity
        return identity + (zhat * (1.0 - zhat)) * self.offsets(zhat)

    @staticmethod
    def finalise(raw: torch.Tensor) -> torch.Tensor:
        return raw.clamp(0.0, 1.0)


class SineWarps(nn.Module):
    """TTW warps from ``n_components`` discrete-sine-transform coefficients per signal.

    Parameters
    ----------
    groups : int, sequence of int or GroupLayout
        Number of series (one group), the size of every group, or the layout.
    n_components : int
        Sine terms K (the ``n_components`` knob).
    """

    def __init__(
        self,
        groups: int | Sequence[int] | GroupLayout,
        n_components: int,
        dtype=torch.float64,
    ):
        super().__init__()
        if n_components < 1:
            raise ValueError(f"n_components must be >= 1, got {n_components}")
        self.layout = _layout(groups)
        self.coefficients = nn.Parameter(
            torch.zeros(self.layout.n_series, n_components, dtype=dtype)
        )
        self._basis: tuple | None = None

    def parameter_groups(self) -> list[torch.Tensor]:
        return [self.layout.codes.to(self.coefficients.device)]

    def subset(self, groups: torch.Tensor) -> SineWarps:
        """The coefficients of the series of ``groups`` only."""
        layout, rows = self.layout.to(self.coefficients.device).subset(groups)
        other = SineWarps.__new__(SineWarps)
        nn.Module.__init__(other)
        other.layout = layout
        other.coefficients = nn.Parameter(self.coefficients.detach()[rows].clone())
        other._basis = self._basis
        return other

    def _sines(self, zhat: torch.Tensor) -> torch.Tensor:
        key = (zhat.shape[0], zhat.device)
        if self._basis is None or self._basis[0] != key:
            k = torch.arange(1, self.coefficients.shape[1] + 1, dtype=zhat.dtype,
                             device=zhat.device)  # fmt: skip
            basis = torch.sin(math.pi * k.unsqueeze(-1) * zhat)  # (K, Z)
            # sin(pi k) is ~1e-16 in floating point: make the end points exact
            basis = basis * ((zhat > 0) & (zhat < 1)).to(basis.dtype)
            self._basis = (key, basis)
        return self._basis[1]

    def forward(self, zhat: torch.Tensor) -> torch.Tensor:
        layout = self.layout.to(zhat.device)
        share = 1.0 / layout.sizes.to(zhat.dtype).unsqueeze(-1)
        centred = self.coefficients - layout.expand(layout.sum(self.coefficients) * share)
        return zhat + centred @ self._sines(zhat)

    @staticmethod
    def finalise(raw: torch.Tensor) -> torch.Tensor:
        return torch.cummax(raw.clamp(0.0, 1.0), dim=-1).values


def build_warps(
    config: AlignmentConfig, layout: GroupLayout, seeds: list[int]
) -> NeuralWarps | SineWarps:
    """The warp model a resolved configuration asks for: TTW's sine series, or the
    networks of RTW and NTW (one per group of ``layout``, seeded by ``seeds``)."""
    if config.warp == "sine":
        assert config.n_components is not None  # resolved for TTW
        return SineWarps(layout, config.n_components)
    assert config.hidden_size is not None and config.init is not None  # resolved for RTW, NTW
    dtype = torch.float32 if config.warp_dtype == "float32" else torch.float64
    return NeuralWarps(
        layout, config.hidden_size, config.init, config.warp_knots, seeds, dtype=dtype
    )
