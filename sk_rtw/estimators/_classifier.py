"""Nearest-centroid classification by manifold DTW to time-warping class means."""

from __future__ import annotations

import inspect
import math
from typing import Any

import numpy as np
from scipy.optimize import minimize_scalar
from scipy.special import log_softmax, softmax
from sklearn.base import ClassifierMixin
from sklearn.utils.validation import check_is_fitted

from ..align._config import check_positive
from ..manifolds import Manifold
from ._averager import RTWAverager, _check_labels, _encode


def fit_temperature(distances: np.ndarray, labels: np.ndarray) -> float:
    """The temperature ``tau`` minimising the log-loss of ``softmax(-distances / tau)``.

    Parameters
    ----------
    distances : ndarray of shape (n_series, n_classes)
        DTW distances of labelled series to the class means.
    labels : ndarray of shape (n_series,), int
        Column of each series' class.

    Returns
    -------
    tau : float
        Searched in log space over 8 e-folds either side of the median distance of a
        series to its own class mean (a bounded 1-D problem; Platt scaling's analogue with
        one parameter). 1.0 when every distance is zero.
    """
    own = distances[np.arange(len(labels)), labels]
    scale = float(np.median(own))
    if not np.isfinite(scale) or scale <= 0:
        scale = float(np.median(distances))
    if not np.isfinite(scale) or scale <= 0:
        return 1.0

    def loss(log_tau: float) -> float:
        logp = log_softmax(-distances / math.exp(log_tau), axis=1)
        return -float(logp[np.arange(len(labels)), labels].mean())

    centre = math.log(scale)
    best = minimize_scalar(loss, bounds=(centre - 8.0, centre + 8.0), method="bounded")
    return math.exp(best.x)


