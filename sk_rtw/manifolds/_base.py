"""The manifold interface shared by every space.

Each manifold is a small frozen dataclass (value equality, readable repr, picklable, safe
under :func:`sklearn.base.clone`). Geometry is written once in torch (private ``_exp``,
``_log``, ... methods); the public methods accept numpy arrays or torch tensors and
broadcast over all leading axes. A point has shape :attr:`Manifold.point_shape`, so an
array of points has shape ``(*leading, *point_shape)``.
"""

from __future__ import annotations

import functools
import math
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
import torch

from .._backend import numpy_compatible, safe_norm, to_tensor
from .._random import check_generator
from ._mean import MEAN_MAX_ITER, MEAN_TOL, checked_mean, group_expand

#: Magnitudes beyond ``10 ** +-EXTREME_EXPONENT`` are aligned in a rescaled frame.
EXTREME_EXPONENT = 100

#: Kinds of point distance a block of coordinates can have (see
#: :attr:`Manifold.distance_segments`).
DISTANCE_KINDS = ("euclidean", "sphere", "sign-invariant sphere", "spd")


def checked_geometry(points=(), vectors=(), plain=(), broadcast=True):
    """:func:`numpy_compatible`, plus argument checks for numpy (public) calls.

    Arrays named in ``points`` must be finite points of the manifold, those in
    ``vectors`` finite tangent vectors (:meth:`Manifold._vector_problem`), those in
    ``plain`` finite arrays of points' shape (``project``'s input), and all of them
    broadcast against each other (unless ``broadcast=False``, as for ``pairwise_dist``).
    Torch tensors -- the engine's internal calls -- are not checked.
    """
    names = (*points, *vectors, *plain)

    def decorate(method):
        wrapped = numpy_compatible(method)

        @functools.wraps(method)
        def wrapper(self, *arrays, **kwargs):
            if not any(isinstance(a, torch.Tensor) for a in arrays):
                checked = [
                    self._check_argument(a, name, name in points, name in vectors)
                    for a, name in zip(arrays, names, strict=False)
                ]
                if broadcast and len(checked) > 1:
                    _check_broadcast(self, dict(zip(names, checked, strict=False)))
            return wrapped(self, *arrays, **kwargs)

        return wrapper

    return decorate


def _check_broadcast(manifold, arrays: dict) -> None:
    nd = manifold.point_ndim
    leading = {name: a.shape[: a.ndim - nd] for name, a in arrays.items()}
    try:
        np.broadcast_shapes(*leading.values())
    except ValueError:
        text = ", ".join(f"{name} {a.shape}" for name, a in arrays.items())
        raise ValueError(
            f"the arguments do not broadcast against each other: {text} (points of "
            f"{manifold!r} have shape {manifold.point_shape})"
        ) from None


