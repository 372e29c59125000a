"""Riemannian manifolds: geometry for numpy arrays and differentiable torch tensors."""

from ._base import Manifold
from ._euclidean import Euclidean
from ._product import Product
from ._registry import ManifoldSpec, available_manifolds, get_manifold
from ._spd import SPD
from ._sphere import Quaternion, Sphere

__all__ = [
    "SPD",
    "Euclidean",
    "Manifold",
    "ManifoldSpec",
    "Product",
    "Quaternion",
    "Sphere",
    "available_manifolds",
    "get_manifold",
]
