"""A manifold of one's own in one file: the circle S^1 read as angles in (-pi, pi].

Used by ``test_user_manifold.py`` to show what a new space needs: ``point_shape``,
``_exp`` and ``_log`` (the rest is derived), and one registration.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import torch

from sk_rtw.manifolds import Manifold, ManifoldSpec


def wrap(angle: torch.Tensor) -> torch.Tensor:
    """An angle in (-pi, pi]."""
    return torch.atan2(torch.sin(angle), torch.cos(angle))


@dataclass(frozen=True)
class CircleAngle(Manifold):
    """S^1 with points as angles: ``log`` the wrapped difference, ``exp`` the wrapped sum."""

    name = "circle-angle"

    @property
    def point_shape(self):
        return (1,)

    @property
    def injectivity_radius(self):
        return math.pi

    def _exp(self, p, v):
        return wrap(p + v)

    def _log(self, p, x):
        return wrap(x - p)

    def _project(self, x):
        return wrap(x)


SPEC = ManifoldSpec(
    "circle-angle",
    lambda dim: CircleAngle(),
    lambda shape: 0 if shape in ((), (1,)) else None,
    "the circle S^1 as angles in (-pi, pi]",
)
