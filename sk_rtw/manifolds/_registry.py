"""Names for manifolds, and resolution of a name against the shape of the data."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from ._base import Manifold
from ._euclidean import Euclidean
from ._product import Product
from ._spd import SPD
from ._sphere import Quaternion, Sphere


@dataclass(frozen=True)
class ManifoldSpec:
    """Registry entry: how to build a manifold from a dimension or from a point shape."""

    name: str
    factory: Callable[[int | None], Manifold]
    dim_from_point_shape: Callable[[tuple[int, ...]], int | None]
    description: str
    matrix_valued: bool = False
    sign_invariant: bool = False
    flat: bool = False


def _euclidean_dim(shape):
    if shape == ():
        return 1
    return shape[0] if len(shape) == 1 else None


def _sphere_dim(shape):
    return shape[0] - 1 if len(shape) == 1 and shape[0] >= 2 else None


def _spd_dim(shape):
    return shape[0] if len(shape) == 2 and shape[0] == shape[1] else None


def _fixed(size):
    return lambda shape: 0 if shape == (size,) else None


def _given(dim: int | None) -> int:
    """The dimension a spec's ``infer`` found (always set by the time a factory runs)."""
    if dim is None:
        raise ValueError("the manifold's dimension could not be inferred")
    return dim


def _pose(_dim=None) -> Product:
    return Product((Euclidean(3), Quaternion()))


_REGISTRY: dict[str, ManifoldSpec] = {
    spec.name: spec
    for spec in [
        ManifoldSpec(
            "euclidean",
            lambda d: Euclidean(_given(d)),
            _euclidean_dim,
            "R^d; univariate series are R^1",
            flat=True,
        ),
        ManifoldSpec(
            "sphere", lambda d: Sphere(_given(d)), _sphere_dim, "unit sphere S^d in R^(d+1)"
        ),
        ManifoldSpec(
            "quaternion",
            lambda d: Quaternion(),
            _fixed(4),
            "unit quaternions (w, x, y, z), q ~ -q",
            sign_invariant=True,
        ),
        ManifoldSpec(
            "spd",
            lambda d: SPD(_given(d)),
            _spd_dim,
            "SPD(k) matrices, affine-invariant metric",
            matrix_valued=True,
        ),
        ManifoldSpec(
            "pose",
            _pose,
            _fixed(7),
            "R^3 x S^3 poses (x, y, z, qw, qx, qy, qz)",
            sign_invariant=True,
        ),
    ]
}
#: The names the package ships (never replaced by :func:`register_manifold`).
_BUILT_IN = frozenset(_REGISTRY)
#: Spaces with one dimension only, and that dimension (S^3; 3 + 3 for R^3 x S^3).
_FIXED_DIMENSION = {"quaternion": 3, "pose": 6}


def register_manifold(spec: ManifoldSpec, *, replace: bool = False) -> None:
    """Give a manifold of your own a name: ``manifold="name"`` then works wherever a
    built-in name does (``get_manifold``, the DTW functions, ``align``, the estimators).

    A new space is one file -- a :class:`Manifold` subclass with ``point_shape``,
    ``_exp`` and ``_log`` (:func:`check_manifold` tests it) -- plus this registration.
    Its DTW runs on its own ``pairwise_dist`` (derived from ``_log`` unless overridden);
    where its distance is made of the kinds the compiled kernels know
    (``distance_segments``: "euclidean", "sphere", "sign-invariant sphere", "spd"), the
    kernels compute it, with lower bounds for the nearest-neighbour search.

    Parameters
    ----------
    spec : ManifoldSpec
        Its name (lower case), a factory from a dimension (``None`` for a space of one
        dimension), how to read the dimension from a point shape, and a description.
    replace : bool, default=False
        Replace a name registered earlier (never a built-in one).

    Raises
    ------
    TypeError
        ``spec`` is no ManifoldSpec, or its factory or reader is not callable.
    ValueError
        The name is empty, not lower case, or taken.

    Examples
    --------
    >>> from sk_rtw.manifolds import Euclidean, ManifoldSpec, register_manifold
    >>> plane = ManifoldSpec("plane", lambda d: Euclidean(2),
    ...                      lambda shape: 2 if shape == (2,) else None, "R^2")
    >>> register_manifold(plane)  # doctest: +SKIP
    >>> get_manifold("plane", point_shape=(2,))  # doctest: +SKIP
    Euclidean(dim=2)
    """
    if not isinstance(spec, ManifoldSpec):
        raise TypeError(f"register_manifold needs a ManifoldSpec, got {type(spec).__name__}")
    if not callable(spec.factory) or not callable(spec.dim_from_point_shape):
        raise TypeError(
            f"ManifoldSpec {spec.name!r}: factory and dim_from_point_shape must be callable"
        )
    if not isinstance(spec.name, str) or not spec.name or spec.name != spec.name.lower():
        raise ValueError(
            f"a manifold's name must be a non-empty lower-case str, got {spec.name!r}"
        )
    if spec.name in _BUILT_IN:
        raise ValueError(f"{spec.name!r} is a built-in manifold; choose another name")
    if spec.name in _REGISTRY and not replace:
        raise ValueError(
            f"a manifold named {spec.name!r} is registered already; pass replace=True to "
            "replace it"
        )
    _REGISTRY[spec.name] = spec


