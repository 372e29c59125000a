"""Windowed sinc interpolation of manifold-valued series in local tangent spaces.

For signal ``n`` and output index ``z`` with warp value ``w = w_n[z]`` in [0, 1], the
continuous position in the signal is ``tau = w (T_n - 1)`` (0-based: ``w = 0`` is the first
sample, ``w = 1`` the last, so the boundary constraint maps ends onto ends). With
``b = floor(tau)`` and ``f = tau - b``, the samples ``m = b - nu, ..., b + nu`` (indices
clamped to ``[0, T_n - 1]``, i.e. the signal is extended by its end values) are mapped to
the tangent space at a tangent point ``p``, combined with the weights ``sinc(m - tau)`` and
mapped back with ``Exp_p`` (paper, eqs. 11-12). The tangent point is the centre sample
``x_n[b]``; ``refinements > 0`` refines it by Gauss–Newton steps
``p <- Exp_p(sum_m s_m Log_p(x_n[m]))``, which converge to the weighted Fréchet mean of the
window.

The truncated kernel is normalised to unit sum. Without that, ``p + sum_m s_m (x_m - p)``
would depend on the tangent point even in flat space; with it, Euclidean data give exactly
the (normalised) windowed sinc interpolation ``sum_m s_m x_m``, constant signals are
reproduced exactly on every manifold, and at integer positions the sample itself is
returned.

Computation. Because ``sinc(k - f) = (-1)^k sin(pi f) / (pi (f - k))``, the normalised
weights are ``c_k / sum_j c_j`` with the *barycentric* weights ``c_0 = 1`` and
``c_k = (-1)^k f / (f - k)`` (``k != 0``), which are finite at every ``f`` in [0, 1) and
need one division per tap. Their derivative ``dc_k/df = (-1)^k (-k) / (f - k)^2`` gives the
derivative of the interpolated tangent vector in closed form, so one custom autograd
function computes the value and its derivative in a single pass and keeps only the
derivative (``N x Z x D`` numbers) for the backward pass: the ``N x Z x K`` weight tensors
are never stored, and the work is done in chunks of output indices, so memory stays
bounded for any number of signals and for the full sinc.

The tangent vectors of each window at its centre sample, ``Log_{x[b]}(x[b + k])``, do not
depend on the warps: without refinement they are computed once per fit (for every ``b``,
``N x T x K`` of them) and each epoch only gathers them. Gradients flow through the
weights only: the tangent point is a choice of chart, found without gradient tracking.

``window=None`` uses every sample of the signal (the full, unwindowed sinc of NTW).
"""

from __future__ import annotations

import copy
import math

import torch

from .._backend import inner
from .._resources import available_memory
from ..manifolds import Manifold
from ._sinc_kernel import window_sums

#: Values gathered at once (per chunk of output indices); bounds the transient memory.
CHUNK_ELEMENTS = 2**21
#: Largest table of precomputed window vectors kept for a fit, in bytes, unless an eighth
#: of the free memory is more (see :func:`table_budget`).
TABLE_BYTES = 512 * 2**20


