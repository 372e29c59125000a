"""Riemannian manifolds: geometry for numpy arrays and differentiable torch tensors."""

from ._base import Manifold
from ._check import ManifoldCheckError, check_manifold
from ._compiled import compiled_maps
from ._euclidean import Euclidean
from ._product import Product
from ._registry import ManifoldSpec, available_manifolds, get_manifold, register_manifold
from ._spd import SPD
from ._sphere import Quaternion, Sphere, quaternion_conjugate, quaternion_product

__all__ = [
    "SPD",
    "Euclidean",
    "Manifold",
    "ManifoldCheckError",
    "ManifoldSpec",
    "Product",
    "Quaternion",
    "Sphere",
    "available_manifolds",
    "check_manifold",
    "compiled_maps",
    "get_manifold",
    "quaternion_conjugate",
    "quaternion_product",
    "register_manifold",
]
