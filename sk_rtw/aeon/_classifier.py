"""RTWClassifier: :class:`~sk_rtw.RTWNearestCentroid` as an aeon classifier."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from aeon.classification.base import BaseClassifier
from aeon.utils.validation import check_n_jobs

from ..estimators import RTWNearestCentroid
from ..manifolds import SPD, Euclidean, Manifold
from ..utils import from_aeon
from ..utils._params import declare_parameters

if TYPE_CHECKING:
    import torch

    from ..methods import AveragingMethod

_NEAREST_CENTROID = RTWNearestCentroid._declaration  # type: ignore[attr-defined]


def _is_named(manifold: Any, name: str) -> bool:
    return isinstance(manifold, str) and manifold.lower() == name


def time_major(X: np.ndarray | list[np.ndarray], manifold: Any) -> np.ndarray | list:
    """aeon's channels-first cases as sk_rtw series of ``manifold``'s points.

    Every channel is a coordinate of the point: ``(n, c, T)`` becomes ``(n, T)`` for one
    channel, ``(n, T, c)`` otherwise; for SPD(k) the ``c = k * k`` channels are the
    matrix's entries, row by row, and become ``(n, T, k, k)``.
    """
    series = from_aeon(X)
    if not (_is_named(manifold, "spd") or isinstance(manifold, SPD)):
        return series
    shapes = {np.shape(s)[1:] for s in series}
    n_channels = 1 if shapes == {()} else next(iter(shapes))[0]
    k = math.isqrt(n_channels)
    if k * k != n_channels or (isinstance(manifold, SPD) and manifold.dim != k):
        expected = f"{manifold.dim ** 2}" if isinstance(manifold, SPD) else "a square number of"
        raise ValueError(
            f"SPD points in aeon's layout are the k x k matrix's entries as channels, row "
            f"by row: expected {expected} channels, got {n_channels}"
        )
    if isinstance(series, np.ndarray):
        return series.reshape(*series.shape[:2], k, k)
    return [np.reshape(s, (len(s), k, k)) for s in series]


@declare_parameters(
    _NEAREST_CENTROID.parameters,
    defaults={**_NEAREST_CENTROID.defaults, "n_jobs": 1},
)
class RTWClassifier(BaseClassifier):
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

    def __init__(
        self,
        manifold: str | Manifold = "euclidean",
        *,
        method: str | AveragingMethod = "rtw",
        preset: str = "class-means",
        n_centroids: int | str = "auto",
        dtw_window: float | str | None = "auto",
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
        self.n_jobs = n_jobs
        self.random_state = random_state
        self.device = device
        self.verbose = verbose
        self.temperature = temperature
        super().__init__()

    def _manifold_for(self, X: np.ndarray | list[np.ndarray]) -> str | Manifold:
        """The manifold handed on: ``"euclidean"`` becomes ``Euclidean(n_channels)``.

        The layout is known here, so the time-major check against aeon's layout (a
        by-name Euclidean array with fewer time points than channels is refused) must
        not refuse short multichannel cases; the resolved manifold is the same.
        """
        n_channels = X.shape[1] if isinstance(X, np.ndarray) else X[0].shape[0]
        if _is_named(self.manifold, "euclidean") and n_channels > 1:
            return Euclidean(n_channels)
        return self.manifold

    def _fit(self, X: np.ndarray | list[np.ndarray], y: np.ndarray) -> RTWClassifier:
        self._n_jobs = check_n_jobs(self.n_jobs if self.n_jobs is not None else 1)
        params = {
            name: getattr(self, name) for name in _NEAREST_CENTROID.names if name != "n_jobs"
        }
        params["manifold"] = self._manifold_for(X)
        self.estimator_ = RTWNearestCentroid(n_jobs=self._n_jobs, **params)
        self.estimator_.fit(time_major(X, self.manifold), y)
        return self

    def _predict(self, X: np.ndarray | list[np.ndarray]) -> np.ndarray:
        return self.estimator_.predict(time_major(X, self.manifold))

    def _predict_proba(self, X: np.ndarray | list[np.ndarray]) -> np.ndarray:
        return self.estimator_.predict_proba(time_major(X, self.manifold))

    @classmethod
    def _get_test_params(cls, parameter_set: str = "default") -> dict | list[dict]:
        """Fast settings for aeon's estimator checks: few epochs, a fixed seed."""
        from ..methods import DBA, RTW

        return [
            {"method": RTW(n_epochs=2), "random_state": 0},
            {"method": DBA(max_iter=2), "n_centroids": 1, "dtw_window": 0.1},
        ]
