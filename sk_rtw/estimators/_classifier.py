"""Nearest-centroid classification by manifold DTW to time-warping class means."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy.optimize import minimize_scalar
from scipy.special import log_softmax, softmax
from sklearn.base import ClassifierMixin
from sklearn.utils.validation import check_is_fitted

from ..dtw import dtw_nearest_distance
from ..utils._params import declare_parameters
from ._averager import RTWAverager
from ._params import (
    AVERAGER_DEFAULTS,
    AVERAGER_PARAMETERS,
    TEMPERATURE,
    document_settings,
    setting_hint,
)

if TYPE_CHECKING:
    import torch

    from ..manifolds import Manifold
    from ..methods import AveragingMethod
    from ._choice import AutoChoice


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


@document_settings
@declare_parameters(
    (*AVERAGER_PARAMETERS, TEMPERATURE),
    {**AVERAGER_DEFAULTS, "n_centroids": "auto", "dtw_window": "auto", "temperature": "fit"},
    hint=setting_hint,
    notes={
        "n_centroids": "A series gets the class of its nearest centroid (Petitjean et al., "
        "ICDM 2014: a few DBA centroids per class approach 1-NN DTW at a fraction of its "
        "cost).",
    },
)
class RTWNearestCentroid(ClassifierMixin, RTWAverager):
    """Nearest-centroid classifier: the class whose RTW mean is nearest by manifold DTW.

    ``fit`` learns Riemannian Time Warping centroids of every class (as
    :class:`RTWAverager`); ``predict`` returns the class of the nearest centroid by
    manifold DTW (paper, section V-A, with several centroids per class).

    What to set: ``manifold`` for your data, nothing else to start with. By default
    (``n_centroids="auto", dtw_window="auto"``) ``fit`` chooses the Sakoe-Chiba band and
    the centroids of every class from the training data: every candidate of ``choice``
    (:class:`~sk_rtw.AutoChoice`) is scored by leave-one-out nearest-medoid
    classification of the training series, and its prior is kept unless the held-out
    series clearly prefer another candidate (``selection_``).

    %(choice)s

    Each class is then split by k-medoids and every part averaged once, so large classes
    get many centroids and small ones few; prediction finds the nearest centroid with
    lower bounds and early abandoning (the exhaustive search's answer at a fraction of
    its cost). The UCR benchmark page of the documentation gives the accuracy, fit and
    prediction times measured against 1-NN DTW. One mean per class, as in the paper's
    Table II: ``n_centroids=1, dtw_window=None``; ``preset="paper"`` for the paper's
    exact protocol; ``method="dba"`` for the fastest fit; ``n_centroids=1.0`` for 1-NN
    DTW within the band. Splitting a class into centroids needs the DTW matrix of its
    series, which without a band grows with the square of the class size and of the
    length (the classification guide gives measured times): where classes hold hundreds
    of long series, fix the band or take one mean per class. The method's own settings
    go in its object: ``method=RTW(n_epochs=64)``, searchable as ``method__n_epochs``.

    Parameters
    ----------
    %(parameters)s

    Attributes
    ----------
    classes_ : ndarray of shape (n_classes,)
    means_ : ndarray of shape (n_means, Z, *point_shape) or list of ndarray
        Every centroid, class after class (``n_centroids_`` of every class); a centroid
        of one training series is that series.
    centroid_classes_ : ndarray of shape (n_means,)
        Class index of every entry of ``means_``: the class of every column of
        :meth:`transform` (one per centroid, as ``RTWAverager.transform``);
        :meth:`class_distances` gives one column per class, the nearest centroid's.
    alignments_ : list of Alignment, sk_rtw.baselines.MultipleAlignment or SeriesCentroid
        One per entry of ``means_``: the method's result (a ``SeriesCentroid`` for a
        centroid of one series, which was not averaged).
    assignments_ : ndarray of shape (n_series,)
        Entry of ``means_`` each training series was averaged into.
    method_ : str
        The averaging method used.
    manifold_ : Manifold
        The manifold resolved against the training data.
    dtw_window_ : float or None
        The Sakoe-Chiba band of the fit and of prediction (chosen for ``"auto"``).
    n_centroids_ : int or float
        Centroids of every class: a count, or a fraction of every class (chosen for
        ``"auto"``); ``np.bincount(centroid_classes_)`` gives each class's number.
    selection_ : dict
        The training-data scores behind the ``"auto"`` choices (empty without them):
        ``"criterion"``, ``"prior"`` (the choice unless the data clearly prefer another),
        ``"candidates"`` (every candidate band and number of centroids with its
        leave-one-out accuracy and its advantage over the prior in standard errors,
        ``"z"``), ``"class_centroids"`` (the chosen number of every class),
        ``"n_series"`` and ``"sampled"`` (the series it was made on: a stratified sample
        of a large training set) and ``"seconds"`` (part of the fit).
    temperature_ : float
        The temperature used by :meth:`predict_proba`, fitted on the choice's held-out
        distances (on the training distances when nothing was chosen).

    Notes
    -----
    %(method_settings)s

    Examples
    --------
    >>> import numpy as np
    >>> from sk_rtw import RTW, RTWNearestCentroid
    >>> t = np.linspace(0, 1, 40)
    >>> X = np.stack([np.sin(2 * np.pi * t ** p) for p in (0.8, 1.2)]
    ...              + [np.cos(2 * np.pi * t ** p) for p in (0.8, 1.2)])
    >>> clf = RTWNearestCentroid(method=RTW(n_epochs=10), random_state=0)
    >>> clf.fit(X, ["sin"] * 2 + ["cos"] * 2).predict(X).tolist()
    ['sin', 'sin', 'cos', 'cos']
    """

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
        n_jobs: int | None = None,
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

    def fit(self, X: Any, y: Any = None):
        """Choose the band and the centroids, learn the centroids of every class (and the
        probability temperature).

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
        selection = self._fit_means(X, y, require_two_classes=True).selection
        if not isinstance(self.temperature, str):  # "fit" was checked with the others
            self.temperature_ = float(self.temperature)
            return self
        finite = None if selection is None else np.isfinite(selection.held_out).all(1)
        if selection is not None and finite is not None and finite.sum() >= 2:
            # the choice's leave-one-out distances: a centroid that is a training series
            # is at distance 0 from it, which would make the fitted temperature collapse
            codes = self._fit_record.codes[selection.sample]
            self.temperature_ = fit_temperature(selection.held_out[finite], codes[finite])
        else:
            distances = self.class_distances(X)
            self.temperature_ = fit_temperature(distances, self._fit_record.codes)
        return self

    def class_distances(self, X: Any) -> np.ndarray:
        """Manifold-DTW distance of every series to every class: to its nearest centroid.

        Parameters
        ----------
        X : array-like or list of series
            Series of any length on the training manifold.

        Returns
        -------
        distances : ndarray of shape (n_series, n_classes)
            Column ``k`` is the class ``classes_[k]``; with one centroid per class it equals
            :meth:`transform` (which gives one column per centroid, as
            ``RTWAverager.transform``). The nearest centroid of every class is found with
            lower bounds and early abandoning (:func:`~sk_rtw.dtw.dtw_nearest_distance`):
            the values of the exhaustive search, at a fraction of its cost when the
            centroids are many.
        """
        return self._nearest_centroids(X, nearest_only=False)

    def _nearest_centroids(self, X: Any, nearest_only: bool) -> np.ndarray:
        """:meth:`class_distances`, or only the nearest class's (``inf`` elsewhere)."""
        collection, means = self._represented(X)
        return dtw_nearest_distance(
            collection, means, self.centroid_classes_, window=self.dtw_window_,
            nearest_only=nearest_only, n_jobs=self.n_jobs,
        )  # fmt: skip

    def predict(self, X: Any) -> np.ndarray:
        """Label of the nearest class mean.

        Parameters
        ----------
        X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list
            Series on the training manifold; any length (a list for unequal lengths).

        Returns
        -------
        labels : ndarray of shape (n_series,)
            The class of the nearest centroid (found without computing the distances to
            the other classes' nearest centroids: the argmin of :meth:`class_distances`,
            ties to the first class).
        """
        distances = self._nearest_centroids(X, nearest_only=True)
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
        distances = self.class_distances(X)
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
        distances = self.class_distances(X)
        if len(self.classes_) == 2:
            return distances[:, 0] - distances[:, 1]
        return -distances


