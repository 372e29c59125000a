"""The manifold interface shared by every space.

Each manifold is a small frozen dataclass (value equality, readable repr, picklable, safe
under :func:`sklearn.base.clone`). Geometry is written once in torch (private ``_exp``,
``_log``, ... methods); the public methods accept numpy arrays or torch tensors and
broadcast over all leading axes. A point has shape :attr:`Manifold.point_shape`, so an
array of points has shape ``(*leading, *point_shape)``.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
import torch

from .._backend import numpy_compatible, to_tensor
from .._random import check_generator

#: Default stopping rule of :meth:`Manifold.mean`.
MEAN_TOL = 1e-10
MEAN_MAX_ITER = 64

# Codes of the point distances that the numba DTW kernel knows (see sk_rtw.dtw).
SEGMENT_EUCLIDEAN = 0
SEGMENT_SPHERE = 1
SEGMENT_SIGN_INVARIANT_SPHERE = 2


@dataclass(frozen=True)
class Manifold(ABC):
    """Riemannian manifold: exponential and logarithmic maps, distance, Fréchet mean.

    Points are arrays of shape ``point_shape`` (e.g. ``(3,)`` on S^2, ``(2, 2)`` on
    SPD(2)); every operation broadcasts over leading axes, so a series is
    ``(T, *point_shape)`` and a collection ``(n, T, *point_shape)``. numpy input gives
    numpy output; torch input gives differentiable torch output.

    Subclasses implement the torch methods ``_exp``, ``_log``, ``_dist``, ``_norm``,
    ``_project`` and ``_point_problems``; everything else is derived here.
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
    def numba_segments(self) -> tuple[tuple[int, int, int], ...] | None:
        """Point distance as ``(start, stop, code)`` segments of the flat point, or None.

        Used by the DTW kernel to compute the cost matrix inside numba; manifolds that
        return None have their cost matrix computed by :meth:`pairwise_dist`.
        """
        return None

    # --------------------------------------------------------- torch geometry
    @abstractmethod
    def _exp(self, p: torch.Tensor, v: torch.Tensor) -> torch.Tensor: ...

    @abstractmethod
    def _log(self, p: torch.Tensor, x: torch.Tensor) -> torch.Tensor: ...

    @abstractmethod
    def _dist(self, p: torch.Tensor, x: torch.Tensor) -> torch.Tensor: ...

    @abstractmethod
    def _norm(self, p: torch.Tensor, v: torch.Tensor) -> torch.Tensor: ...

    @abstractmethod
    def _project(self, x: torch.Tensor) -> torch.Tensor: ...

    @abstractmethod
    def _point_problems(self, x: torch.Tensor, atol: float) -> list[tuple[torch.Tensor, str]]:
        """Per-point boolean masks of violations (over leading axes) with a description."""

    # ------------------------------------------------------------- public API
    @numpy_compatible
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

    @numpy_compatible
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

    @numpy_compatible
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

    @numpy_compatible
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

    @numpy_compatible
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

    @numpy_compatible
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

    @numpy_compatible
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
        max_iter: int = MEAN_MAX_ITER,
        tol: float = MEAN_TOL,
    ):
        """Weighted Fréchet (Karcher) mean by Gauss–Newton iterations.

        Starting from the first sample, each iteration maps all samples to the tangent
        space at the current estimate, averages them there (weighted) and maps the
        average back with ``exp``. Stopping rule: the Riemannian norm of the update is
        below ``tol`` for every mean being computed, or ``max_iter`` iterations were done.

        Parameters
        ----------
        X : array-like or torch.Tensor, shape (..., *point_shape)
            Samples; the mean is taken over the leading axis ``axis``.
        weights : array-like, optional
            Non-negative weights, shape ``(n_samples,)`` or broadcastable to the leading
            axes of ``X`` (after moving ``axis`` first). Default: uniform.
        axis : int, default=0
            Leading axis holding the samples.
        max_iter : int, default=64
            Iteration cap.
        tol : float, default=1e-10
            Convergence threshold on the norm of the Gauss–Newton step.

        Returns
        -------
        mean : same type as ``X``, shape of ``X`` without ``axis``.
        """
        return numpy_compatible(_mean_impl)(
            self, X, weights, axis=axis, max_iter=max_iter, tol=tol
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
        finite = torch.isfinite(X).reshape(*X.shape[: X.ndim - len(ps)], -1).all(-1)
        if not bool(finite.all()):
            idx = _first_index(~finite)
            raise ValueError(f"{name}{idx} contains NaN or infinite values.")
        for mask, description in self._point_problems(X, atol):
            if bool(mask.any()):
                idx = _first_index(mask)
                raise ValueError(
                    f"{name}{idx} is not a point of {self!r}: {description} "
                    f"(tolerance {atol:g}); use {type(self).__name__}.project to map data "
                    "onto the manifold."
                )

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

    @abstractmethod
    def _random_point(self, leading: tuple[int, ...], rng: np.random.Generator) -> np.ndarray: ...

    @abstractmethod
    def _random_tangent(
        self, p: np.ndarray, scale: float, rng: np.random.Generator
    ) -> np.ndarray: ...


def _first_index(mask: torch.Tensor) -> str:
    if mask.ndim == 0:
        return ""
    first = torch.nonzero(mask)[0].tolist()
    return "[" + ", ".join(str(i) for i in first) + "]"


def _mean_impl(
    manifold: Manifold,
    X: torch.Tensor,
    weights: torch.Tensor | None,
    *,
    axis: int,
    max_iter: int,
    tol: float,
) -> torch.Tensor:
    nd = manifold.point_ndim
    n_leading = X.ndim - nd
    if n_leading < 1:
        raise ValueError(
            f"mean needs at least one sample axis before the point axes {manifold.point_shape}"
        )
    axis = axis % n_leading
    X = torch.movedim(X, axis, 0)
    n = X.shape[0]
    if n == 0:
        raise ValueError("cannot compute the mean of zero samples")
    if weights is None:
        w = torch.full((n,), 1.0 / n, dtype=X.dtype, device=X.device)
    else:
        w = weights.to(dtype=X.dtype, device=X.device)
        if bool((w < 0).any()):
            raise ValueError("weights must be non-negative")
        total = w.sum(0)
        if bool((total <= 0).any()):
            raise ValueError("weights must not all be zero")
        w = w / total
    w = w.reshape(*w.shape, *([1] * (X.ndim - w.ndim)))
    M = X[0]
    for _ in range(max_iter):
        step = (w * manifold._log(M.unsqueeze(0), X)).sum(0)
        M = manifold._exp(M, step)
        if tol > 0 and float(manifold._norm(M, step).max()) < tol:
            break
    return M
