"""k-means of time series on a manifold: assignment by manifold DTW, centres by averaging."""

from __future__ import annotations

from typing import Any

import numpy as np
from sklearn.base import BaseEstimator, ClusterMixin, TransformerMixin
from sklearn.utils import check_random_state
from sklearn.utils.validation import check_is_fitted

from .._numba import check_n_jobs
from .._random import check_random_state_value
from ..align._config import check_int, check_positive, check_preset
from ..dtw import check_window
from ..manifolds import Manifold
from ..utils import check_series_collection
from ._core import (
    ENGINE_ARGUMENTS,
    ENGINE_OPTIONS,
    ESTIMATOR_METHODS,
    centre_settings,
    dtw_to_centres,
    engine_keywords,
    kmeans,
)

#: Engine settings of the centre fits that ``averager_params`` may set.
AVERAGER_PARAMS = tuple(
    name for name in (*ENGINE_ARGUMENTS, *ENGINE_OPTIONS)
    if name not in ("preset", "n_epochs", "device")
)  # fmt: skip


class RTWKMeans(ClusterMixin, TransformerMixin, BaseEstimator):
    """k-means clustering of time series on a Riemannian manifold.

    Lloyd's iterations with manifold DTW: every series goes to the centre nearest in
    manifold DTW, every centre is the time-warping average of its series (RTW, TTW, NTW
    or manifold DBA, as in :class:`RTWAverager`), until the assignment stops changing or
    the inertia improves by less than ``tol``; the best iterate is kept. The distance is
    ``sqrt`` of the DTW with squared geodesic point costs (tslearn's ``dtw`` on Euclidean
    data), so the inertia is the sum of squared-cost DTW values: the objective DBA
    minimises, and tslearn's ``TimeSeriesKMeans(metric="dtw")`` inertia. Centres start by
    k-means++ seeding with DTW distances (Arthur and Vassilvitskii, 2007); ``n_init``
    seedings are run and the one with the lowest inertia is kept. A cluster that empties
    is re-seeded with the series farthest from its centre.

    Parameters
    ----------
    n_clusters : int, default=3
    method : {"rtw", "ttw", "ntw", "dba"}, default="rtw"
        Averaging method of the centres. ``"dba"`` is much faster (no training); the
        engine's methods train one warp model per cluster and iteration.
    manifold : str or Manifold, default="euclidean"
        Space of the samples; a name takes its dimension from the data.
    n_init : int, default=1
        k-means++ seedings; the clustering with the lowest inertia is kept.
    max_iter : int, default=10
        Assignment/update rounds per seeding.
    tol : float, default=1e-4
        Stop when the inertia improves by less than this fraction.
    output_length : int, optional
        Length of the centres (default: the longest series; see :class:`RTWAverager`).
    n_epochs : int, default=256
        Adam epochs of each centre fit (RTW, TTW, NTW).
    preset : {"default", "paper"} or None, default=None
        Engine preset of the centre fits.
    dtw_window : float in [0, 1], optional
        Sakoe–Chiba band of every DTW (assignment and DBA).
    n_jobs : int, optional
        Centres fitted in parallel and threads of the DTW computations.
    random_state : int, RandomState or None
        Seeds the k-means++ seeding and the centre fits.
    device : str, default="cpu"
        Torch device of the centre fits.
    verbose : int, default=0
        1: a line per iteration (inertia, changed assignments, time); 2: also per centre.
    averager_params : dict, optional
        Further engine settings of the centre fits, by their :class:`RTWAverager` names
        (``learning_rate``, ``hidden_size``, ``warp_start``, ``mean_weights``, ...; an
        unknown name is a ``TypeError``).

    Attributes
    ----------
    cluster_centers_ : ndarray of shape (n_clusters, Z, *point_shape) or list
        One centre per cluster, on the manifold (a list when lengths differ).
    labels_ : ndarray of shape (n_series,)
        Cluster of every training series.
    inertia_ : float
        Sum over the training series of the squared distance to their centre.
    n_iter_ : int
        Rounds run by the kept seeding (its best iterate is returned).
    manifold_ : Manifold
    n_features_in_ : int
        Length of the training series when they are univariate of one length.

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
        method: str = "rtw",
        manifold: str | Manifold = "euclidean",
        n_init: int = 1,
        max_iter: int = 10,
        tol: float = 1e-4,
        output_length: int | None = None,
        n_epochs: int = 256,
        preset: str | None = None,
        dtw_window: float | None = None,
        n_jobs: int | None = None,
        random_state: Any = None,
        device: str = "cpu",
        verbose: int = 0,
        averager_params: dict[str, Any] | None = None,
    ):
        self.n_clusters = n_clusters
        self.method = method
        self.manifold = manifold
        self.n_init = n_init
        self.max_iter = max_iter
        self.tol = tol
        self.output_length = output_length
        self.n_epochs = n_epochs
        self.preset = preset
        self.dtw_window = dtw_window
        self.n_jobs = n_jobs
        self.random_state = random_state
        self.device = device
        self.verbose = verbose
        self.averager_params = averager_params

    # ------------------------------------------------------------------ fit
    def _check_params(self) -> None:
        check_int("n_clusters", self.n_clusters, 1)
        check_int("n_init", self.n_init, 1)
        check_int("max_iter", self.max_iter, 1)
        check_positive("tol", self.tol, allow_zero=True)
        if self.averager_params is not None and not isinstance(self.averager_params, dict):
            raise TypeError(
                f"averager_params must be a dict or None, got {type(self.averager_params)}"
            )
        if not isinstance(self.method, str) or self.method.lower() not in ESTIMATOR_METHODS:
            raise ValueError(f"method must be one of {ESTIMATOR_METHODS}, got {self.method!r}")
        check_random_state_value(self.random_state)
        check_n_jobs(self.n_jobs)
        check_window(self.dtw_window, name="dtw_window")

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
        self._check_params()
        collection = check_series_collection(X, self.manifold)
        if collection.n_series < self.n_clusters:
            raise ValueError(
                f"n_clusters={self.n_clusters} needs at least as many series; got "
                f"{collection.n_series}"
            )
        self._settings = self._centre_settings(collection)
        rng = check_random_state(self.random_state)
        problem = np.zeros(collection.n_series, dtype=np.int64)
        best = None
        for run in range(self.n_init):
            (outcome,) = kmeans(
                collection, problem, [self.n_clusters], self._settings, [rng],
                max_iter=self.max_iter, tol=self.tol,
                init_label=f"init {run + 1}/{self.n_init} ",
            )  # fmt: skip
            if best is None or outcome.inertia < best.inertia:
                best = outcome
        assert best is not None
        self.manifold_ = collection.manifold
        same_length = len({len(c) for c in best.centres}) == 1
        self.cluster_centers_ = np.stack(best.centres) if same_length else best.centres
        self.labels_ = best.labels
        self.inertia_ = float(best.inertia)
        self.n_iter_ = best.n_iter
        if collection.equal_length and collection.manifold.point_shape == (1,):
            self.n_features_in_ = collection.max_length
        return self

    def _centre_settings(self, collection):
        method = self.method.lower()
        params = dict(self.averager_params or {})
        unknown = sorted(set(params) - set(AVERAGER_PARAMS))
        if unknown:
            raise TypeError(
                f"averager_params has unknown engine setting(s) {unknown}; known: "
                f"{list(AVERAGER_PARAMS)}"
            )
        check_preset(self.preset)
        params.update(preset=self.preset, n_epochs=self.n_epochs, device=self.device)
        return centre_settings(
            method,
            engine=engine_keywords(params, output_length=self.output_length),
            dtw_window=self.dtw_window, n_jobs=self.n_jobs, verbose=self.verbose,
            owner="RTWKMeans",
        )  # fmt: skip

    # ------------------------------------------------------------ inference
    def transform(self, X: Any) -> np.ndarray:
        """Manifold-DTW distance of every series to every centre.

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
        return dtw_to_centres(collection, list(self.cluster_centers_), self._settings)

    def predict(self, X: Any) -> np.ndarray:
        """Index of the nearest centre.

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
