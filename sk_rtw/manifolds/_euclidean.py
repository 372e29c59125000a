"""Euclidean space R^d."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._backend import safe_norm
from ._base import Manifold, power_of_two_scale

#: A window coordinate whose standard deviation is below this is only centred (aeon's
#: z-normalisation threshold).
STD_FLOOR = 1e-8


@dataclass(frozen=True)
class Euclidean(Manifold):
    """Euclidean space R^d: ``exp`` is addition, ``log`` subtraction.

    Parameters
    ----------
    dim : int, default=1
        Dimension ``d``; points have shape ``(d,)``. Univariate series use ``d = 1``.
    """

    dim: int = 1
    name = "euclidean"
    is_flat = True

    def __post_init__(self):
        _check_dim(self.dim, "Euclidean", minimum=1)

    @property
    def point_shape(self) -> tuple[int, ...]:
        return (self.dim,)

    @property
    def distance_segments(self):
        return ((0, self.dim, "euclidean"),)

    @property
    def intrinsic_dim(self) -> int:
        return self.dim

    def _to_coordinates(self, p, v):
        return v + 0.0 * p  # broadcast like the other spaces

    def _from_coordinates(self, p, c):
        return c + 0.0 * p

    def _exp(self, p, v):
        return p + v

    def _log(self, p, x):
        return x - p

    def _velocity(self, p, x):
        return x - p

    def _dist(self, p, x):
        return safe_norm(x - p)

    def _norm(self, p, v):
        return safe_norm(v)

    def _project(self, x):
        return x

    @property
    def normalised_space(self):
        return self

    def normalise_windows(self, windows):
        # aeon's z-normalisation: a constant coordinate is only centred
        windows = np.asarray(windows, dtype=np.float64)
        mean = windows.mean(axis=-2, keepdims=True)
        std = windows.std(axis=-2, keepdims=True)
        return (windows - mean) / np.where(std > STD_FLOOR, std, 1.0)

    def extreme_scale(self, points):
        return power_of_two_scale(float(np.abs(points).max(initial=0.0)))

    def _point_problems(self, x, atol):
        return []

    def _random_point(self, leading, rng):
        return rng.standard_normal((*leading, self.dim))

    def _random_tangent(self, p, scale, rng):
        return scale * rng.standard_normal(p.shape)


def _check_dim(dim, cls: str, minimum: int) -> None:
    if isinstance(dim, bool) or not isinstance(dim, (int, np.integer)) or dim < minimum:
        raise ValueError(f"{cls} needs an integer dim >= {minimum}, got {dim!r}")
