"""``check_manifold``: the contract every space must meet, public for the spaces you write.

In the spirit of scikit-learn's ``check_estimator``: the properties the package's own
manifolds are tested for, run on a manifold object before it is aligned or averaged.
Points come from :meth:`Manifold.random_point` or are given; tangent vectors are drawn
with :meth:`Manifold.random_tangent` where the space has it, else made from the logs
between the points (so ``exp`` and ``log`` are all a new space needs).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import torch

from ._base import Manifold
from ._point_kernels import kernel_points, robust_distance, segment_codes


class ManifoldCheckError(AssertionError):
    """A manifold broke one of the properties of :func:`check_manifold`."""


def _fail(manifold: Manifold, check: str, detail: str) -> None:
    raise ManifoldCheckError(f"{manifold!r} fails '{check}': {detail}")


def _close(manifold, check, actual, expected, atol):
    error = float(np.max(np.abs(np.asarray(actual) - np.asarray(expected)), initial=0.0))
    if not np.isfinite(error) or error > atol:
        _fail(manifold, check, f"largest error {error:.3g} > {atol:g}")


def check_manifold(
    manifold: Manifold,
    points: np.ndarray | None = None,
    *,
    n_points: int = 8,
    random_state: int = 0,
    atol: float = 1e-7,
) -> list[str]:
    """Check that ``manifold`` meets the contract the alignment engine relies on.

    Properties checked, on the given or drawn points and tangent vectors at them:
    the points validate; ``exp(p, 0) = p`` and ``log(p, p) = 0``; ``log`` inverts
    ``exp`` and ``exp`` inverts ``log`` within half the injectivity radius; ``exp``
    lands on the manifold; the distance is symmetric, non-negative, zero on the
    diagonal, satisfies the triangle inequality and equals the norm of the log;
    ``pairwise_dist`` equals ``dist``; the compiled DTW distance (from
    ``distance_segments``, where the manifold declares them) equals ``dist``; numpy and
    torch give the same numbers; the mean of identical points is that point and the mean
    of two is the geodesic midpoint; the gradients of ``exp``, ``log`` and the squared
    distance are finite at zero tangent vectors and at coincident points; tangent
    coordinates (where defined) round-trip and preserve the norm.

    Parameters
    ----------
    manifold : Manifold
        The space to check (a subclass of :class:`Manifold` with at least
        ``point_shape``, ``_exp`` and ``_log``).
    points : array-like of shape (n, *point_shape), optional
        Points of the manifold to check at (at least 3); default: ``n_points`` drawn by
        :meth:`Manifold.random_point`.
    n_points : int, default=8
    random_state : int, default=0
    atol : float, default=1e-7
        Tolerance of the identities.

    Returns
    -------
    list of str
        The names of the checks passed.

    Raises
    ------
    ManifoldCheckError
        An ``AssertionError`` naming the manifold, the property and the error.
    """
    if not isinstance(manifold, Manifold):
        raise TypeError(f"check_manifold needs a Manifold, got {type(manifold).__name__}")
    rng = np.random.default_rng(random_state)
    if points is None:
        try:
            points = manifold.random_point(n_points, random_state=rng)
        except NotImplementedError:
            raise TypeError(
                f"{manifold!r} draws no random points: pass points=, an array of points of "
                "the manifold"
            ) from None
    points = np.asarray(points, dtype=np.float64)
    if len(points) < 3:
        raise ValueError(f"check_manifold needs at least 3 points, got {len(points)}")
    passed: list[str] = []

    def check(name: str, test: Callable[[], None]) -> None:
        try:
            test()
        except ManifoldCheckError:
            raise
        except Exception as exc:  # a crash is a failed property too, named as such
            _fail(manifold, name, f"{type(exc).__name__}: {exc}")
        passed.append(name)

    M, nd = manifold, manifold.point_ndim
    p, q = points, np.roll(points, 1, axis=0)
    radius = M.injectivity_radius
    half = 0.5 * radius if math.isfinite(radius) else 1.0
    if p.shape[1:] != M.point_shape:
        raise ValueError(
            f"points have shape {p.shape[1:]} each, but {M!r} has point_shape {M.point_shape}"
        )

    def shapes():
        for what, out in (("log(p, q)", M.log(p, q)), ("exp(p, 0)", M.exp(p, np.zeros_like(p)))):
            shape = np.shape(out)
            if shape != p.shape:
                _fail(M, "exp and log keep the point shape", f"{what} has shape {shape[1:]} per "
                      f"point where point_shape is {M.point_shape}")  # fmt: skip

    check("exp and log keep the point shape", shapes)
    setup: dict[str, np.ndarray] = {}

    def tangent_vectors():
        vectors = np.asarray(_tangents(M, p, q, rng))
        if not np.isfinite(vectors).all():
            _fail(M, "tangent vectors at the points", "log (or random_tangent) returns NaN or "
                  "infinite values between the given points")  # fmt: skip
        norms = np.asarray(M.norm(p, vectors)).reshape(-1, *([1] * nd))
        scale = half * rng.uniform(0.2, 1.0, norms.shape)
        setup["vectors"] = vectors
        setup["small"] = vectors / np.where(norms > 0, norms, 1.0) * scale

    check("tangent vectors at the points", tangent_vectors)
    vectors, small = setup["vectors"], setup["small"]

    check("points validate", lambda: M.validate(p))
    check("exp(p, 0) = p", lambda: _close(M, "exp(p, 0) = p", M.exp(p, np.zeros_like(p)), p, atol))
    check("exp lands on the manifold", lambda: M.validate(M.exp(p, small)))
    check("exp lands on the manifold far out", lambda: M.validate(M.exp(p, 3.0 * vectors)))
    near = M.exp(p, small)
    identities = {
        "log(p, p) = 0": lambda: (M.log(p, p), 0.0),
        "log inverts exp": lambda: (M.log(p, near), small),
        "exp inverts log": lambda: (M.dist(M.exp(p, M.log(p, near)), near), 0.0),
        "dist = norm of log": lambda: (M.dist(p, near), M.norm(p, small)),
    }
    for name, pair in identities.items():
        check(name, _identity(M, name, pair, atol))

    def distance_axioms():
        a, b, c = p, q, np.roll(points, 2, axis=0)
        d_ab, d_ba = np.asarray(M.dist(a, b)), np.asarray(M.dist(b, a))
        _close(M, "dist is symmetric", d_ab, d_ba, atol)
        if np.any(d_ab < 0):
            _fail(M, "dist is non-negative", f"smallest distance {d_ab.min():.3g}")
        _close(M, "dist(p, p) = 0", M.dist(a, a), 0.0, atol)
        excess = np.asarray(M.dist(a, c)) - d_ab - np.asarray(M.dist(b, c))
        if np.any(excess > atol):
            _fail(M, "triangle inequality", f"violated by {excess.max():.3g}")

    check("distance axioms", distance_axioms)

    def pairwise():
        expected = np.array([[M.dist(a, b) for b in q] for a in p])
        _close(M, "pairwise_dist = dist", M.pairwise_dist(p, q), expected, atol)

    check("pairwise_dist = dist", pairwise)

    def compiled_distance():
        segments = segment_codes(M)  # raises for segments that do not tile a point
        if segments is None:
            return
        flat_p = p.reshape(len(p), -1)
        flat_q = q.reshape(len(q), -1)
        kp, kq = kernel_points(M, flat_p), kernel_points(M, flat_q)
        got = np.array([robust_distance(kp[i], kq[i], segments) for i in range(len(p))])
        _close(M, "the compiled distance (distance_segments) = dist", got,
               np.asarray(M.dist(p, q)), atol)  # fmt: skip

    check("the compiled distance (distance_segments) = dist", compiled_distance)

    def numpy_and_torch():
        tp, tq = torch.as_tensor(p), torch.as_tensor(q)
        _close(M, "numpy and torch agree", M.log(tp, tq).numpy(), M.log(p, q), 1e-12)
        _close(M, "numpy and torch agree", M.dist(tp, tq).numpy(), M.dist(p, q), 1e-12)

    check("numpy and torch agree", numpy_and_torch)

    def means():
        same = np.stack([p[0]] * 4)
        _close(M, "mean of identical points", M.dist(M.mean(same), p[0]), 0.0, atol)
        midpoint = M.exp(p[0], 0.5 * small[0])
        pair = np.stack([p[0], near[0]])
        _close(M, "mean of two points is the midpoint", M.dist(M.mean(pair), midpoint), 0.0,
               10 * atol)  # fmt: skip

    check("Fréchet means", means)

    def gradients():
        base = torch.as_tensor(p[0])
        for name, fn, at in (
            ("exp at a zero vector", lambda v: M.exp(base, v), torch.zeros_like(base)),
            ("log at a coincident point", lambda x: M.log(base, x), base.clone()),
            ("squared distance at a coincident point", lambda x: M.squared_dist(base, x),
             base.clone()),
        ):  # fmt: skip
            x = at.clone().requires_grad_(True)
            fn(x).sum().backward()
            if x.grad is None or not bool(torch.isfinite(x.grad).all()):
                _fail(M, "finite gradients", f"the gradient of {name} is not finite")

    check("finite gradients", gradients)

    def coordinates():
        try:
            c = M.to_coordinates(p, small)
        except NotImplementedError:
            return
        _close(M, "tangent coordinates round-trip", M.from_coordinates(p, c), small, atol)
        _close(M, "tangent coordinates keep the norm", np.linalg.norm(c, axis=-1),
               M.norm(p, small), atol)  # fmt: skip

    check("tangent coordinates", coordinates)
    return passed


def _identity(M: Manifold, name: str, pair: Callable, atol: float) -> Callable[[], None]:
    def test() -> None:
        actual, expected = pair()
        _close(M, name, actual, expected, atol)

    return test


def _tangents(M: Manifold, p: np.ndarray, q: np.ndarray, rng) -> np.ndarray:
    """Tangent vectors at ``p``: drawn where the space can, else logs towards other points."""
    try:
        return np.asarray(M.random_tangent(p, 1.0, random_state=rng))
    except NotImplementedError:
        v = np.asarray(M.log(p, q))
        if not np.isfinite(v).all():
            _fail(M, "tangent vectors at the points", "log returns NaN or infinite values "
                  "between the given points")  # fmt: skip
        zero = np.asarray(M.norm(p, v)) == 0
        if np.any(zero):  # coincident neighbours: use the next point instead
            v[zero] = np.asarray(M.log(p[zero], np.roll(p, 2, axis=0)[zero]))
        return v


#: Relative tolerance of :func:`check_on_data`'s round trip ``exp(p, log(p, x)) = x``.
ROUND_TRIP_RTOL = 1e-6
#: Manifolds of the user's that passed :func:`check_on_data` (checked once each).
_PASSED: set = set()


def shipped(manifold: Manifold) -> bool:
    """Whether ``manifold`` is one of the package's spaces (tested by its own suite)."""
    return type(manifold).__module__.startswith("sk_rtw.manifolds.")