class RTWNearestCentroid(ClassifierMixin, RTWAverager):
    """Nearest-centroid classifier: the class whose RTW mean is nearest by manifold DTW.

    ``fit`` learns one Riemannian Time Warping mean per class (as :class:`RTWAverager`);
    ``predict`` returns the class of the nearest mean (paper, section V-A).

    Parameters
    ----------
    manifold, method, preset, output_length, n_epochs, learning_rate, sinc_window, \
loss_window, loss_step, penalty, warp_start, n_components, hidden_size, warp_knots, \
tangent_refinements, mean_iterations, mean_weights, n_iter_no_change, tol, dtw_window, \
n_jobs, random_state, device, verbose
        As in :class:`RTWAverager`.
    n_centroids : int, default=1
        Centroids per class, as in :class:`RTWAverager` (k-means within each class); a
        series gets the class of its nearest centroid (Petitjean et al., ICDM 2014: a few
        DBA centroids per class approach 1-NN DTW at a fraction of its cost).
    temperature : float or "auto", default="auto"
        Scale of the distances in :meth:`predict_proba`,
        ``softmax(-d(x, mean_k) / temperature)``. ``"auto"`` fits it in ``fit`` by
        minimising the log-loss of the training series (one DTW per training series and
        class): raw DTW distances are in the data's units, so a fixed scale either
        saturates to 0/1 rows or flattens to uniform ones. Predictions do not depend on it.

    Attributes
    ----------
    classes_ : ndarray of shape (n_classes,)
    means_ : ndarray of shape (n_means, Z, *point_shape)
        Every centroid (one per class unless ``n_centroids > 1``).
    centroid_classes_ : ndarray of shape (n_means,)
        Class index of every entry of ``means_``; :meth:`transform` returns, per class,
        the distance to its nearest centroid (``RTWAverager.transform`` gives every
        centroid's).
    alignments_ : list of Alignment or MultipleAlignment
        One per entry of ``means_``.
    assignments_ : ndarray of shape (n_series,)
        Entry of ``means_`` each training series was averaged into.
    manifold_ : Manifold
    temperature_ : float
        The temperature used by :meth:`predict_proba`.

    Examples
    --------
    >>> import numpy as np
    >>> from sk_rtw import RTWNearestCentroid
    >>> t = np.linspace(0, 1, 40)
    >>> X = np.stack([np.sin(2 * np.pi * t ** p) for p in (0.8, 1.2)]
    ...              + [np.cos(2 * np.pi * t ** p) for p in (0.8, 1.2)])
    >>> clf = RTWNearestCentroid(n_epochs=10, random_state=0).fit(X, ["sin"] * 2 + ["cos"] * 2)
    >>> clf.predict(X).tolist()
    ['sin', 'sin', 'cos', 'cos']
    """

    def __init__(
        self,
        manifold: str | Manifold = "euclidean",
        method: str | None = None,
        preset: str | None = None,
        output_length: int | None = None,
        n_epochs: int = 256,
        learning_rate: float = 0.01,
        sinc_window: int | str | None = None,
        loss_window: int | None = None,
        loss_step: int | None = None,
        penalty: float | None = None,
        warp_start: str = "auto",
        n_components: int = 8,
        hidden_size: int | str = "auto",
        warp_knots: int | str | None = "auto",
        tangent_refinements: int | str = "auto",
        mean_iterations: int | str = "auto",
        mean_weights: str = "auto",
        n_iter_no_change: int | str | None = "auto",
        tol: float | None = None,
        n_centroids: int = 1,
        dtw_window: float | None = None,
        n_jobs: int | None = None,
        random_state: Any = None,
        device: str = "cpu",
        verbose: int = 0,
        temperature: float | str = "auto",
    ):
        averager = inspect.signature(RTWAverager.__init__).parameters
        values = locals()
        super().__init__(**{name: values[name] for name in averager if name != "self"})
        self.temperature = temperature

    def _check_temperature(self) -> None:
        if not (isinstance(self.temperature, str) and self.temperature == "auto"):
            check_positive('temperature (a positive number or "auto")', self.temperature)

    def fit(self, X: Any, y: Any = None):
        """Learn one mean per class (and the probability temperature).

        Parameters
        ----------
        X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list
            Training series (a list of ``(T_i, *point_shape)`` arrays for unequal lengths).
        y : array-like of shape (n_series,)
            Labels of at least two classes (strings, integers or a mix).

        Returns
        -------
        self
        """
        if y is None:
            raise ValueError(
                f"{type(self).__name__} requires y to be passed, but the target y is None"
            )
        self._check_temperature()
        self._fit_means(X, y, require_two_classes=True)
        if self.temperature == "auto":
            distances = self.transform(X)
            _, codes = _encode(_check_labels(y, len(distances), True))
            self.temperature_ = fit_temperature(distances, codes)
        else:
            self.temperature_ = float(self.temperature)
        return self

    def transform(self, X: Any) -> np.ndarray:
        """Manifold-DTW distance of every series to every class (its nearest centroid).

        Parameters
        ----------
        X : array-like or list of series
            Series of any length on the training manifold.

        Returns
        -------
        distances : ndarray of shape (n_series, n_classes)
        """
        distances = super().transform(X)
        owners = self.centroid_classes_
        if len(owners) == len(self.classes_):
            return distances
        out = np.full((len(distances), len(self.classes_)), np.inf)
        np.minimum.at(out.T, owners, distances.T)
        return out

    def predict(self, X: Any) -> np.ndarray:
        """Label of the nearest class mean.

        Parameters
        ----------
        X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list
            Series on the training manifold; any length (a list for unequal lengths).

        Returns
        -------
        labels : ndarray of shape (n_series,)
        """
        distances = self.transform(X)
        return self.classes_[np.argmin(distances, axis=1)]

    def predict_proba(self, X: Any) -> np.ndarray:
        """Softmax of the negative DTW distances to the class means over ``temperature_``.

        Parameters
        ----------
        X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list
            Series on the training manifold; any length (a list for unequal lengths).

        Returns
        -------
        proba : ndarray of shape (n_series, n_classes)
        """
        distances = self.transform(X)
        return softmax(-distances / self.temperature_, axis=1)

    def decision_function(self, X: Any) -> np.ndarray:
        """Confidence scores: negative DTW distances to the class means.

        Parameters
        ----------
        X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list
            Series on the training manifold; any length (a list for unequal lengths).

        Returns
        -------
        scores : ndarray of shape (n_series, n_classes) or (n_series,)
            For two classes the 1-D score ``d(x, mean_0) - d(x, mean_1)``, positive
            towards ``classes_[1]``.
        """
        check_is_fitted(self, "means_")
        distances = self.transform(X)
        if len(self.classes_) == 2:
            return distances[:, 0] - distances[:, 1]
        return -distances


class TTWNearestCentroid(RTWNearestCentroid):
    """Nearest-centroid classifier on Riemannian TTW class means.

    Same parameters, attributes and input shapes (``(n_series, n_timepoints[,
    *point_shape])`` or a list of series) as :class:`RTWNearestCentroid`; engine defaults
    of ``"ttw"``.
    """

    _method = "ttw"


class NTWNearestCentroid(RTWNearestCentroid):
    """Nearest-centroid classifier on Riemannian NTW class means.

    Same parameters, attributes and input shapes (``(n_series, n_timepoints[,
    *point_shape])`` or a list of series) as :class:`RTWNearestCentroid`; engine defaults
    of ``"ntw"``.
    """

    _method = "ntw"
