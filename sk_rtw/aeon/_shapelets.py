"""GeodesicShapeletClassifier for aeon: :class:`~sk_rtw.GeodesicShapeletClassifier` as an
aeon classifier."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from ..shapelets import GeodesicShapeletClassifier as _Shapelets
from ..utils._params import declare_parameters
from ._base import DelegatingClassifier

if TYPE_CHECKING:
    from ..manifolds import Manifold

_DECLARED = _Shapelets._declaration  # type: ignore[attr-defined]


@declare_parameters(_DECLARED.parameters, defaults={**_DECLARED.defaults, "n_jobs": 1})
class GeodesicShapeletClassifier(DelegatingClassifier):
    """Random dilated shapelets on any manifold with a ridge readout, as an aeon
    estimator.

    :class:`sk_rtw.GeodesicShapeletClassifier` (its parameters, defaults and
    predictions) behind aeon's :class:`~aeon.classification.base.BaseClassifier`, on
    aeon's layouts: ``(n_cases, n_channels, n_timepoints)`` or a list of
    ``(n_channels, T_i)`` arrays; every channel is a coordinate of the point
    (``manifold="quaternion"`` reads 4 channels, ``"spd"`` the ``k * k`` entries). The
    only default that differs is ``n_jobs=1`` (aeon's convention).

    Parameters
    ----------
    %(parameters)s

    Attributes
    ----------
    classes_ : ndarray of shape (n_classes,)
    n_classes_ : int
    estimator_ : sk_rtw.GeodesicShapeletClassifier
        The fitted classifier (its shapelets in ``estimator_.transform_.shapelets_``).

    See Also
    --------
    sk_rtw.GeodesicShapeletClassifier : the same classifier, scikit-learn style.
    aeon.classification.shapelet_based.RDSTClassifier : Euclidean random dilated
        shapelets.

    Examples
    --------
    >>> from aeon.datasets import load_classification
    >>> from sk_rtw.aeon import GeodesicShapeletClassifier
    >>> X, y = load_classification("GunPoint", split="train")
    >>> clf = GeodesicShapeletClassifier(n_shapelets=100, random_state=0).fit(X, y)
    >>> clf.predict(X[:3]).tolist()
    ['2', '2', '1']
    """

    _tags: ClassVar[dict[str, Any]] = {
        "capability:multivariate": True,
        "capability:unequal_length": True,
        "capability:multithreading": True,
        "X_inner_type": ["np-list", "numpy3D"],
        "algorithm_type": "shapelet",
    }
    _wrapped = _Shapelets

    def __init__(
        self,
        manifold: str | Manifold = "euclidean",
        *,
        n_shapelets: int = 10_000,
        lengths: tuple[int, ...] | None = None,
        normalised_fraction: float = 0.5,
        representation: str = "auto",
        threshold_percentiles: tuple[float, float] = (5.0, 10.0),
        readout: Any = None,
        n_jobs: int | None = 1,
        random_state: int | np.random.RandomState | np.random.Generator | None = None,
        verbose: bool | int = 0,
    ) -> None:
        self.manifold = manifold
        self.n_shapelets = n_shapelets
        self.lengths = lengths
        self.normalised_fraction = normalised_fraction
        self.representation = representation
        self.threshold_percentiles = threshold_percentiles
        self.readout = readout
        self.n_jobs = n_jobs
        self.random_state = random_state
        self.verbose = verbose
        super().__init__()

    @classmethod
    def _get_test_params(cls, parameter_set: str = "default") -> dict | list[dict]:
        """Small transforms for aeon's estimator checks."""
        return [
            {"n_shapelets": 20, "random_state": 0},
            {"n_shapelets": 10, "representation": "raw", "random_state": 1},
        ]