def available_manifolds() -> dict[str, ManifoldSpec]:
    """The registry: manifold names mapped to their specification.

    Returns
    -------
    registry : dict of str to ManifoldSpec
        For example ``"sphere"``, whose spec builds ``Sphere(d)`` from a point shape
        ``(d + 1,)``.
    """
    return dict(_REGISTRY)


def get_manifold(
    manifold: str | Manifold = "euclidean",
    dim: int | None = None,
    *,
    point_shape: tuple[int, ...] | None = None,
) -> Manifold:
    """Build (or check) a manifold from a name, a dimension and/or the data's point shape.

    Parameters
    ----------
    manifold : str or Manifold, default="euclidean"
        A registry name (``"euclidean"``, ``"sphere"``, ``"quaternion"``, ``"spd"``,
        ``"pose"``) or a manifold object, which is returned unchanged after checking it
        against ``point_shape``.
    dim : int, optional
        Dimension for the named space (``d`` of R^d or S^d, ``k`` of SPD(k)).
    point_shape : tuple of int, optional
        Shape of one point of the data at hand (``()`` for univariate series). Used to
        infer ``dim`` when it is not given, and to check it when it is.

    Returns
    -------
    Manifold

    Examples
    --------
    >>> get_manifold("sphere", dim=2)
    Sphere(dim=2)
    >>> get_manifold("spd", point_shape=(3, 3))
    SPD(dim=3)
    """
    if isinstance(manifold, Manifold):
        if dim is not None:
            raise ValueError("dim can only be given together with a manifold name")
        if point_shape is not None:
            _check_point_shape(manifold, point_shape)
        return manifold
    if not isinstance(manifold, str):
        raise TypeError(
            f"manifold must be a name or a Manifold object, got {type(manifold).__name__}"
        )
    key = manifold.lower()
    if key not in _REGISTRY:
        raise ValueError(f"unknown manifold {manifold!r}; choose one of {sorted(_REGISTRY)}")
    spec = _REGISTRY[key]
    if dim is not None and key in _FIXED_DIMENSION:
        fixed = spec.factory(None)
        if dim != _FIXED_DIMENSION[key]:
            raise ValueError(
                f"{manifold!r} has a fixed dimension ({fixed!r}, points of shape "
                f"{fixed.point_shape}); got dim={dim!r}. Leave dim out."
            )
    if dim is None and key not in _FIXED_DIMENSION:
        if point_shape is None:
            raise ValueError(
                f"manifold {manifold!r} needs a dimension: pass dim=... or data to infer it from"
            )
        dim = spec.dim_from_point_shape(tuple(point_shape))
        if dim is None:
            raise ValueError(
                f"data with points of shape {tuple(point_shape)} do not fit manifold "
                f"{manifold!r} ({spec.description})"
            )
    result = spec.factory(dim)
    if not isinstance(result, Manifold):
        raise TypeError(
            f"the factory of the registered manifold {key!r} returned a "
            f"{type(result).__name__}, not a Manifold: ManifoldSpec.factory must build the "
            "manifold object from a dimension (e.g. lambda d: MySpace(d))"
        )
    if point_shape is not None:
        _check_point_shape(result, point_shape)
    return result


def _check_point_shape(manifold: Manifold, point_shape: tuple[int, ...]) -> None:
    shape = tuple(point_shape)
    if shape == () and manifold.point_shape == (1,):
        return
    if shape != manifold.point_shape:
        raise ValueError(
            f"data with points of shape {shape} do not fit {manifold!r}, whose points have "
            f"shape {manifold.point_shape}"
        )
