"""What a classifier compares: the series themselves, or their tangent velocity.

The tangent velocity of a series ``x_0, ..., x_{T-1}`` is its ``T - 1`` steps
``log_{x_t}(x_{t+1})``, each in the coordinates of :meth:`~sk_rtw.Manifold.velocity`:
the manifold's derivative series, in a frame that compares across time and across series
(Euclidean first differences, the body angular velocity of unit quaternions, the whitened
logarithm of SPD matrices, ...). Velocities are Euclidean vectors, so DTW compares them
with the Euclidean point cost. On univariate UCR data it is the first difference, which
the elastic-classifier literature found to be one of the strongest levers of accuracy
(Proximity Forest 2.0 draws it for half of its splits).

:func:`tangent_velocity` is the public function; :func:`represent` is how the estimators
ask for a representation by name (:data:`REPRESENTATIONS`).
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from .manifolds import Euclidean, Manifold
from .utils import SeriesCollection, check_series_collection

#: The representations a classifier can compare series in.
REPRESENTATIONS = ("raw", "velocity")
#: The values every ``representation`` parameter takes: one of :data:`REPRESENTATIONS`,
#: or ``"auto"``, chosen from the training data (by a held-out choice in the centroid
#: estimators, split by split in the forest, shapelet by shapelet in the shapelets).
REPRESENTATION_VALUES = (*REPRESENTATIONS, "auto")
#: The forest's former word for ``"auto"``, still accepted with a FutureWarning.
DEPRECATED_BOTH = "both"


def drawn_representations(value: str) -> tuple[str, ...]:
    """The representations an estimator that draws them (the forest, the shapelets)
    draws from for a ``representation`` value: every one for ``"auto"``."""
    if value == DEPRECATED_BOTH:
        warnings.warn(
            'representation="both" is now representation="auto" (the same draw); "both" '
            "will be removed",
            FutureWarning,
            stacklevel=3,
        )
        value = "auto"
    return REPRESENTATIONS if value == "auto" else (value,)


def velocity_collection(collection: SeriesCollection) -> SeriesCollection:
    """The tangent velocity of validated series (each at least 2 samples long), as series
    on ``Euclidean(manifold.velocity_dim)``, padded by repeating each series' last
    velocity (the package's padding convention)."""
    manifold = collection.manifold
    data = collection.data
    steps = np.asarray(manifold.velocity(data[:, :-1], data[:, 1:]))
    steps = steps.reshape(collection.n_series, collection.max_length - 1, -1)
    lengths = collection.lengths - 1
    valid = np.arange(steps.shape[1])[None, :] < lengths[:, None]
    finite = np.isfinite(steps).all(-1)
    if not finite[valid].all():
        series, time = np.argwhere(valid & ~finite)[0]
        note = manifold.spread_note(data[series, time : time + 2])
        raise ValueError(
            f"the tangent velocity of series {series} between time points {time} and "
            f"{time + 1} is not finite on {manifold!r}"
            + (f" ({note})" if note else "")
            + ": the step between these points is beyond float64; rescale the series"
        )
    for i in np.flatnonzero(lengths < steps.shape[1]):
        steps[i, lengths[i] :] = steps[i, lengths[i] - 1]
    return SeriesCollection(
        data=np.ascontiguousarray(steps), lengths=lengths, manifold=Euclidean(steps.shape[-1])
    )


def represented_manifold(manifold: Manifold, representation: str) -> Manifold:
    """The space of a representation's samples: the manifold itself, or
    ``Euclidean(manifold.velocity_dim)`` for the velocity."""
    return manifold if representation == "raw" else Euclidean(manifold.velocity_dim)


def represent(collection: SeriesCollection, representation: str) -> SeriesCollection:
    """``collection`` in ``representation`` (one of :data:`REPRESENTATIONS`): the
    collection itself, or its :func:`velocity_collection`."""
    if representation == "raw":
        return collection
    if representation == "velocity":
        return velocity_collection(collection)
    raise ValueError(f"representation must be one of {REPRESENTATIONS}, got {representation!r}")


def tangent_velocity(X: Any, manifold: str | Manifold = "euclidean") -> np.ndarray | list:
    """The tangent velocity of every series: its steps ``log_{x_t}(x_{t+1})`` in
    coordinates that compare across time and across series.

    The derivative series of a manifold-valued series (:meth:`Manifold.velocity
    <sk_rtw.Manifold.velocity>` gives each space's coordinates): first differences of
    Euclidean data (``np.diff``), the signed angular step on the circle S^1, the ambient
    tangent vector on S^d (d >= 2), the body angular velocity ``2 log(q_t^-1 q_{t+1})`` of
    unit quaternions (its norm the rotation angle, the sign ambiguity resolved), the
    whitened logarithm ``logm(X_t^-1/2 X_{t+1} X_t^-1/2)`` of SPD matrices in the
    eigenbasis of ``X_t`` and isometric coordinates (its norm the affine-invariant
    distance; the same in any world frame ``R X R^T``, :class:`~sk_rtw.manifolds.SPD`'s
    ``velocity_frame``), each factor's of a product.
    Velocities are Euclidean: compare them with ``manifold="euclidean"`` (the
    classifiers' ``representation="velocity"`` does so).

    Parameters
    ----------
    X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list of series
        Series of at least 2 samples (a list of ``(T_i, *point_shape)`` arrays for
        unequal lengths).
    manifold : str or Manifold, default="euclidean"
        Space of the samples; a name takes its dimension from the data.

    Returns
    -------
    velocity : ndarray of shape (n_series, n_timepoints - 1, velocity_dim), or a list
        One step fewer than the series. Univariate series given as ``(n, T)`` (or a list
        of 1-D arrays) give ``(n, T - 1)`` (1-D arrays), like ``np.diff(X, axis=1)``;
        unequal lengths give a list of ``(T_i - 1, velocity_dim)`` arrays.

    Examples
    --------
    >>> import numpy as np
    >>> from sk_rtw import tangent_velocity
    >>> tangent_velocity(np.array([[0.0, 1.0, 3.0]]))
    array([[1., 2.]])
    >>> angles = np.array([0.0, 0.1, 0.3])  # a turn about z at 0.1 then 0.2 rad a step
    >>> q = np.stack([np.cos(angles / 2), 0 * angles, 0 * angles, np.sin(angles / 2)], -1)
    >>> tangent_velocity(q[None], "quaternion").round(12)
    array([[[0. , 0. , 0.1],
            [0. , 0. , 0.2]]])
    """
    collection = check_series_collection(X, manifold, min_length=2)
    velocity = velocity_collection(collection)
    univariate = _univariate_input(X) and velocity.data.shape[-1] == 1
    if collection.equal_length:
        return velocity.data[..., 0] if univariate else velocity.data
    return [
        velocity.series(i)[:, 0] if univariate else velocity.series(i)
        for i in range(velocity.n_series)
    ]


def _univariate_input(X: Any) -> bool:
    """Whether ``X`` was given without a point axis: ``(n, T)`` or a list of 1-D series."""
    if isinstance(X, (list, tuple)) or (isinstance(X, np.ndarray) and X.dtype == object):
        return all(np.ndim(s) == 1 for s in X)
    return np.ndim(X) == 2
