"""k-means of time series on a manifold: assignment by manifold DTW, centroids by averaging."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from sklearn.base import BaseEstimator, ClusterMixin, TransformerMixin
from sklearn.utils.validation import check_is_fitted

from .._random import check_random_state
from .._settings import DEVICE_PARAMETER, PRESET_PARAMETER
from ..methods import FitContext, get_method
from ..utils import check_series_collection
from ..utils._common_params import DTW_WINDOW, MANIFOLD, N_JOBS, RANDOM_STATE, VERBOSE
from ..utils._params import declare_parameters, validate_parameters
from ._core import dtw_to_centroids, kmeans
from ._params import (
    MAX_ITER,
    METHOD,
    N_CLUSTERS,
    N_INIT,
    TOL,
    document_settings,
    set_params_with_hints,
    setting_hint,
)

if TYPE_CHECKING:
    import torch

    from ..manifolds import Manifold
    from ..methods import AveragingMethod

KMEANS_PARAMETERS = (
    N_CLUSTERS, METHOD, MANIFOLD, PRESET_PARAMETER, N_INIT, MAX_ITER, TOL, DTW_WINDOW,
    N_JOBS, RANDOM_STATE, DEVICE_PARAMETER, VERBOSE,
)  # fmt: skip
KMEANS_DEFAULTS = {
    "n_clusters": 3,
    "method": "rtw",
    "manifold": "euclidean",
    "preset": "class-means",
    "n_init": 1,
    "max_iter": 10,
    "tol": 1e-4,
    "dtw_window": None,
    "n_jobs": None,
    "random_state": None,
    "device": "cpu",
    "verbose": 0,
}


@document_settings
@declare_parameters(
    KMEANS_PARAMETERS, KMEANS_DEFAULTS, hint=setting_hint,
    notes={
        "method": '"dba" is much faster (no training); the engine\'s methods train one warp '
        "model per cluster and round.",
        "verbose": "Here 1: a line per round (inertia, changed assignments, time).",
    },
)  # fmt: skip
class RTWKMeans(ClusterMixin, TransformerMixin, BaseEstimator):
    """k-means clustering of time series on a Riemannian manifold.

    Lloyd's iterations with manifold DTW: every series goes to the centroid nearest in
    manifold DTW, every centroid is the time-warping average of its series (RTW, TTW, NTW
    or manifold DBA, as in :class:`RTWAverager`), until the assignment stops changing or
    the inertia improves by less than ``tol``; the best iterate is kept. The distance is
    ``sqrt`` of the DTW with squared geodesic point costs (tslearn's ``dtw`` on Euclidean
    data), so the inertia is the sum of squared-cost DTW values: the objective DBA
    minimises, and tslearn's ``TimeSeriesKMeans(metric="dtw")`` inertia. Centroids start by
    k-means++ seeding with DTW distances (Arthur and Vassilvitskii, 2007); ``n_init``
    seedings are run and the one with the lowest inertia is kept. A cluster that empties
    is re-seeded with the series farthest from its centroid. The length of the centroids
    follows the preset's rule (the median length of the cluster's series by default; see
    the presets table), or the method's ``output_length``.

    Parameters
    ----------
    %(parameters)s

    Attributes
    ----------
    cluster_centers_ : ndarray of shape (n_clusters, Z, *point_shape) or list
        One centroid per cluster, on the manifold (a list when lengths differ).
    labels_ : ndarray of shape (n_series,)
        Cluster of every training series.
    inertia_ : float
        Sum over the training series of the squared distance to their centroid.
    n_iter_ : int
        Rounds run by the kept seeding (its best iterate is returned).
    alignments_ : list of Alignment or sk_rtw.baselines.MultipleAlignment
        The averaging method's result of every cluster (as :class:`RTWAverager`'s): the
        series averaged into each centre, i.e. the assignment before the last round, which
        can differ from ``labels_`` (the nearest centre) where that round moved series.
    manifold_ : Manifold
    n_features_in_ : int
        Length of the training series when they are univariate of one length.

    Notes
    -----
    %(method_settings)s

    Examples
    --------
    >>> import numpy as np
    >>> from sk_rtw import RTWKMeans
    >>> t = np.linspace(0, 1, 40)
    >>> X = np.stack([np.sin(2 * np.pi * t ** p) for p in (0.8, 1.0, 1.2)]
    ...              + [np.cos(2 * np.pi * t ** p) for p in (0.8, 1.0, 1.2)])
    >>> km = RTWKMeans(n_clusters=2, method="dba", random_state=0).fit(X)
    >>> labels = km.labels_.tolist()  # cluster numbers are arbitrary: compare groupings
    >>> labels[:3] == [labels[0]] * 3 and labels[3:] == [labels[3]] * 3 != labels[:3]
    True
    """

    def __init__(
        self,
        n_clusters: int = 3,
        *,
        method: str | AveragingMethod = "rtw",
        manifold: str | Manifold = "euclidean",
        preset: str = "class-means",
        n_init: int = 1,
        max_iter: int = 10,
        tol: float = 1e-4,
        dtw_window: float | None = None,
        n_jobs: int | None = None,
        random_state: int | np.random.RandomState | np.random.Generator | None = None,
        device: str | torch.device = "cpu",
        verbose: bool | int = 0,
    ) -> None:
        self.n_clusters = n_clusters
        self.method = method
        self.manifold = manifold
        self.preset = preset
        self.n_init = n_init
        self.max_iter = max_iter
        self.tol = tol
        self.dtw_window = dtw_window
        self.n_jobs = n_jobs
        self.random_state = random_state
        self.device = device
        self.verbose = verbose

    def set_params(self, **params):
        """Set parameters, scikit-learn's way; ``method__<setting>`` also works when
        ``method`` is a name (it becomes the method's object), and a setting that is no
        parameter says where it belongs.

        Parameters
        ----------
        **params : dict

        Returns
        -------
        self
        """
        set_params_with_hints(self, params, super().set_params)
        return self

    def fit(self, X: Any, y: Any = None):
        """Cluster the series.

        Parameters
        ----------
        X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list
            Series on the manifold (a list of ``(T_i, *point_shape)`` arrays for unequal
            lengths).
        y : ignored

        Returns
        -------
        self
        """
        params = validate_parameters(self)
        method = get_method(params["method"])
        self._context = FitContext(
            preset=params["preset"], dtw_window=params["dtw_window"], device=params["device"],
            n_jobs=params["n_jobs"], verbose=int(params["verbose"]),
        )  # fmt: skip
        config = method.configure(self._context)  # every setting checked and resolved, once
        collection = check_series_collection(X, self.manifold)
        n_clusters = params["n_clusters"]
        if collection.n_series < n_clusters:
            raise ValueError(
                f"n_clusters={n_clusters} needs at least as many series; got {collection.n_series}"
            )
        rng = check_random_state(self.random_state)
        problem = np.zeros(collection.n_series, dtype=np.int64)
        best = None
        for run in range(params["n_init"]):
            (outcome,) = kmeans(
                collection, problem, [n_clusters], method, config, self._context, [rng],
                max_iter=params["max_iter"], tol=params["tol"],
                init_label=f"init {run + 1}/{params['n_init']} ", owner="RTWKMeans",
            )  # fmt: skip
            if best is None or outcome.inertia < best.inertia:
                best = outcome
        assert best is not None
        self.manifold_ = collection.manifold
        same_length = len({len(c) for c in best.centroids}) == 1
        self.cluster_centers_ = np.stack(best.centroids) if same_length else best.centroids
        self.labels_ = best.labels
        self.alignments_ = best.fits
        self.inertia_ = float(best.inertia)
        self.n_iter_ = best.n_iter
        if collection.equal_length and collection.manifold.point_shape == (1,):
            self.n_features_in_ = collection.max_length
        return self

    # ------------------------------------------------------------ inference
    def transform(self, X: Any) -> np.ndarray:
        """Manifold-DTW distance of every series to every centroid.

        Parameters
        ----------
        X : array-like or list of series
            Series of any length on the training manifold.

        Returns
        -------
        distances : ndarray of shape (n_series, n_clusters)
        """
        check_is_fitted(self, "cluster_centers_")
        collection = check_series_collection(X, self.manifold_, min_length=1)
        return dtw_to_centroids(collection, list(self.cluster_centers_), self._context)

    def predict(self, X: Any) -> np.ndarray:
        """Index of the nearest centroid.

        Parameters
        ----------
        X : array-like or list of series
            Series of any length on the training manifold.

        Returns
        -------
        labels : ndarray of shape (n_series,)
        """
        return self.transform(X).argmin(1)

    def fit_predict(self, X: Any, y: Any = None, **kwargs) -> np.ndarray:
        """Cluster the series and return ``labels_``.

        Parameters
        ----------
        X : array-like or list of series
        y : ignored

        Returns
        -------
        labels : ndarray of shape (n_series,)
        """
        return self.fit(X).labels_

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.allow_nan = False
        tags.non_deterministic = False
        return tags