def check_on_data(manifold: Manifold, series: list[np.ndarray], name: str = "X") -> None:
    """A quick check of a space the package does not ship, on a few of the user's samples.

    The first time a manifold of your own meets data, ``exp`` and ``log`` are checked at
    up to 4 pairs of neighbouring samples in each of the first three series: shapes (the
    point shape), finite values, ``log(p, p) = 0`` and the round trip
    ``exp(p, log(p, x)) = x``. A
    space that fails is refused before any work with a ``ValueError`` naming the property;
    :func:`check_manifold` checks the whole contract.
    """
    if shipped(manifold):
        return
    try:
        if manifold in _PASSED:
            return
    except TypeError:  # an unhashable space is checked every time (it is cheap)
        pass
    pairs = []
    for s in series[:3]:
        if len(s) < 2:
            continue
        at = np.unique(np.linspace(0, len(s) - 2, 4).astype(int))
        pairs += [(s[t], s[t + 1]) for t in at]
    if not pairs:
        return
    p = np.stack([a for a, _ in pairs]).astype(np.float64)
    x = np.stack([b for _, b in pairs]).astype(np.float64)
    hint = f"; sk_rtw.check_manifold({manifold!r}, points) checks the whole contract"

    def refuse(problem: str) -> None:
        raise ValueError(f"{manifold!r} cannot be used on {name}: {problem}{hint}")

    def computed(what: str, fn) -> np.ndarray:
        try:
            out = np.asarray(fn())
        except Exception as exc:
            refuse(f"{what} fails on its samples ({type(exc).__name__}: {exc})")
        if out.shape != p.shape:
            refuse(
                f"{what} returns arrays of shape {out.shape[1:]} for points of shape "
                f"{p.shape[1:]} (point_shape is {manifold.point_shape}): exp and log must "
                "return arrays of the point shape"
            )
        if not np.isfinite(out).all():
            refuse(f"{what} returns NaN or infinite values at neighbouring samples")
        return out

    v = computed("log(p, x)", lambda: manifold.log(p, x))
    zero = computed("log(p, p)", lambda: manifold.log(p, p))
    back = computed("exp(p, log(p, x))", lambda: manifold.exp(p, v))
    scale = 1.0 + float(np.abs(x).max())
    if np.abs(zero).max() > ROUND_TRIP_RTOL * scale:
        refuse(f"log(p, p) is not 0 (largest entry {np.abs(zero).max():.3g})")
    error = float(np.abs(back - x).max())
    if error > ROUND_TRIP_RTOL * scale:
        refuse(
            f"exp(p, log(p, x)) differs from x by up to {error:.3g} for neighbouring samples "
            "p, x: exp must invert log, or the aligned series and their mean are wrong"
        )
    try:
        _PASSED.add(manifold)
    except TypeError:
        pass