@dataclass(frozen=True)
class Manifold(ABC):
    """Riemannian manifold: exponential and logarithmic maps, distance, Fréchet mean.

    Points are arrays of shape ``point_shape`` (e.g. ``(3,)`` on S^2, ``(2, 2)`` on
    SPD(2)); every operation broadcasts over leading axes, so a series is
    ``(T, *point_shape)`` and a collection ``(n, T, *point_shape)``. numpy input gives
    numpy output; torch input gives differentiable torch output.

    A space of your own needs ``point_shape`` and the torch methods ``_exp`` and ``_log``;
    the rest is derived (``_norm``: the Euclidean norm of the ambient tangent vector,
    ``_dist``: the norm of the log, the Fréchet mean, DTW cost matrices) and may be
    overridden for speed or accuracy: ``_project`` and ``_point_problems`` (the
    manifold constraint, for clear errors), ``_to_coordinates``/``_from_coordinates`` and
    ``intrinsic_dim`` (for :mod:`sk_rtw.statistics`), ``_random_point`` and
    ``_random_tangent`` (for examples). :func:`check_manifold` checks such a space the
    way the built-in ones are tested; the user guide aligns rotation matrices with one.
    """

    #: Registry name of the space.
    name: ClassVar[str] = "manifold"
    #: True when log/exp are subtraction/addition (the tangent point does not matter).
    is_flat: ClassVar[bool] = False

    # ------------------------------------------------------------------ shape
    @property
    @abstractmethod
    def point_shape(self) -> tuple[int, ...]:
        """Shape of one point, e.g. ``(3,)`` for S^2 or ``(2, 2)`` for SPD(2)."""

    @property
    def point_ndim(self) -> int:
        """Number of trailing axes that describe one point."""
        return len(self.point_shape)

    @property
    def injectivity_radius(self) -> float:
        """Radius of the ball around any point on which ``log`` inverts ``exp``."""
        return float("inf")

    @property
    def intrinsic_dim(self) -> int:
        """Dimension of the manifold: the number of tangent coordinates (2 on S^2, 3 on
        S^3, ``k (k + 1) / 2`` on SPD(k)), not the size of a point."""
        raise NotImplementedError(
            f"{type(self).__name__} does not state its intrinsic_dim (needed by the "
            "statistics of an aligned set)"
        )

    @property
    def distance_segments(self) -> tuple[tuple[int, int, str], ...] | None:
        """The geodesic distance as ``(start, stop, kind)`` blocks of the flat point.

        ``kind`` is one of :data:`DISTANCE_KINDS`: Euclidean distance, great-circle
        distance, the sign-invariant great circle of unit quaternions, or the
        affine-invariant distance of a row-major SPD matrix; the distance of a point is
        ``sqrt(sum_s d_s^2)`` over the blocks. None when the distance has no such form:
        computations that need it (the DTW kernels) then use :meth:`pairwise_dist`, as
        they do for the kinds they have no kernel for (SPD matrices larger than 12 x 12).
        A statement about the geometry only: how a consumer computes these distances is
        its own business.
        """
        return None

    @property
    def velocity_dim(self) -> int:
        """Number of coordinates of :meth:`velocity`: by default those of an ambient
        tangent vector, ``prod(point_shape)``."""
        return math.prod(self.point_shape)

    # --------------------------------------------------------- torch geometry
    @abstractmethod
    def _exp(self, p: torch.Tensor, v: torch.Tensor) -> torch.Tensor: ...

    @abstractmethod
    def _log(self, p: torch.Tensor, x: torch.Tensor) -> torch.Tensor: ...

    def _group_log(
        self, means: torch.Tensor, codes: torch.Tensor, points: torch.Tensor
    ) -> torch.Tensor:
        """``Log`` of every point at its group's mean: ``means`` (n_groups, ...), ``codes``
        (N,), ``points`` (N, ...). Manifolds whose log first prepares the tangent point
        (SPD's whitening) override it to prepare each mean once."""
        return self._log(group_expand(means, codes), points)

    def _dist(self, p: torch.Tensor, x: torch.Tensor) -> torch.Tensor:
        """Geodesic distance: the Riemannian norm of the log."""
        return self._norm(p, self._log(p, x))

    def _norm(self, p: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
        """Riemannian norm; by default the Euclidean norm of the ambient tangent vector (the
        metric induced by the embedding)."""
        _, v = torch.broadcast_tensors(p, v)
        return safe_norm(v.reshape(*v.shape[: v.ndim - self.point_ndim], -1))

    def _velocity(self, p: torch.Tensor, x: torch.Tensor) -> torch.Tensor:
        """``log_p(x)`` in coordinates that compare across base points: by default the
        ambient tangent vector, flattened (:meth:`velocity`)."""
        v = self._log(p, x)
        return v.reshape(*v.shape[: v.ndim - self.point_ndim], -1)

    def _project(self, x: torch.Tensor) -> torch.Tensor:
        raise NotImplementedError(f"{type(self).__name__} defines no projection onto itself")

    def _to_coordinates(self, p: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
        raise NotImplementedError(
            f"{type(self).__name__} defines no tangent coordinates (_to_coordinates, needed "
            "by the statistics of an aligned set)"
        )

    def _from_coordinates(self, p: torch.Tensor, c: torch.Tensor) -> torch.Tensor:
        raise NotImplementedError(
            f"{type(self).__name__} defines no tangent coordinates (_from_coordinates, "
            "needed by the statistics of an aligned set)"
        )

    def _point_problems(self, x: torch.Tensor, atol: float) -> list[tuple[torch.Tensor, Any]]:
        """Per-point boolean masks of violations (over leading axes) with a description
        (a string, or a callable that describes the first offending point). Default: none
        (only finiteness is checked)."""
        return []

    # ------------------------------------------------------------- public API
    @checked_geometry(points=("p",), vectors=("v",))
    def exp(self, p, v):
        """Exponential map: the point reached from ``p`` along tangent vector ``v``.

        Parameters
        ----------
        p : array-like or torch.Tensor, shape (..., *point_shape)
            Base points.
        v : array-like or torch.Tensor, shape (..., *point_shape)
            Tangent vectors at ``p`` (ambient coordinates), broadcast against ``p``.

        Returns
        -------
        x : same type as the input, shape (..., *point_shape)
        """
        return self._exp(p, v)

    @checked_geometry(points=("p", "x"))
    def log(self, p, x):
        """Logarithmic map: the tangent vector at ``p`` pointing to ``x``.

        Parameters
        ----------
        p, x : array-like or torch.Tensor, shape (..., *point_shape)
            Base points and target points, broadcast against each other.

        Returns
        -------
        v : same type as the input, shape (..., *point_shape)
        """
        return self._log(p, x)

    @checked_geometry(points=("p", "x"))
    def dist(self, p, x):
        """Geodesic distance between ``p`` and ``x``.

        Parameters
        ----------
        p, x : array-like or torch.Tensor, shape (..., *point_shape)

        Returns
        -------
        d : same type as the input, shape (...)
        """
        return self._dist(p, x)

    @checked_geometry(points=("p", "x"))
    def squared_dist(self, p, x):
        """Squared geodesic distance (smooth where the distance is zero).

        Parameters
        ----------
        p, x : array-like or torch.Tensor, shape (..., *point_shape)

        Returns
        -------
        d2 : same type as the input, shape (...)
        """
        return self._dist(p, x) ** 2

    @checked_geometry(points=("p",), vectors=("v",))
    def norm(self, p, v):
        """Riemannian norm of the tangent vector ``v`` at ``p``.

        Parameters
        ----------
        p : array-like or torch.Tensor, shape (..., *point_shape)
            Base points.
        v : array-like or torch.Tensor, shape (..., *point_shape)
            Tangent vectors at ``p``.

        Returns
        -------
        n : same type as the input, shape (...)
        """
        return self._norm(p, v)

    @checked_geometry(points=("p",), vectors=("v",))
    def to_coordinates(self, p, v):
        """Coordinates of tangent vectors in an orthonormal basis of the tangent space.

        The basis at ``p`` is orthonormal for the Riemannian metric, so the Euclidean norm
        of the coordinates is :meth:`norm` ``(p, v)`` and a covariance of coordinates is a
        covariance of tangent vectors (what Gaussians on manifolds are built from). The
        basis depends on ``p`` only: compare coordinates at the same point.

        Parameters
        ----------
        p : array-like or torch.Tensor, shape (..., *point_shape)
            Base points.
        v : array-like or torch.Tensor, shape (..., *point_shape)
            Tangent vectors at ``p`` (ambient form, as :meth:`log` returns them).

        Returns
        -------
        c : same type as the input, shape (..., intrinsic_dim)
        """
        return self._to_coordinates(p, v)

    @checked_geometry(points=("p",), broadcast=False)
    def from_coordinates(self, p, c):
        """Tangent vectors at ``p`` from their coordinates (inverse of :meth:`to_coordinates`).

        Parameters
        ----------
        p : array-like or torch.Tensor, shape (..., *point_shape)
        c : array-like or torch.Tensor, shape (..., intrinsic_dim)

        Returns
        -------
        v : same type as the input, shape (..., *point_shape)
        """
        c = c if isinstance(c, torch.Tensor) else torch.as_tensor(np.asarray(c), dtype=p.dtype)
        if c.shape[-1:] != (self.intrinsic_dim,):
            raise ValueError(
                f"coordinates must have {self.intrinsic_dim} entries on the last axis for "
                f"{self!r}, got shape {tuple(c.shape)}"
            )
        return self._from_coordinates(p, c.to(dtype=p.dtype, device=p.device))

    @checked_geometry(points=("p", "x"))
    def velocity(self, p, x):
        """The step from ``p`` to ``x``, ``log_p(x)``, in coordinates that compare across
        base points: what a series' tangent velocity is made of
        (:func:`sk_rtw.tangent_velocity`).

        :meth:`log` gives a vector of the tangent space at ``p``; two such vectors at
        different points are not comparable as they are. Each space gives its steps in a
        frame that does not depend on where they start, so that the velocities of two
        series (or of one series at two times) can be compared as Euclidean vectors:

        * Euclidean: ``x - p``;
        * sphere S^1: the signed angle, counter-clockwise positive (the circle's own
          frame); S^d, d >= 2: the ambient tangent vector in R^(d+1) (no continuous
          frame exists on S^2; an ambient vector is rotation-equivariant and keeps the
          geodesic length as its norm);
        * unit quaternions: the body angular velocity ``2 log(p^-1 x)`` in R^3 (the
          rotation vector of the relative rotation, sign ambiguity resolved: its norm is
          the rotation angle, twice :meth:`dist`);
        * SPD(k): ``logm(p^-1/2 x p^-1/2)`` in the eigenbasis of ``p`` (eigenvalues
          ascending; ``det = +1``; for k >= 3 the first row's entries made non-negative,
          the last column's sign from the determinant for even k), in isometric
          coordinates (diagonal and sqrt(2) x upper triangle, ``k (k + 1) / 2`` numbers;
          norm = :meth:`dist`): the same for a series in any world frame ``R x R^T``.
          ``SPD(k, velocity_frame="world")`` keeps the ambient axes;
        * products: each factor's, concatenated;
        * a space of your own: the ambient :meth:`log`, flattened, unless it defines
          ``_velocity`` and :attr:`velocity_dim`.

        Parameters
        ----------
        p : array-like or torch.Tensor, shape (..., *point_shape)
        x : array-like or torch.Tensor, shape (..., *point_shape)

        Returns
        -------
        v : same type as the input, shape (..., velocity_dim)
        """
        return self._velocity(p, x)

    @checked_geometry(points=("A", "B"), broadcast=False)
    def pairwise_dist(self, A, B):
        """Geodesic distances between every point of ``A`` and every point of ``B``.

        Parameters
        ----------
        A : array-like or torch.Tensor, shape (..., m, *point_shape)
        B : array-like or torch.Tensor, shape (..., n, *point_shape)

        Returns
        -------
        D : same type as the input, shape (..., m, n)
            ``D[..., i, j] = dist(A[..., i], B[..., j])``: the DTW cost matrix.
        """
        return self._pairwise_dist(A, B)

    def _pairwise_dist(self, A: torch.Tensor, B: torch.Tensor) -> torch.Tensor:
        nd = self.point_ndim
        return self._dist(A.unsqueeze(-nd - 1), B.unsqueeze(-nd - 2))

    @checked_geometry(plain=("X",))
    def project(self, X):
        """Nearest point on the manifold (normalise, symmetrise, clip eigenvalues, ...).

        Parameters
        ----------
        X : array-like or torch.Tensor, shape (..., *point_shape)
            Points near the manifold.

        Returns
        -------
        points : same type as the input, shape (..., *point_shape)
        """
        return self._project(X)

    def mean(
        self,
        X: Any,
        weights: Any = None,
        *,
        axis: int = 0,
        groups: Any = None,
        start: Any = None,
        max_iter: int = MEAN_MAX_ITER,
        tol: float = MEAN_TOL,
    ):
        """Weighted Fréchet (Karcher) mean by Gauss–Newton iterations, batched over groups.

        Each iteration maps the samples to the tangent space at the current estimate,
        averages them there (weighted) and maps the average back with ``exp``, from the
        first sample (of each group) or ``start``. A group stops when none of its means
        moves by ``tol`` or more. Where the full step cycles (samples far apart, such as
        SPD matrices whose log-eigenvalues differ by several units), the means still
        moving after ``max_iter`` iterations take up to ``max_iter`` line-searched
        fractions of it; one ``ConvergenceWarning`` if one is still moving after those
        (``tol=0``: exactly ``max_iter`` full steps, no fallback, no warning). The same
        kernel (:func:`sk_rtw.manifolds._mean.frechet_mean`) averages in the engine, DBA
        and the statistics.

        Parameters
        ----------
        X : array-like or torch.Tensor, shape (..., *point_shape)
            Samples; the mean is taken over the leading axis ``axis``.
        weights : array-like, optional
            Non-negative weights, shape ``(n_samples,)`` or broadcastable to the leading
            axes of ``X`` (after moving ``axis`` first). Default: uniform (per group).
        axis : int, default=0
            Leading axis holding the samples.
        groups : array-like of int, shape (n_samples,), optional
            Group of every sample, ``0..n_groups - 1`` with none empty: one mean per
            group, stacked on a new first axis.
        start : array-like, optional
            Starting estimate, shaped like the result.
        max_iter : int, default=64
            Iteration cap.
        tol : float, default=1e-10
            Convergence threshold on the geodesic length of the Gauss–Newton step.

        Returns
        -------
        mean : same type as ``X``
            Shape of ``X`` without ``axis``, with ``(n_groups,)`` in front when ``groups``
            is given.
        """
        if not isinstance(X, torch.Tensor):
            X = self._check_argument(X, "X", is_point=True)
        return numpy_compatible(checked_mean)(
            self, X, weights, groups, start, axis=axis, max_iter=max_iter, tol=tol
        )

    def validate(self, X: Any, *, atol: float = 1e-6, name: str = "X") -> None:
        """Raise ``ValueError`` if ``X`` is not an array of points of this manifold.

        Parameters
        ----------
        X : array-like or torch.Tensor, shape (..., *point_shape)
        atol : float, default=1e-6
            Tolerance for the manifold constraint (unit norm, symmetry, ...).
        name : str, default="X"
            Name used in the error message.

        Raises
        ------
        ValueError
            Naming the index of the first offending point and what is wrong with it.
        """
        X = to_tensor(X).detach()
        ps = self.point_shape
        if tuple(X.shape[X.ndim - len(ps) :]) != ps or X.ndim < len(ps):
            raise ValueError(
                f"{name} has shape {tuple(X.shape)}, but points of {self!r} have shape {ps}."
            )
        lead = X.ndim - len(ps)
        finite = torch.isfinite(X).flatten(lead).all(-1) if ps else torch.isfinite(X)
        if not bool(finite.all()):
            idx = _first_index(~finite)
            raise ValueError(f"{name}{idx} contains NaN or infinite values.")
        for mask, description in self._point_problems(X, atol):
            if bool(mask.any()):
                idx = _first_index(mask)
                if callable(description):  # a description of the first offending point
                    first = tuple(torch.nonzero(mask)[0].tolist()) if mask.ndim else ()
                    description = description(X[first])
                raise ValueError(
                    f"{name}{idx} is not a point of {self!r}: {description} "
                    f"(tolerance {atol:g}); use {type(self).__name__}.project to map data "
                    "onto the manifold."
                )

    def _check_argument(
        self, value: Any, name: str, is_point: bool, is_vector: bool = False
    ) -> np.ndarray:
        try:
            arr = np.asarray(value, dtype=np.float64)
        except (TypeError, ValueError):
            kind = type(value).__name__
            raise TypeError(f"{name} must be a numeric array, got {kind}") from None
        ps = self.point_shape
        if arr.ndim < len(ps) or tuple(arr.shape[arr.ndim - len(ps) :]) != ps:
            raise ValueError(
                f"{name} has shape {arr.shape}, but points of {self!r} have shape {ps} "
                f"(arrays of them: (..., {', '.join(map(str, ps))}))"
            )
        if is_point:
            self.validate(arr, name=name)
        elif not np.all(np.isfinite(arr)):
            raise ValueError(f"{name} contains NaN or infinite values")
        elif is_vector:
            problem = self._vector_problem(arr)
            if problem is not None:
                raise ValueError(f"{name} is not a tangent vector of {self!r}: {problem}")
        return arr

    def _vector_problem(self, v: np.ndarray) -> str | None:
        """What makes the finite array ``v`` (``(..., *point_shape)``) no tangent vector of
        this space at any point, or None (the default: every array of the points' shape
        is one, as in R^d; SPD(k) needs symmetric matrices)."""
        return None

    def extreme_scale(self, points: np.ndarray) -> float | None:
        """A power of two to divide ``points`` by when their magnitude is extreme, or None.

        Spaces where dividing points by a positive number maps the geometry onto itself
        up to scale (R^d; SPD(k), whose affine-invariant metric does not change at all)
        return one when the magnitudes lie beyond 1e+-100, so that squares and exponentials
        neither overflow nor underflow; the others return None.

        Parameters
        ----------
        points : ndarray of shape (..., *point_shape)

        Returns
        -------
        factor : float or None
        """
        return None

    def _beyond_injectivity(self, p: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
        """Where ``exp(p, v)`` leaves the ball on which ``log`` inverts ``exp`` (over the
        leading axes): geodesics that long wrap round (a sphere) or stop being shortest."""
        return self._norm(p, v) > self.injectivity_radius

    @property
    def normalised_space(self) -> Manifold | None:
        """The space of :meth:`normalise_windows`' points, or None where the manifold
        has no form of z-normalisation (then shapelets compare windows as they are)."""
        return None

    def normalise_windows(self, windows: np.ndarray) -> np.ndarray:
        """Windows of points with the manifold's group action removed: the manifold's
        form of z-normalisation, for shapelets that compare shape without position.

        A window recorded in another frame (the group acting on every point alike)
        gives the same normalised window: R^d subtracts each coordinate's mean and
        divides by its standard deviation (an affine map per coordinate); unit
        quaternions left-multiply by the inverse of the window's chordal mean (a
        rotation of the world frame); SPD(k) takes each point's log-eigenvalues
        relative to the window's arithmetic mean (any congruence ``A X A^T``); a
        product normalises each factor.

        Parameters
        ----------
        windows : ndarray of shape (..., length, *point_shape)

        Returns
        -------
        ndarray of shape (..., length, *normalised_space.point_shape)
        """
        raise NotImplementedError(f"{self!r} has no form of z-normalisation")

    def spread_note(self, points: np.ndarray) -> str:
        """A few words on the range of ``points`` for error messages ("" if none apply).

        :class:`SPD` names the eigenvalue range: where float64 arithmetic cannot follow
        the geodesics between the points, that range is the reason.
        """
        return ""

    def continuous(self, series: Any) -> np.ndarray:
        """Representatives of a series that do not jump between equivalent points.

        Only spaces whose points have several coordinate representations change
        anything: for :class:`Quaternion` every sample takes the sign that keeps it in
        the hemisphere of the previous one, so a mean trajectory does not flip between
        ``q`` and ``-q``. Distances and means are unaffected.

        Parameters
        ----------
        series : array-like of shape (..., T, *point_shape)
            Series along the axis just before the point axes.

        Returns
        -------
        series : ndarray of shape (..., T, *point_shape)
        """
        return np.asarray(series, dtype=np.float64)

    def random_point(self, n_points: int | tuple[int, ...] = (), random_state=None):
        """Random points, for tests and examples.

        Parameters
        ----------
        n_points : int or tuple of int, default=()
            Leading shape; ``()`` gives a single point.
        random_state : int, Generator, RandomState or None

        Returns
        -------
        points : ndarray of shape (*n_points, *point_shape)
        """
        rng = check_generator(random_state)
        leading = (n_points,) if isinstance(n_points, int) else tuple(n_points)
        return self._random_point(leading, rng)

    def random_tangent(self, p: Any, scale: float = 1.0, random_state=None):
        """Random tangent vectors at ``p``, with entries of size about ``scale``.

        Parameters
        ----------
        p : array-like of shape (..., *point_shape)
            Base points.
        scale : float, default=1.0
        random_state : int, Generator, RandomState or None

        Returns
        -------
        v : ndarray of shape (..., *point_shape)
        """
        rng = check_generator(random_state)
        p = np.asarray(p, dtype=np.float64)
        return self._random_tangent(p, scale, rng)

    def _random_point(self, leading: tuple[int, ...], rng: np.random.Generator) -> np.ndarray:
        raise NotImplementedError(f"{type(self).__name__} draws no random points")

    def _random_tangent(self, p: np.ndarray, scale: float, rng: np.random.Generator) -> np.ndarray:
        raise NotImplementedError(f"{type(self).__name__} draws no random tangent vectors")


def _first_index(mask: torch.Tensor) -> str:
    if mask.ndim == 0:
        return ""
    first = torch.nonzero(mask)[0].tolist()
    return "[" + ", ".join(str(i) for i in first) + "]"


def power_of_two_scale(magnitude: float) -> float | None:
    """``2 ** round(log2(magnitude))`` if ``magnitude`` is extreme (beyond 1e+-100)."""
    if not np.isfinite(magnitude) or magnitude <= 0:
        return None
    exponent = np.log10(magnitude)
    if -EXTREME_EXPONENT <= exponent <= EXTREME_EXPONENT:
        return None
    # within float64's powers of two (2^1024 overflows to inf, 2^-1075 underflows to 0)
    return float(np.ldexp(1.0, int(np.clip(np.round(np.log2(magnitude)), -1022, 1023))))
