"""Cartesian products of manifolds, e.g. poses R^3 x S^3."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import torch

from ._base import Manifold


@dataclass(frozen=True)
class Product(Manifold):
    """Product manifold ``M_1 x … x M_m`` with the product metric.

    A point is the concatenation of the flattened factor points, so a pose
    ``R^3 x S^3`` is 7 numbers ``(x, y, z, qw, qx, qy, qz)``: ``point_shape`` is
    ``(sum_i prod(point_shape_i),)`` and a series is ``(T, point_shape[0])``. The distance is
    ``sqrt(sum_i dist_i^2)``; ``exp`` and ``log`` act factor by factor.

    Parameters
    ----------
    factors : tuple of Manifold
        The factor spaces, in the order their coordinates appear.
    """

    factors: tuple[Manifold, ...] = ()
    name = "product"

    def __post_init__(self):
        factors = tuple(self.factors)
        if not factors or not all(isinstance(f, Manifold) for f in factors):
            raise ValueError("Product needs a non-empty sequence of Manifold objects")
        object.__setattr__(self, "factors", factors)

    @property
    def is_flat(self) -> bool:  # type: ignore[override]
        return all(f.is_flat for f in self.factors)

    @property
    def _sizes(self) -> list[int]:
        return [math.prod(f.point_shape) for f in self.factors]

    @property
    def point_shape(self) -> tuple[int, ...]:
        return (sum(self._sizes),)

    @property
    def injectivity_radius(self) -> float:
        return min(f.injectivity_radius for f in self.factors)

    @property
    def intrinsic_dim(self) -> int:
        return sum(f.intrinsic_dim for f in self.factors)

    def _to_coordinates(self, p, v):
        p, v = torch.broadcast_tensors(p, v)
        return torch.cat(
            [f._to_coordinates(a, b)
             for f, a, b in zip(self.factors, self._split(p), self._split(v), strict=True)],
            dim=-1,
        )  # fmt: skip

    def _from_coordinates(self, p, c):
        lead = torch.broadcast_shapes(p.shape[:-1], c.shape[:-1])
        p, c = p.expand(*lead, p.shape[-1]), c.expand(*lead, c.shape[-1])
        parts = torch.split(c, [f.intrinsic_dim for f in self.factors], dim=-1)
        return self._join(
            [f._from_coordinates(a, b)
             for f, a, b in zip(self.factors, self._split(p), parts, strict=True)],
            self.factors,
        )  # fmt: skip

    @property
    def velocity_dim(self) -> int:
        return sum(f.velocity_dim for f in self.factors)

    def _velocity(self, p, x):
        p, x = torch.broadcast_tensors(p, x)
        return torch.cat(
            [f._velocity(a, b)
             for f, a, b in zip(self.factors, self._split(p), self._split(x), strict=True)],
            dim=-1,
        )  # fmt: skip

    @property
    def normalised_space(self):
        spaces = [f.normalised_space for f in self.factors]
        if any(space is None for space in spaces):
            return None
        return Product(tuple(spaces))

    def normalise_windows(self, windows):
        windows = np.asarray(windows, dtype=np.float64)
        parts, offset = [], 0
        for factor, size in zip(self.factors, self._sizes, strict=True):
            part = windows[..., offset : offset + size]
            part = part.reshape(*part.shape[:-1], *factor.point_shape)
            normal = factor.normalise_windows(part)
            width = int(np.prod(factor.normalised_space.point_shape))
            parts.append(normal.reshape(*windows.shape[:-1], width))
            offset += size
        return np.concatenate(parts, axis=-1)

    @property
    def distance_segments(self):
        segments, offset = [], 0
        for factor, size in zip(self.factors, self._sizes, strict=True):
            own = factor.distance_segments
            if own is None:
                return None
            segments.extend((offset + a, offset + b, kind) for a, b, kind in own)
            offset += size
        return tuple(segments)

    def continuous(self, series):
        series = np.array(series, dtype=np.float64)
        bounds = np.cumsum([0, *self._sizes])
        for factor, start, stop in zip(self.factors, bounds[:-1], bounds[1:], strict=True):
            part = series[..., start:stop]
            part = part.reshape(*part.shape[:-1], *factor.point_shape)
            fixed = factor.continuous(part)
            series[..., start:stop] = fixed.reshape(
                *fixed.shape[: fixed.ndim - factor.point_ndim], -1
            )
        return series

    def _split(self, x):
        parts = torch.split(x, self._sizes, dim=-1)
        return [
            part.reshape(*part.shape[:-1], *f.point_shape)
            for part, f in zip(parts, self.factors, strict=True)
        ]

    @staticmethod
    def _join(parts, factors):
        return torch.cat(
            [
                part.reshape(*part.shape[: part.ndim - f.point_ndim], -1)
                for part, f in zip(parts, factors, strict=True)
            ],
            dim=-1,
        )

    def _map(self, method: str, a, b):
        return self._join(
            [
                getattr(f, method)(pa, pb)
                for f, pa, pb in zip(self.factors, self._split(a), self._split(b), strict=True)
            ],
            self.factors,
        )

    def _exp(self, p, v):
        return self._map("_exp", p, v)

    def _log(self, p, x):
        return self._map("_log", p, x)

    def _combine(self, method: str, a, b):
        squares = [
            getattr(f, method)(pa, pb) ** 2
            for f, pa, pb in zip(self.factors, self._split(a), self._split(b), strict=True)
        ]
        total = torch.stack(torch.broadcast_tensors(*squares)).sum(0)
        positive = total > 0
        return torch.where(positive, torch.sqrt(torch.where(positive, total, 1.0)), 0.0)

    def _dist(self, p, x):
        return self._combine("_dist", p, x)

    def _norm(self, p, v):
        return self._combine("_norm", p, v)

    def _beyond_injectivity(self, p, v):
        p, v = torch.broadcast_tensors(p, v)
        parts = zip(self.factors, self._split(p), self._split(v), strict=True)
        flags = [f._beyond_injectivity(a, b) for f, a, b in parts]
        return torch.stack(flags).any(0)

    def _project(self, x):
        return self._join(
            [f._project(part) for f, part in zip(self.factors, self._split(x), strict=True)],
            self.factors,
        )

    def _point_problems(self, x, atol):
        problems = []
        for i, (f, part) in enumerate(zip(self.factors, self._split(x), strict=True)):
            for mask, text in f._point_problems(part, atol):
                if callable(text):  # describes the factor's part of the first point
                    problems.append((mask, _factor_text(self, i, f, text)))
                else:
                    problems.append((mask, f"factor {i} ({f!r}): {text}"))
        return problems

    def _random_point(self, leading, rng):
        parts = [f._random_point(leading, rng).reshape(*leading, -1) for f in self.factors]
        return np.concatenate(parts, axis=-1)

    def _random_tangent(self, p, scale, rng):
        lead = p.shape[:-1]
        parts = np.split(p, np.cumsum(self._sizes)[:-1], axis=-1)
        out = [
            f._random_tangent(part.reshape(*lead, *f.point_shape), scale, rng).reshape(*lead, -1)
            for f, part in zip(self.factors, parts, strict=True)
        ]
        return np.concatenate(out, axis=-1)


def _factor_text(product: Product, i: int, factor: Manifold, describe):
    """A description of a product point made from its ``i``-th factor's description."""

    def text(point):
        return f"factor {i} ({factor!r}): {describe(product._split(point)[i])}"

    return text
