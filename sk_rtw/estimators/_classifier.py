"""Nearest-centroid classification by manifold DTW to time-warping class means."""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.special import softmax
from sklearn.base import ClassifierMixin
from sklearn.utils.validation import check_is_fitted

from ._averager import RTWAverager


class RTWNearestCentroid(ClassifierMixin, RTWAverager):
    """Nearest-centroid classifier: the class whose RTW mean is nearest by manifold DTW.

    ``fit`` learns one Riemannian Time Warping mean per class (as :class:`RTWAverager`);
    ``predict`` returns the class of the nearest mean (paper, section V-A).

    Parameters
    ----------
    manifold, output_length, n_epochs, learning_rate, sinc_window, loss_window, \
loss_step, penalty, n_components, hidden_size, warp_knots, tangent_refinements, \
mean_iterations, dtw_window, n_jobs, random_state, device, verbose
        As in :class:`RTWAverager`.

    Attributes
    ----------
    classes_ : ndarray of shape (n_classes,)
    means_ : ndarray of shape (n_classes, Z, *point_shape)
    alignments_ : list of Alignment
    manifold_ : Manifold

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

    def fit(self, X: Any, y: Any = None):
        """Learn one mean per class.

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
        return self._fit_means(X, y, require_two_classes=True)

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
        """Softmax of the negative DTW distances to the class means.

        Parameters
        ----------
        X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list
            Series on the training manifold; any length (a list for unequal lengths).

        Returns
        -------
        proba : ndarray of shape (n_series, n_classes)
        """
        return softmax(-self.transform(X), axis=1)

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
