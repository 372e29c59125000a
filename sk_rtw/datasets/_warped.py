"""Synthetic data by inverted time warping (paper, section V-B).

A smooth original signal on the manifold is warped by N random monotone warping functions
(NTW form, TTW form and random monotone splines), applied with the same tangent-space sinc
interpolation as the alignment engine. Reversing the warps restores the original, so
alignment quality can be measured against a known answer.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch
from scipy.interpolate import CubicSpline, PchipInterpolator

from .._random import check_generator
from ..align._sinc import tangent_sinc_interpolate
from ..manifolds import Manifold, get_manifold

WARP_FAMILIES = ("ntw", "ttw", "spline")


@dataclass(frozen=True, eq=False)
class WarpedSignals:
    """Output of :func:`make_warped_signals`.

    Attributes
    ----------
    original : ndarray of shape (T, *point_shape)
    signals : ndarray of shape (N, T, *point_shape)
        ``signals[n, t]`` is the original at relative position ``warps[n, t]``.
    warps : ndarray of shape (N, T)
        The true warping functions, monotone, from 0 to 1.
    families : list of str
        Family each warp was drawn from.
    manifold : Manifold
    """

    original: np.ndarray
    signals: np.ndarray
    warps: np.ndarray
    families: list[str]
    manifold: Manifold


def smooth_signal(
    manifold: Manifold,
    length: int,
    rng: np.random.Generator,
    n_knots: int = 8,
    amplitude: float = 1.0,
) -> np.ndarray:
    """A smooth curve on the manifold: a cubic spline through random tangent vectors at a
    random base point, mapped with ``Exp``; shape (length, *point_shape)."""
    base = manifold.random_point((), rng)
    knots = manifold.random_tangent(np.stack([base] * n_knots), 1.0, rng)
    radius = manifold.injectivity_radius
    norms = np.asarray(manifold.norm(np.stack([base] * n_knots), knots))
    limit = min(amplitude, 0.45 * radius) if np.isfinite(radius) else amplitude
    knots = knots * (limit / max(norms.max(), 1e-12))
    spline = CubicSpline(np.linspace(0.0, 1.0, n_knots), knots, axis=0, bc_type="natural")
    tangent = spline(np.linspace(0.0, 1.0, length))
    return manifold.project(manifold.exp(base, tangent))


def random_warp(
    family: str, length: int, rng: np.random.Generator, strength: float = 1.0
) -> np.ndarray:
    """One random warp from ``family`` (no constraint check), shape (length,)."""
    zhat = np.linspace(0.0, 1.0, length)
    if family == "ttw":
        k = np.arange(1, 5)
        coefficients = rng.normal(0.0, 0.12 * strength / k)
        return zhat + np.sin(np.pi * np.outer(zhat, k)) @ coefficients
    if family == "ntw":
        # a random one-hidden-layer network as phi(zhat), as in eq. (6) for one signal
        w1, b1 = rng.normal(0, 3.0, 16), rng.normal(0, 1.0, 16)
        w2 = rng.normal(0, 0.35 * strength, 16)
        phi = np.tanh(np.outer(zhat, w1) + b1) @ w2
        return zhat + zhat * (1.0 - zhat) * phi
    if family == "spline":
        n_knots = int(rng.integers(3, 8))
        increments = rng.dirichlet(np.full(n_knots, 4.0 / strength))
        knots_y = np.concatenate([[0.0], np.cumsum(increments)])
        knots_x = np.linspace(0.0, 1.0, n_knots + 1)
        if rng.random() < 0.5:
            return PchipInterpolator(knots_x, knots_y)(zhat)
        return np.interp(zhat, knots_x, knots_y)
    raise ValueError(f"unknown warp family {family!r}; choose from {WARP_FAMILIES}")


def _is_valid(warp: np.ndarray, max_slope: float) -> bool:
    slopes = np.diff(warp) * (len(warp) - 1)
    return (
        abs(warp[0]) < 1e-12
        and abs(warp[-1] - 1.0) < 1e-12
        and slopes.min() >= 1.0 / max_slope
        and slopes.max() <= max_slope
    )


def make_warped_signals(
    manifold: str | Manifold = "sphere",
    n_signals: int = 4,
    length: int = 100,
    random_state=None,
    *,
    dim: int | None = None,
    families: tuple[str, ...] = WARP_FAMILIES,
    strength: float = 1.0,
    max_slope: float = 4.0,
    amplitude: float = 1.0,
    original: np.ndarray | None = None,
) -> WarpedSignals:
    """Generate N time-warped copies of one smooth signal on a manifold.

    Parameters
    ----------
    manifold : str or Manifold, default="sphere"
        The space; a name without ``dim`` uses a small default (S^1 for "sphere",
        R^1 for "euclidean", SPD(2) for "spd").
    n_signals : int, default=4
    length : int, default=100
        Length ``T`` of the original and of every warped signal.
    random_state : int, Generator, RandomState or None
    dim : int, optional
        Dimension for a named manifold.
    families : tuple of {"ntw", "ttw", "spline"}
        Warp families; each warp is drawn from one of them uniformly.
    strength : float, default=1.0
        Scale of the random warp parameters (0 gives identity warps).
    max_slope : float, default=4.0
        Rejection bound on the relative slope: every warp satisfies
        ``1 / max_slope <= w'(t) <= max_slope`` (monotone, no sample skipped or frozen
        beyond that), besides ``w(0) = 0`` and ``w(1) = 1``.
    amplitude : float, default=1.0
        Size of the original signal in the tangent space (capped below the injectivity
        radius).
    original : array-like of shape (T, *point_shape), optional
        Use this signal instead of a random one.

    Returns
    -------
    WarpedSignals
    """
    rng = check_generator(random_state)
    if isinstance(manifold, str):
        default_dims = {"sphere": 1, "euclidean": 1, "spd": 2}
        manifold = get_manifold(
            manifold, dim if dim is not None else default_dims.get(manifold.lower())
        )
    if n_signals < 1 or length < 2:
        raise ValueError("n_signals must be >= 1 and length >= 2")
    unknown = set(families) - set(WARP_FAMILIES)
    if not families or unknown:
        raise ValueError(f"families must be a non-empty subset of {WARP_FAMILIES}")
    if original is None:
        original = smooth_signal(manifold, length, rng, amplitude=amplitude)
    else:
        original = np.asarray(original, dtype=np.float64)
        manifold.validate(original, name="original")
        length = len(original)
    drawn: list[np.ndarray] = []
    chosen: list[str] = []
    while len(drawn) < n_signals:
        family = families[int(rng.integers(len(families)))]
        for _ in range(1000):
            warp = random_warp(family, length, rng, strength)
            if _is_valid(warp, max_slope):
                break
        else:
            raise RuntimeError(f"could not draw a valid {family!r} warp; lower strength")
        drawn.append(warp)
        chosen.append(family)
    warps = np.stack(drawn)
    data = torch.from_numpy(np.ascontiguousarray(original))[None]
    lengths = torch.tensor([length])
    with torch.no_grad():
        signals = tangent_sinc_interpolate(
            manifold,
            data.expand(n_signals, *data.shape[1:]),
            lengths.expand(n_signals),
            torch.from_numpy(warps),
            refinements=2,  # the warped samples are the weighted Fréchet means of the window
        ).numpy()
    return WarpedSignals(
        original=original,
        signals=manifold.project(signals),
        warps=warps,
        families=chosen,
        manifold=manifold,
    )