def table_budget(device: torch.device) -> int:
    """Bytes the table of window vectors may take: :data:`TABLE_BYTES`, or on the CPU an
    eighth of the free memory when that is more. The table is a cache: without it the
    window vectors are recomputed in every epoch, which slows the long alignments whose
    table outgrows a fixed cap (8 quaternion series of 256,000 samples need 1.4 GB)."""
    if torch.device(device).type != "cpu":
        return TABLE_BYTES
    return max(TABLE_BYTES, available_memory() // 8)


def barycentric_weights(
    offsets: torch.Tensor, frac: torch.Tensor
) -> tuple[torch.Tensor, torch.Tensor]:
    """Barycentric sinc weights ``c_k(f)`` and their derivatives ``dc_k/df``.

    ``c_k = (-1)^k f / (f - k)`` for ``k != 0`` and ``c_0 = 1``: proportional to
    ``sinc(k - f)`` (the factor ``pi f / sin(pi f)`` cancels in the normalised kernel).

    Parameters
    ----------
    offsets : torch.Tensor
        Integer tap offsets ``k`` (as floats), broadcastable to ``frac[..., None]``.
    frac : torch.Tensor
        Fractional positions ``f`` in [0, 1).

    Returns
    -------
    weights, derivatives : torch.Tensor
        Both of the broadcast shape ``(*frac.shape, n_taps)``.
    """
    f = frac.unsqueeze(-1)
    centre = offsets == 0
    sign = 1.0 - 2.0 * torch.remainder(offsets, 2.0)
    gap = torch.where(centre, 1.0, f - offsets)
    signed_inverse = sign / gap
    weights = torch.where(centre, 1.0, f * signed_inverse)
    derivatives = torch.where(centre, 0.0, -offsets * signed_inverse / gap)
    return weights, derivatives


class SincInterpolator:
    """Tangent-space windowed sinc interpolation of N series, prepared once per fit.

    Parameters
    ----------
    manifold : Manifold
    data : torch.Tensor, shape (N, T_max, *point_shape)
        Series padded to ``T_max`` (padding is ignored: indices are clamped per series).
    lengths : torch.Tensor of int, shape (N,)
        True length ``T_n`` of each series.
    window : int or None, default=10
        Half-width ``nu`` of the sinc window; None for the full sinc over all samples.
    refinements : int, default=0
        Gauss–Newton refinements of the tangent point (ignored on flat manifolds, where
        the result does not depend on it).
    """

    def __init__(
        self,
        manifold: Manifold,
        data: torch.Tensor,
        lengths: torch.Tensor,
        window: int | None = 10,
        refinements: int = 0,
    ):
        self.manifold = manifold
        self.data = data
        self.lengths = lengths.to(data.device)
        self.window = window
        self.refinements = 0 if manifold.is_flat else int(refinements)
        n_series, t_max = data.shape[:2]
        self.point_shape = tuple(manifold.point_shape)
        self.point_size = math.prod(self.point_shape)
        self.n_taps = t_max if window is None else 2 * window + 1
        self._rows = torch.arange(n_series, device=data.device).view(-1, 1)
        self._last = (self.lengths - 1).view(-1, 1)
        if window is None:
            self._samples = torch.arange(t_max, device=data.device)
            self._valid = (self._samples < self.lengths.view(-1, 1)).unsqueeze(1)  # (N, 1, T)
        else:
            self._taps = torch.arange(-window, window + 1, device=data.device)
        self.table = self._build_table()

    def subset(self, rows: torch.Tensor) -> SincInterpolator:
        """The interpolator of the series ``rows`` only (indices, in order), its table
        sliced rather than rebuilt: each series is interpolated exactly as before."""
        other = copy.copy(self)
        other.data = self.data[rows]
        other.lengths = self.lengths[rows]
        other._rows = torch.arange(len(rows), device=self.data.device).view(-1, 1)
        other._last = self._last[rows]
        if self.window is None:
            other._valid = self._valid[rows]
        other.table = None if self.table is None else self.table[rows]
        return other

    # ------------------------------------------------------------------ setup
    def _build_table(self) -> torch.Tensor | None:
        """Window vectors for every centre sample ``b``: (N, T_max, K, *point_shape).

        Flat manifolds with the windowed sinc store the (clamped) window samples; curved
        manifolds without refinement store their logs at the centre sample. None when
        nothing is gained (flat full sinc: one matrix product) or the table would exceed
        :func:`table_budget` (the vectors are then computed chunk by chunk).
        """
        flat = self.manifold.is_flat
        if (flat and self.window is None) or (not flat and self.refinements > 0):
            return None
        n_series, t_max = self.data.shape[:2]
        size = n_series * t_max * self.n_taps * self.point_size * self.data.element_size()
        if size > table_budget(self.data.device):
            return None
        with torch.no_grad():
            centres = torch.arange(t_max, device=self.data.device).expand(n_series, -1)
            if flat:
                return self._window_samples(centres)
            table = self.data.new_empty(n_series, t_max, self.n_taps, *self.point_shape)
            for part in self._chunks(t_max):  # the logs' temporaries stay chunk-sized
                samples = self._window_samples(centres[:, part])
                table[:, part] = self._logs(self.data[:, part], samples)
            return table

    # -------------------------------------------------------------- geometry
    def _window_samples(self, base: torch.Tensor) -> torch.Tensor:
        """The samples of each window, shape (N, c, K, *point_shape), for centres (N, c)."""
        if self.window is None:
            return self.data.unsqueeze(1).expand(-1, base.shape[1], *self.data.shape[1:])
        index = base.unsqueeze(-1) + self._taps
        index = torch.minimum(index.clamp_min(0), self._last.unsqueeze(-1))
        return self.data[self._rows.unsqueeze(-1), index]

    def _logs(self, anchors: torch.Tensor, samples: torch.Tensor) -> torch.Tensor:
        """``Log_anchor(sample)`` for anchors (N, c, *ps) and samples (N, c, K, *ps)."""
        nd = len(self.point_shape)
        return self.manifold._log(anchors.unsqueeze(-nd - 1), samples)

    def _offsets(self, base: torch.Tensor) -> torch.Tensor:
        """Tap offsets ``k`` relative to the centres: (K,) windowed, (N, c, T) full."""
        if self.window is None:
            return (self._samples - base.unsqueeze(-1)).to(self.data.dtype)
        return self._taps.to(self.data.dtype)

    def _weights(self, base: torch.Tensor, frac: torch.Tensor):
        weights, derivatives = barycentric_weights(self._offsets(base), frac)
        if self.window is None:  # samples beyond T_n are padding
            valid = self._valid.to(weights.dtype)
            weights, derivatives = weights * valid, derivatives * valid
        return weights, derivatives

    def _combine(self, weights: torch.Tensor, values: torch.Tensor | None) -> torch.Tensor:
        """``sum_k weights_k values_k`` -> (N, c, D); values None means the raw series."""
        if values is None:  # flat full sinc: one batched matrix product
            return torch.bmm(weights, self.data.reshape(*self.data.shape[:2], -1))
        values = values.reshape(*values.shape[:3], self.point_size)
        return (weights.unsqueeze(-1) * values).sum(-2)

    def _values(self, base: torch.Tensor, anchors: torch.Tensor | None):
        """Window vectors for centres (N, c) in the chart of ``anchors`` (N, c, *ps)."""
        if self.table is not None:
            return self.table[self._rows, base]
        if self.manifold.is_flat:
            return None if self.window is None else self._window_samples(base)
        if anchors is None:
            raise ValueError("curved manifolds need tangent points")
        return self._logs(anchors, self._window_samples(base))

    def _chunks(self, n_points: int):
        n_series = self.data.shape[0]
        step = max(1, CHUNK_ELEMENTS // max(1, n_series * self.n_taps * self.point_size))
        return [slice(start, start + step) for start in range(0, n_points, step)]

    # --------------------------------------------------------- interpolation
    def positions(self, warps: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """Centre samples ``b`` (long) and fractional parts ``f`` of ``tau = w (T_n - 1)``."""
        tau = warps * self._last.to(warps.dtype)
        base = torch.floor(tau).detach()
        frac = tau - base
        base = torch.minimum(base.long().clamp_min(0), self._last)  # NaN warps stay in range
        return base, frac

    def anchors(self, base: torch.Tensor, frac: torch.Tensor) -> torch.Tensor:
        """Tangent points (N, Z, *ps): the centre samples, refined if asked (no gradient)."""
        centres = self.data[self._rows, base]
        if self.refinements == 0:
            return centres
        out = torch.empty_like(centres)
        with torch.no_grad():
            for part in self._chunks(base.shape[1]):
                b, anchor = base[:, part], centres[:, part]
                weights, _ = self._weights(b, frac[:, part])
                weights = weights / weights.sum(-1, keepdim=True)
                samples = self._window_samples(b)
                for _ in range(self.refinements):
                    step = self._combine(weights, self._logs(anchor, samples))
                    anchor = self.manifold._exp(anchor, step.reshape(anchor.shape))
                out[:, part] = anchor
        return out

    def window_sums(
        self, base: torch.Tensor, frac: torch.Tensor, anchors: torch.Tensor | None
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """Interpolated tangent vectors ``u`` and ``du/df``, both (N, Z, D), no gradient."""
        n_series, n_points = frac.shape
        u = frac.new_empty(n_series, n_points, self.point_size)
        du = torch.empty_like(u)
        if frac.device.type == "cpu":
            self._window_sums_cpu(base, frac, anchors, u, du)
        else:
            self._window_sums_torch(base, frac, anchors, u, du)
        return u, du

    def _window_sums_torch(self, base, frac, anchors, u, du) -> None:
        """:meth:`window_sums` with torch operations, chunk by chunk (any device)."""
        for part in self._chunks(frac.shape[1]):
            b = base[:, part]
            weights, derivatives = self._weights(b, frac[:, part])
            values = self._values(b, None if anchors is None else anchors[:, part])
            total = weights.sum(-1, keepdim=True)
            value = self._combine(weights, values) / total
            slope = derivatives.sum(-1, keepdim=True)
            u[:, part] = value
            du[:, part] = (self._combine(derivatives, values) - value * slope) / total

    def _window_sums_cpu(self, base, frac, anchors, u, du) -> None:
        """:meth:`window_sums` by the numba kernel: one pass, no weight tensors."""
        window = -1 if self.window is None else self.window
        lengths = self.lengths.numpy()
        n_series, n_points = frac.shape
        if self.table is not None or (self.manifold.is_flat and self.window is None):
            if self.table is not None:
                values, rows = self.table, base
            else:  # flat full sinc: the taps are the samples themselves, for every point
                values, rows = self.data.unsqueeze(1), torch.zeros_like(base)
            values = values.reshape(*values.shape[:3], self.point_size).contiguous()
            window_sums(
                values.numpy(), rows.numpy(), base.numpy(), frac.numpy(), lengths, window,
                u.numpy(), du.numpy(),
            )  # fmt: skip
            return
        for part in self._chunks(n_points):
            b = base[:, part]
            values = self._values(b, None if anchors is None else anchors[:, part])
            values = values.reshape(*values.shape[:3], self.point_size).contiguous()
            rows = torch.arange(b.shape[1]).expand(n_series, -1)
            window_sums(
                values.numpy(), rows.numpy(), b.numpy(), frac[:, part].numpy(), lengths,
                window, u[:, part].numpy(), du[:, part].numpy(),
            )  # fmt: skip

    def __call__(self, warps: torch.Tensor) -> torch.Tensor:
        """Resample every series at its warped positions.

        Parameters
        ----------
        warps : torch.Tensor, shape (N, Z)
            Warp values in [0, 1]; the result is differentiable with respect to them.

        Returns
        -------
        torch.Tensor, shape (N, Z, *point_shape)
        """
        base, frac = self.positions(warps)
        anchors = None if self.manifold.is_flat else self.anchors(base, frac.detach())
        vectors = _WindowSum.apply(frac, self, base, anchors)
        vectors = vectors.reshape(*vectors.shape[:2], *self.point_shape)
        if anchors is None:
            return vectors
        return self.manifold._exp(anchors, vectors)


class _WindowSum(torch.autograd.Function):
    """``u(f) = sum_k c_k(f) V_k / sum_k c_k(f)``; backward ``grad_f = <grad_u, du/df>``."""

    @staticmethod
    def forward(ctx, frac, interpolator, base, anchors):
        u, du = interpolator.window_sums(base, frac.detach(), anchors)
        ctx.save_for_backward(du)
        return u

    @staticmethod
    def backward(ctx, grad):
        (du,) = ctx.saved_tensors
        return inner(grad, du), None, None, None


def tangent_sinc_interpolate(
    manifold: Manifold,
    data: torch.Tensor,
    lengths: torch.Tensor,
    warps: torch.Tensor,
    window: int | None = 10,
    refinements: int = 0,
) -> torch.Tensor:
    """Resample every series at its warped positions, in the tangent spaces.

    Parameters
    ----------
    manifold : Manifold
    data : torch.Tensor, shape (N, T_max, *point_shape)
        Series padded to ``T_max`` (padding is ignored: indices are clamped per series).
    lengths : torch.Tensor of int, shape (N,)
        True length ``T_n`` of each series.
    warps : torch.Tensor, shape (N, Z)
        Warp values in [0, 1]; the result is differentiable with respect to them.
    window : int or None, default=10
        Half-width ``nu`` of the sinc window; None for the full sinc over all samples.
    refinements : int, default=0
        Gauss–Newton refinements of the tangent point (skipped on flat manifolds, where
        the result does not depend on it).

    Returns
    -------
    torch.Tensor, shape (N, Z, *point_shape)
    """
    return SincInterpolator(manifold, data, lengths, window, refinements)(warps)
