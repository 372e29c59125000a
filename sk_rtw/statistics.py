"""Time-varying Riemannian statistics of an aligned set of series.

After alignment every output time ``z`` holds one point per series, ``x_n[z]``, around the
mean ``y[z]``. Their spread is described in the tangent space at the mean: the tangent
vectors ``Log_{y[z]}(x_n[z])`` written in an orthonormal basis of that tangent space
(:meth:`sk_rtw.manifolds.Manifold.to_coordinates`, ``D`` coordinates: 3 on S^3 and on R^3,
``k (k + 1) / 2`` on SPD(k), their sum on a product) have the empirical covariance

``S[z] = sum_n c_n[z] c_n[z]^T / (N - ddof) + reg I``

(the covariance about the mean: with the equal-weight Fréchet mean the coordinates
average to zero, and on a flat space it is the ordinary covariance).

This is the Gaussian on the manifold that movement models in the tangent space at the
mean (GMR, ProMP on quaternions or SPD matrices) are built from, with no Euclidean
shortcut: the mean stays on the manifold and distances are geodesic. From it:

* :meth:`AlignedStatistics.sample` draws whole trajectories, correlated in time: ``Exp``
  at the mean of ``sum_n a_n c_n / sqrt(N - ddof)`` plus ``sqrt(reg)`` white noise, with
  ``a ~ N(0, I)``, whose covariance at every time is ``S[z]``;
* :meth:`AlignedStatistics.tube` gives the confidence tube: at every time the principal
  axes (unit tangent vectors) and half-widths of the ellipsoid
  ``c^T S^-1 c <= chi2_D(level)`` (``D`` the intrinsic dimension, not the
  ambient size of a point);
* :meth:`AlignedStatistics.mahalanobis` scores new aligned series against it.

``N`` aligned series give a covariance of rank at most ``N - 1``: ``reg`` keeps it
invertible (scikit-learn's ``reg_covar``).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch
from scipy.stats import chi2

from ._random import check_generator
from .manifolds import Manifold, Product

#: Default regularisation of the covariances (added to the diagonal).
REG = 1e-9


@dataclass(frozen=True, eq=False)
class ConfidenceTube:
    """A confidence tube around a mean trajectory.

    Attributes
    ----------
    level : float
        Probability mass inside the tube under the Gaussian in the tangent space.
    radius : float
        Mahalanobis radius ``sqrt(chi2_D(level))``.
    half_widths : ndarray of shape (Z, D)
        Half-length of every principal axis, ``radius * sqrt(eigenvalue)``, ascending.
    axes : ndarray of shape (Z, D, *point_shape)
        The principal axes as unit tangent vectors at the mean (ambient form).
    mean : ndarray of shape (Z, *point_shape)
    """

    level: float
    radius: float
    half_widths: np.ndarray
    axes: np.ndarray
    mean: np.ndarray

    def boundary(self, manifold: Manifold, n_points: int = 16) -> np.ndarray:
        """Points on the tube along its two widest axes, ``(Z, n_points, *point_shape)``.

        At every time the ellipse spanned by the two largest principal axes is mapped to
        the manifold by ``Exp`` at the mean: for a position or an orientation trajectory a
        ring to draw around the mean.

        Parameters
        ----------
        manifold : Manifold
        n_points : int, default=16

        Returns
        -------
        ndarray of shape (Z, n_points, *point_shape)
        """
        angle = np.linspace(0.0, 2.0 * np.pi, n_points, endpoint=False)
        nd = self.mean.ndim - 1
        major = self.axes[:, -1] * self.half_widths[:, -1].reshape(-1, *([1] * nd))
        minor = (
            self.axes[:, -2] * self.half_widths[:, -2].reshape(-1, *([1] * nd))
            if self.axes.shape[1] > 1
            else np.zeros_like(major)
        )
        shape = (1, -1, *([1] * nd))
        vectors = (
            np.cos(angle).reshape(shape) * major[:, None]
            + np.sin(angle).reshape(shape) * minor[:, None]
        )
        base = np.broadcast_to(self.mean[:, None], vectors.shape)
        points = np.asarray(manifold.exp(base, vectors))
        _warn_off_manifold(manifold, points, "the tube's boundary")
        return points


@dataclass(frozen=True, eq=False)
class AlignedStatistics:
    """Mean and per-time tangent-space covariance of an aligned set.

    Build it with :func:`aligned_statistics` (from an :class:`sk_rtw.Alignment`, a baseline's
    result, or aligned series and their mean).

    Attributes
    ----------
    mean : ndarray of shape (Z, *point_shape)
        The mean trajectory, on the manifold.
    coordinates : ndarray of shape (N, Z, D)
        Tangent coordinates of every aligned series at the mean, ``D = intrinsic_dim``.
    covariance : ndarray of shape (Z, D, D)
        Covariance of the coordinates at every time (with ``reg`` on the diagonal).
    manifold : Manifold
    reg : float
    ddof : int
    """

    mean: np.ndarray
    coordinates: np.ndarray
    covariance: np.ndarray
    manifold: Manifold
    reg: float = REG
    ddof: int = 1

    @property
    def n_series(self) -> int:
        return self.coordinates.shape[0]

    @property
    def dim(self) -> int:
        """Number ``D`` of tangent coordinates."""
        return self.coordinates.shape[2]

    @property
    def variance(self) -> np.ndarray:
        """Total variance (trace of the covariance) at every time, shape (Z,)."""
        return np.trace(self.covariance, axis1=1, axis2=2)

    def sample(self, n_samples: int = 1, random_state: Any = None) -> np.ndarray:
        """Trajectories drawn from the Gaussian in the tangent spaces at the mean.

        Correlated in time: ``Exp`` at the mean of ``sum_n a_n c_n / sqrt(N - ddof) +
        sqrt(reg) e`` with ``a ~ N(0, I_N)`` per trajectory and white noise ``e``; at every
        time the tangent vectors of the samples have mean zero and covariance
        :attr:`covariance`.

        Parameters
        ----------
        n_samples : int, default=1
        random_state : int, Generator, RandomState or None

        Returns
        -------
        samples : ndarray of shape (n_samples, Z, *point_shape)
        """
        if isinstance(n_samples, bool) or not isinstance(n_samples, (int, np.integer)):
            raise TypeError(f"n_samples must be an integer, got {n_samples!r}")
        if n_samples < 1:
            raise ValueError(f"n_samples must be >= 1, got {n_samples}")
        rng = check_generator(random_state)
        weights = rng.standard_normal((n_samples, self.n_series))
        scale = 1.0 / np.sqrt(max(self.n_series - self.ddof, 1))
        coords = np.einsum("sn,nzd->szd", weights, self.coordinates) * scale
        coords += np.sqrt(self.reg) * rng.standard_normal(coords.shape)
        base = np.broadcast_to(self.mean, (n_samples, *self.mean.shape))
        vectors = self.manifold.from_coordinates(base, coords)
        samples = self.manifold.continuous(self.manifold.exp(base, vectors))
        _warn_off_manifold(self.manifold, samples, "the samples")
        return samples

    def tube(self, level: float = 0.95) -> ConfidenceTube:
        """The confidence tube holding ``level`` of the Gaussian at every time.

        Parameters
        ----------
        level : float in (0, 1), default=0.95

        Returns
        -------
        ConfidenceTube
            Radius ``sqrt(chi2_D(level))`` with ``D`` the intrinsic dimension, principal
            half-widths and axes (unit tangent vectors at the mean).
        """
        if not (isinstance(level, (int, float, np.floating)) and 0.0 < level < 1.0):
            raise ValueError(f"level must be a probability in (0, 1), got {level!r}")
        radius = float(np.sqrt(chi2.ppf(level, self.dim)))
        values, vectors = np.linalg.eigh(self.covariance)
        half_widths = radius * np.sqrt(np.clip(values, 0.0, None))
        base = np.broadcast_to(
            self.mean[:, None], (len(self.mean), self.dim, *self.mean.shape[1:])
        )
        axes = np.asarray(self.manifold.from_coordinates(base, np.swapaxes(vectors, 1, 2)))
        _warn_beyond_injectivity(self.manifold, self.mean, axes, half_widths, level)
        return ConfidenceTube(float(level), radius, half_widths, axes, self.mean)

    def mahalanobis(self, aligned: Any) -> np.ndarray:
        """Mahalanobis distance of aligned series to the Gaussian at every time.

        Parameters
        ----------
        aligned : array-like of shape (n, Z, *point_shape)
            Series on the manifold, already aligned to the ``Z`` output times.

        Returns
        -------
        distances : ndarray of shape (n, Z)
            ``sqrt(c^T S^-1 c)`` of their coordinates ``c`` at the mean: inside the tube of
            ``level`` where at most ``tube(level).radius``.
        """
        aligned = np.asarray(aligned, dtype=np.float64)
        if aligned.ndim != self.mean.ndim + 1 or aligned.shape[1:] != self.mean.shape:
            raise ValueError(
                f"aligned must have shape (n, {', '.join(map(str, self.mean.shape))}), got "
                f"{aligned.shape}"
            )
        self.manifold.validate(aligned, name="aligned")  # NaN, or points off the manifold
        coords = _coordinates(self.manifold, aligned, self.mean)
        singular = np.linalg.eigvalsh(self.covariance)[:, 0] <= 0
        if np.any(singular):
            times = np.flatnonzero(singular)
            raise ValueError(
                f"the covariance is singular at {len(times)} of {len(singular)} times (first: "
                f"{times[:5].tolist()}; the aligned series do not vary there) and reg="
                f"{self.reg:g}: pass reg > 0 to aligned_statistics for a Mahalanobis distance"
            )
        solved = np.linalg.solve(self.covariance[None], coords[..., None])[..., 0]
        return np.sqrt(np.clip((coords * solved).sum(-1), 0.0, None))

    def factor(self, index: int) -> AlignedStatistics:
        """The statistics of one factor of a product manifold (e.g. the orientation of a
        pose): its mean, coordinates and block of the covariance.

        Parameters
        ----------
        index : int

        Returns
        -------
        AlignedStatistics
        """
        if not isinstance(self.manifold, Product):
            raise TypeError(f"factor() needs a Product manifold, not {self.manifold!r}")
        factors = self.manifold.factors
        if not 0 <= index < len(factors):
            raise IndexError(f"factor index {index} out of range for {len(factors)} factors")
        dims = [f.intrinsic_dim for f in factors]
        c0 = sum(dims[:index])
        c1 = c0 + dims[index]
        mean = self.manifold._split(torch.as_tensor(self.mean))[index].numpy()
        return AlignedStatistics(
            mean=mean,
            coordinates=self.coordinates[..., c0:c1],
            covariance=self.covariance[:, c0:c1, c0:c1],
            manifold=factors[index],
            reg=self.reg,
            ddof=self.ddof,
        )


def _warn_off_manifold(manifold: Manifold, points: np.ndarray, what: str) -> None:
    """A warning when computed points are not valid points of the manifold in float64."""
    try:
        manifold.validate(points, name="point")
    except ValueError as exc:
        warnings.warn(
            f"some points of {what} are not valid points of {manifold!r} in float64 "
            f"({exc}); the spread of the aligned series is too large for the Gaussian in "
            "the tangent space to be mapped back here",
            RuntimeWarning,
            stacklevel=3,
        )


def _warn_beyond_injectivity(manifold, mean, axes, half_widths, level) -> None:
    """A warning when the tube leaves the region where ``exp`` at the mean is one-to-one."""
    nd = mean.ndim - 1
    widest = axes[:, -1] * half_widths[:, -1].reshape(-1, *([1] * nd))
    with torch.no_grad():
        beyond = manifold._beyond_injectivity(torch.as_tensor(mean), torch.as_tensor(widest))
    beyond = beyond.numpy()
    if np.any(beyond):
        warnings.warn(
            f"the {level:g} tube leaves the region where exp at the mean is one-to-one (the "
            f"injectivity radius {manifold.injectivity_radius:.3g} of {manifold!r}) at "
            f"{int(beyond.sum())} of {len(beyond)} times (largest half-width "
            f"{float(half_widths[:, -1].max()):.3g}): its boundary wraps round there and the "
            "Gaussian in the tangent space does not describe the spread",
            RuntimeWarning,
            stacklevel=3,
        )


def _coordinates(manifold: Manifold, aligned: np.ndarray, mean: np.ndarray) -> np.ndarray:
    with torch.no_grad():
        points = torch.as_tensor(aligned)
        base = torch.as_tensor(mean).unsqueeze(0).expand_as(points)
        vectors = manifold._log(base, points)
        return manifold._to_coordinates(base, vectors).numpy()


def aligned_statistics(
    alignment: Any = None,
    *,
    aligned: Any = None,
    mean: Any = None,
    manifold: Manifold | None = None,
    reg: float = REG,
    ddof: int = 1,
) -> AlignedStatistics:
    """Per-time tangent-space statistics of an aligned set (see the module docstring).

    Parameters
    ----------
    alignment : Alignment or sk_rtw.baselines.MultipleAlignment, optional
        The result of :func:`sk_rtw.align` or of a baseline (``aligned``, ``mean``,
        ``manifold`` are read from it).
    aligned : array-like of shape (N, Z, *point_shape), optional
        Aligned series, when no ``alignment`` is given.
    mean : array-like of shape (Z, *point_shape), optional
        Their mean (default: the Fréchet mean at every time).
    manifold : Manifold, optional
        Required with ``aligned``.
    reg : float, default=1e-9
        Added to the diagonal of every covariance.
    ddof : int, default=1
        ``N - ddof`` divides the sums of squares (1: the unbiased estimate).

    Returns
    -------
    AlignedStatistics

    Examples
    --------
    >>> from sk_rtw import align, aligned_statistics
    >>> from sk_rtw.datasets import make_warped_signals
    >>> data = make_warped_signals("quaternion", 5, 40, random_state=0)
    >>> stats = aligned_statistics(align(data.signals, manifold="quaternion", n_epochs=4))
    >>> stats.covariance.shape  # 3 tangent coordinates on S^3, at every output time
    (160, 3, 3)
    >>> stats.sample(2, random_state=0).shape
    (2, 160, 4)
    """
    if alignment is not None:
        aligned, mean, manifold = alignment.aligned, alignment.mean, alignment.manifold
    if aligned is None or manifold is None:
        raise TypeError("pass an alignment result, or aligned= and manifold=")
    if not isinstance(manifold, Manifold):
        raise TypeError(f"manifold must be a Manifold, got {type(manifold).__name__}")
    aligned = np.asarray(aligned, dtype=np.float64)
    nd = manifold.point_ndim
    if aligned.ndim != nd + 2 or aligned.shape[2:] != manifold.point_shape:
        raise ValueError(
            f"aligned must have shape (N, Z, {', '.join(map(str, manifold.point_shape))}) "
            f"for {manifold!r}, got {aligned.shape}"
        )
    manifold.validate(aligned, name="aligned")
    n_series = aligned.shape[0]
    if isinstance(ddof, bool) or not isinstance(ddof, (int, np.integer)) or ddof < 0:
        raise ValueError(f"ddof must be a non-negative integer, got {ddof!r}")
    if n_series - ddof < 1:
        single = (
            "this alignment is a centroid of one training series (an estimator's "
            "alignments_[k] of type SeriesCentroid: nothing was averaged; "
            "centroid_classes_[k] names its class). Pass ddof=0 for its spread (zero), or "
            "fit with fewer centroids per class (n_centroids=1, or a smaller fraction) so "
            "that every centroid averages several series"
            if alignment is not None and n_series == 1
            else "align more series, or lower ddof"
        )
        raise ValueError(
            f"a covariance needs more than ddof={ddof} aligned series; got {n_series}: "
            + single
        )
    if not (isinstance(reg, (int, float, np.floating)) and np.isfinite(reg) and reg >= 0):
        raise ValueError(f"reg must be a finite number >= 0, got {reg!r}")
    if mean is None:
        mean = np.asarray(manifold.mean(aligned))
    mean = np.asarray(mean, dtype=np.float64)
    if mean.shape != aligned.shape[1:]:
        raise ValueError(f"mean must have shape {aligned.shape[1:]}, got {mean.shape}")
    manifold.validate(mean, name="mean")
    coords = _coordinates(manifold, aligned, mean)
    covariance = np.einsum("nzi,nzj->zij", coords, coords) / (n_series - ddof)
    covariance += reg * np.eye(coords.shape[-1])
    return AlignedStatistics(mean, coords, covariance, manifold, float(reg), int(ddof))
