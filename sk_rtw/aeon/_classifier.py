"""RTWClassifier: :class:`~sk_rtw.RTWNearestCentroid` as an aeon classifier."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from ..estimators import RTWNearestCentroid
from ..methods import DBA, RTW
from ..utils._params import declare_parameters
from ._base import DelegatingClassifier

if TYPE_CHECKING:
    import torch

    from ..estimators import AutoChoice
    from ..manifolds import Manifold
    from ..methods import AveragingMethod

_NEAREST_CENTROID = RTWNearestCentroid._declaration  # type: ignore[attr-defined]


@declare_parameters(
    _NEAREST_CENTROID.parameters,
    defaults={**_NEAREST_CENTROID.defaults, "n_jobs": 1},
)
class RTWClassifier(DelegatingClassifier):
    """Nearest-centroid classifier by manifold DTW to RTW centroids, as an aeon estimator.

    :class:`sk_rtw.RTWNearestCentroid` (its parameters, defaults and predictions) behind
    aeon's :class:`~aeon.classification.base.BaseClassifier`: it takes aeon's layouts as
    they are, ``(n_cases, n_channels, n_timepoints)``, ``(n_cases, n_timepoints)`` or a
    list of ``(n_channels, T_i)`` arrays of unequal lengths, and works with aeon's
    tools (``fit_predict``, ``score``, benchmarking, tsml-eval experiments). Every
    channel is a coordinate of the point: ``manifold="quaternion"`` reads 4 channels
    (w, x, y, z), ``"pose"`` 7, ``"spd"`` the ``k * k`` entries of a matrix row by row.

    The only default that differs from :class:`~sk_rtw.RTWNearestCentroid` is
    ``n_jobs=1`` (aeon's convention; scikit-learn's ``None`` means the same), and no
    parameter changes what is computed. Use :class:`~sk_rtw.RTWNearestCentroid` itself
    with scikit-learn (``Pipeline``, ``GridSearchCV``) on sk_rtw's time-major layout;
    :func:`sk_rtw.utils.from_aeon` converts.

    Parameters
    ----------
    %(parameters)s

    Attributes
    ----------
    classes_ : ndarray of shape (n_classes,)
    n_classes_ : int
    estimator_ : RTWNearestCentroid
        The fitted classifier: its centroids (``means_``, time-major), the chosen band
        (``dtw_window_``) and centroids per class (``n_centroids_``), ``selection_``.

    See Also
    --------
    sk_rtw.RTWNearestCentroid : the same classifier, scikit-learn style.

    Examples
    --------
    >>> from aeon.datasets import load_classification
    >>> from sk_rtw import RTW
    >>> from sk_rtw.aeon import RTWClassifier
    >>> X, y = load_classification("GunPoint", split="train")
    >>> X.shape
    (50, 1, 150)
    >>> clf = RTWClassifier(method=RTW(n_epochs=8), random_state=0).fit(X, y)
    >>> clf.predict(X[:3]).tolist()
    ['2', '2', '1']
    """

    _tags: ClassVar[dict[str, Any]] = {
        "capability:multivariate": True,
        "capability:unequal_length": True,
        "capability:multithreading": True,
        "X_inner_type": ["np-list", "numpy3D"],
        "algorithm_type": "distance",
        "python_dependencies": "torch",
    }
    _wrapped = RTWNearestCentroid

    def __init__(
        self,
        manifold: str | Manifold = "euclidean",
        *,
        method: str | AveragingMethod = "rtw",
        preset: str = "class-means",
        n_centroids: int | str = "auto",
        dtw_window: float | str | None = "auto",
        representation: str = "raw",
        choice: AutoChoice | None = None,
        n_jobs: int | None = 1,
        random_state: int | np.random.RandomState | np.random.Generator | None = None,
        device: str | torch.device = "cpu",
        verbose: bool | int = 0,
        temperature: float | str = "fit",
    ) -> None:
        self.manifold = manifold
        self.method = method
        self.preset = preset
        self.n_centroids = n_centroids
        self.dtw_window = dtw_window
        self.representation = representation
        self.choice = choice
        self.n_jobs = n_jobs
        self.random_state = random_state
        self.device = device
        self.verbose = verbose
        self.temperature = temperature
        super().__init__()

    @classmethod
    def _get_test_params(cls, parameter_set: str = "default") -> dict | list[dict]:
        """Fast settings for aeon's estimator checks: few epochs, a fixed seed."""
        return [
            {"method": RTW(n_epochs=2), "random_state": 0},
            {"method": DBA(max_iter=2), "n_centroids": 1, "dtw_window": 0.1},
        ]