@document_settings
@declare_parameters(defaults={"method": "ttw"})
class TTWNearestCentroid(RTWNearestCentroid):
    """Nearest-centroid classifier on Riemannian TTW class means.

    :class:`RTWNearestCentroid` with ``method="ttw"``: the same attributes and input
    shapes (``(n_series, n_timepoints[, *point_shape])`` or a list of series).

    Parameters
    ----------
    %(parameters)s

    Notes
    -----
    %(method_settings)s
    """

    def __init__(
        self,
        manifold: str | Manifold = "euclidean",
        *,
        method: str | AveragingMethod = "ttw",
        preset: str = "class-means",
        n_centroids: int | str = "auto",
        dtw_window: float | str | None = "auto",
        representation: str = "raw",
        choice: AutoChoice | None = None,
        n_jobs: int | None = None,
        random_state: int | np.random.RandomState | np.random.Generator | None = None,
        device: str | torch.device = "cpu",
        verbose: bool | int = 0,
        temperature: float | str = "fit",
    ) -> None:
        super().__init__(
            manifold,
            method=method,
            preset=preset,
            n_centroids=n_centroids,
            dtw_window=dtw_window,
            representation=representation,
            choice=choice,
            n_jobs=n_jobs,
            random_state=random_state,
            device=device,
            verbose=verbose,
            temperature=temperature,
        )


@document_settings
@declare_parameters(defaults={"method": "ntw"})
class NTWNearestCentroid(RTWNearestCentroid):
    """Nearest-centroid classifier on Riemannian NTW class means.

    :class:`RTWNearestCentroid` with ``method="ntw"``: the same attributes and input
    shapes (``(n_series, n_timepoints[, *point_shape])`` or a list of series).

    Parameters
    ----------
    %(parameters)s

    Notes
    -----
    %(method_settings)s
    """

    def __init__(
        self,
        manifold: str | Manifold = "euclidean",
        *,
        method: str | AveragingMethod = "ntw",
        preset: str = "class-means",
        n_centroids: int | str = "auto",
        dtw_window: float | str | None = "auto",
        representation: str = "raw",
        choice: AutoChoice | None = None,
        n_jobs: int | None = None,
        random_state: int | np.random.RandomState | np.random.Generator | None = None,
        device: str | torch.device = "cpu",
        verbose: bool | int = 0,
        temperature: float | str = "fit",
    ) -> None:
        super().__init__(
            manifold,
            method=method,
            preset=preset,
            n_centroids=n_centroids,
            dtw_window=dtw_window,
            representation=representation,
            choice=choice,
            n_jobs=n_jobs,
            random_state=random_state,
            device=device,
            verbose=verbose,
            temperature=temperature,
        )
