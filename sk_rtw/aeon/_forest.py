"""RTWProximityForestClassifier: :class:`~sk_rtw.RTWProximityForest` as an aeon
classifier."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from ..forest import RTWProximityForest
from ..utils._params import declare_parameters
from ._base import DelegatingClassifier

if TYPE_CHECKING:
    from ..forest import Splitter
    from ..manifolds import Manifold

_FOREST = RTWProximityForest._declaration  # type: ignore[attr-defined]


@declare_parameters(_FOREST.parameters, defaults={**_FOREST.defaults, "n_jobs": 1})
class RTWProximityForestClassifier(DelegatingClassifier):
    """Proximity Forest on manifold DTW and geodesic shapelets, as an aeon estimator.

    :class:`sk_rtw.RTWProximityForest` (its parameters, defaults and predictions) behind
    aeon's :class:`~aeon.classification.base.BaseClassifier`: it takes aeon's layouts as
    they are, ``(n_cases, n_channels, n_timepoints)``, ``(n_cases, n_timepoints)`` or a
    list of ``(n_channels, T_i)`` arrays of unequal lengths, and works with aeon's tools
    (``fit_predict``, ``score``, benchmarking, tsml-eval experiments). Every channel is a
    coordinate of the point: ``manifold="quaternion"`` reads 4 channels (w, x, y, z),
    ``"pose"`` 7, ``"spd"`` the ``k * k`` entries of a matrix row by row.

    The only default that differs from :class:`~sk_rtw.RTWProximityForest` is
    ``n_jobs=1`` (aeon's convention; scikit-learn's ``None`` means the same), and no
    parameter changes what is computed.

    Parameters
    ----------
    %(parameters)s

    Attributes
    ----------
    classes_ : ndarray of shape (n_classes,)
    n_classes_ : int
    estimator_ : RTWProximityForest
        The fitted forest (its trees in ``trees_``).

    See Also
    --------
    sk_rtw.RTWProximityForest : the same classifier, scikit-learn style.
    sk_rtw.aeon.RTWClassifier : the nearest-centroid classifier for aeon.

    Examples
    --------
    >>> from aeon.datasets import load_classification
    >>> from sk_rtw.aeon import RTWProximityForestClassifier
    >>> X, y = load_classification("GunPoint", split="train")
    >>> clf = RTWProximityForestClassifier(n_trees=10, random_state=0).fit(X, y)
    >>> clf.predict(X[:3]).tolist()
    ['2', '2', '1']
    """

    _tags: ClassVar[dict[str, Any]] = {
        "capability:multivariate": True,
        "capability:unequal_length": True,
        "capability:multithreading": True,
        "X_inner_type": ["np-list", "numpy3D"],
        "algorithm_type": "hybrid",  # elastic distances and shapelets
    }
    _wrapped = RTWProximityForest

    def __init__(
        self,
        manifold: str | Manifold = "euclidean",
        *,
        n_trees: int = 100,
        splitters: tuple[Splitter, ...] | None = None,
        n_candidates: int = 5,
        representation: str = "auto",
        exemplars: str = "series",
        max_depth: int | None = None,
        scoring_sample: int | None = 1000,
        n_jobs: int | None = 1,
        random_state: int | np.random.RandomState | np.random.Generator | None = None,
        verbose: bool | int = 0,
    ) -> None:
        self.manifold = manifold
        self.n_trees = n_trees
        self.splitters = splitters
        self.n_candidates = n_candidates
        self.representation = representation
        self.exemplars = exemplars
        self.max_depth = max_depth
        self.scoring_sample = scoring_sample
        self.n_jobs = n_jobs
        self.random_state = random_state
        self.verbose = verbose
        super().__init__()

    @classmethod
    def _get_test_params(cls, parameter_set: str = "default") -> dict | list[dict]:
        """Small forests for aeon's estimator checks."""
        return [
            {"n_trees": 3, "random_state": 0},
            {"n_trees": 2, "representation": "raw", "max_depth": 2, "random_state": 1},
        ]
