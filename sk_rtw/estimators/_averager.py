"""Class-mean estimators: one Riemannian time-warping mean per class (or several)."""

from __future__ import annotations

from typing import Any

import numpy as np
from sklearn.base import BaseEstimator, TransformerMixin
from sklearn.utils import check_random_state, column_or_1d
from sklearn.utils.multiclass import check_classification_targets
from sklearn.utils.validation import check_is_fitted

from .._numba import check_n_jobs
from .._random import check_random_state_value
from ..align._config import check_preset
from ..dtw import check_window, dtw_pairwise_distance
from ..manifolds import Manifold
from ..utils import check_series_collection
from ._core import ESTIMATOR_METHODS, centre_settings, engine_keywords, fit_centres, kmeans


class RTWAverager(TransformerMixin, BaseEstimator):
    """Learn one Riemannian Time Warping mean per class (or several); transform to DTW
    distances.

    ``fit`` averages the series of each class -- with the alignment engine of
    :func:`sk_rtw.align` (RTW, TTW, NTW; every class in one batched optimisation) or with
    manifold DTW barycenter averaging (``method="dba"``) -- and keeps the class means;
    ``transform`` returns the manifold-DTW distance of each series to each mean (like
    ``KMeans.transform``). With ``n_centroids=k`` every class is clustered into ``k``
    centroids by k-means with the same averaging, and ``transform`` returns the distance
    to every centroid: features for a downstream classifier.

    Parameters
    ----------
    manifold : str or Manifold, default="euclidean"
        Space of the samples; a name takes its dimension from the data.
    method : {"rtw", "ttw", "ntw", "dba"} or None, default=None
        Averaging method; None is the estimator's own (RTW here; TTW for
        :class:`TTWAverager`, ...). ``"dba"``: DTW barycenter averaging with Fréchet means
        (:func:`sk_rtw.baselines.dba_average`, squared costs, medoid start), on any
        manifold. Searchable with ``GridSearchCV`` like any parameter.
    preset : {"class-means", "alignment", "paper", "default"} or None, default=None
        Engine preset (see :func:`sk_rtw.align`). None or ``"default"``:
        ``"class-means"``, density-weighted RTW means on the time axis of the DTW
        reference (what classifies best on the UCR development archive);
        ``"alignment"``: :func:`sk_rtw.align`'s defaults; ``"paper"``: the paper's exact
        configuration (means of length ``N T_max``, warps starting at the identity).
    output_length : int, optional
        Length ``Z`` of the means. Default: the median length of each class's training
        series (:func:`sk_rtw.align.classification_output_length`): means longer than
        the series they are compared with classify worse; the paper preset uses ``N
        T_max`` per class. Not used by DBA, whose means keep the length of their start
        (the class medoid).
    n_epochs : int, default=256
        Most Adam epochs per class.
    learning_rate : float, default=0.01
    sinc_window, loss_window, loss_step, penalty : optional
        Engine settings; None takes the method's default (see :func:`sk_rtw.align`).
    warp_start : {"auto", "identity", "dtw"}, default="auto"
        Starting warps (``"auto"``: the preset's; RTW starts from DTW paths by default).
    n_components : int, default=8
        Sine terms of the TTW warps (TTW only).
    hidden_size : int or "auto", default="auto"
        Hidden width of the RTW/NTW warp network (``"auto"``: the preset's, 64; the paper's
        512 with ``preset="paper"``).
    warp_knots : int, None or "auto", default="auto"
        Times at which the warp network is evaluated (linear in between); None: at every
        output time (the paper); ``"auto"``: the preset's (64, or None for the paper).
    tangent_refinements : int or "auto", default="auto"
        Gauss–Newton refinements of the interpolation tangent point (``"auto"``: the
        preset's, 0 or 2 for the paper).
    mean_iterations : int or "auto", default="auto"
        Gauss–Newton iterations of the mean per epoch (``"auto"``: the preset's).
    mean_weights : {"auto", "density", "equal"}, default="auto"
        How the aligned series enter the class mean: ``"density"`` weighs every series by
        the samples each output time covers (DBA's counting, for continuous warps; the
        RTW default of the ``"class-means"`` preset), ``"equal"`` is the paper's mean.
        Searchable with ``GridSearchCV``.
    n_iter_no_change : int, None or "auto", default="auto"
        Stop a class's training after this many epochs without a relative improvement of
        ``tol`` (None: all ``n_epochs``; ``"auto"``: the preset's).
    tol : float, optional
        Relative improvement that counts for ``n_iter_no_change`` (the preset's: 1e-3).
    n_centroids : int, default=1
        Centroids per class. Above 1, each class is clustered by k-means (the estimator's
        averaging method, k-means++ seeding, at most 10 rounds; at most one centroid per
        series), and ``means_`` holds every centroid.
    dtw_window : float in [0, 1], optional
        Sakoe–Chiba band of the DTW used by ``transform`` (and by DBA).
    n_jobs : int, optional
        Threads of the fit (scikit-learn's convention, None: 1) and of the DTW
        computations; DBA fits classes in parallel with joblib.
    random_state : int, RandomState or None
        Seeds the warp initialisation of every class.
    device : str, default="cpu"
        Torch device of the optimisation (e.g. ``"cuda"``); fitted attributes are numpy.
    verbose : int, default=0
        1: one line per class; 2: also the loss during training.

    Attributes
    ----------
    classes_ : ndarray of shape (n_classes,)
        Class labels (``[0]`` when fitted without ``y``).
    means_ : ndarray of shape (n_means, Z, *point_shape) or list of ndarray
        Every centroid, on the manifold (one per class unless ``n_centroids > 1``); a list
        when they differ in length (DBA on series of unequal lengths).
    centroid_classes_ : ndarray of shape (n_means,)
        Class index (into ``classes_``) of every entry of ``means_``.
    alignments_ : list of Alignment or MultipleAlignment
        Per entry of ``means_``: aligned series, warps and, for the engine's methods, loss
        history and configuration.
    assignments_ : ndarray of shape (n_series,)
        Entry of ``means_`` that every training series was averaged into.
    method_ : str
        The averaging method used.
    manifold_ : Manifold
        The manifold resolved against the training data.
    n_features_in_ : int
        Length of the training series when they all have the same length (a
        scikit-learn convention; series of any length are accepted by ``transform``).

    Examples
    --------
    >>> import numpy as np
    >>> from sk_rtw import RTWAverager
    >>> t = np.linspace(0, 1, 40)
    >>> X = np.stack([np.sin(2 * np.pi * t ** p) for p in (0.8, 1.0, 1.2, 0.9)])
    >>> averager = RTWAverager(n_epochs=10, random_state=0).fit(X, [0, 0, 1, 1])
    >>> averager.means_.shape, averager.transform(X).shape
    ((2, 40, 1), (4, 2))
    >>> RTWAverager(method="dba").fit(X, [0, 0, 1, 1]).means_.shape
    (2, 40, 1)
    """

    _method = "rtw"

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
    ):
        self.manifold = manifold
        self.method = method
        self.preset = preset
        self.output_length = output_length
        self.n_epochs = n_epochs
        self.learning_rate = learning_rate
        self.sinc_window = sinc_window
        self.loss_window = loss_window
        self.loss_step = loss_step
        self.penalty = penalty
        self.warp_start = warp_start
        self.n_components = n_components
        self.hidden_size = hidden_size
        self.warp_knots = warp_knots
        self.tangent_refinements = tangent_refinements
        self.mean_iterations = mean_iterations
        self.mean_weights = mean_weights
        self.n_iter_no_change = n_iter_no_change
        self.tol = tol
        self.n_centroids = n_centroids
        self.dtw_window = dtw_window
        self.n_jobs = n_jobs
        self.random_state = random_state
        self.device = device
        self.verbose = verbose

    # ------------------------------------------------------------------ fit
    def fit(self, X: Any, y: Any = None):
        """Average the series of each class and store the class means.

        Parameters
        ----------
        X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list
            Training series (see the input-shapes table in the user guide).
        y : array-like of shape (n_series,), optional
            Class labels; without ``y`` all series form one class.

        Returns
        -------
        self
        """
        self._fit_means(X, y, require_two_classes=False)
        return self

    def _resolve_method(self) -> str:
        method = self._method if self.method is None else self.method
        if not isinstance(method, str) or method.lower() not in ESTIMATOR_METHODS:
            raise ValueError(
                f"method must be one of {ESTIMATOR_METHODS} or None, got {self.method!r}"
            )
        return method.lower()

    def _check_n_centroids(self) -> int:
        k = self.n_centroids
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 1:
            raise ValueError(f"n_centroids must be an integer >= 1, got {k!r}")
        return int(k)

    def _fit_means(self, X, y, require_two_classes):
        """Validate, then fit ``n_centroids`` means per class (k-means above 1)."""
        method = self._resolve_method()
        n_centroids = self._check_n_centroids()
        check_preset(self.preset)
        check_random_state_value(self.random_state)
        check_n_jobs(self.n_jobs)
        check_window(self.dtw_window, name="dtw_window")  # in fit, not only at predict
        collection = check_series_collection(X, self.manifold)
        if y is None:
            labels = np.zeros(collection.n_series, dtype=int)
        else:
            labels = _check_labels(y, collection.n_series, require_two_classes)
        classes, codes = _encode(labels)
        if require_two_classes and len(classes) < 2:
            raise ValueError(
                f"{type(self).__name__} needs at least 2 classes in y; got {len(classes)} "
                f"class ({classes.tolist()})"
            )
        sizes = np.bincount(codes)
        settings = centre_settings(
            method,
            engine=engine_keywords(self.get_params(), output_length=self.output_length),
            dtw_window=self.dtw_window, n_jobs=self.n_jobs, verbose=self.verbose,
            owner=type(self).__name__,
        )  # fmt: skip
        seeds = check_random_state(self.random_state).randint(2**31 - 1, size=len(classes))
        if n_centroids == 1:
            fits = fit_centres(collection, codes, [int(s) for s in seeds], settings,
                              list(classes), kind="class")  # fmt: skip
            centroid_classes = np.arange(len(classes))
            assignments = codes
        else:
            rngs = [np.random.RandomState(int(s)) for s in seeds]
            clusterings = kmeans(collection, codes, [min(n_centroids, int(n)) for n in sizes],
                                 settings, rngs)  # fmt: skip
            fits = [fit for clustering in clusterings for fit in clustering.fits]
            counts = [len(clustering.fits) for clustering in clusterings]
            centroid_classes = np.repeat(np.arange(len(classes)), counts)
            offsets = np.concatenate([[0], np.cumsum(counts)[:-1]])
            assignments = np.empty(collection.n_series, dtype=np.int64)
            for c, clustering in enumerate(clusterings):
                assignments[codes == c] = offsets[c] + clustering.labels
        self.classes_ = classes
        self.method_ = method
        self.manifold_ = collection.manifold
        self.alignments_ = fits
        self.centroid_classes_ = centroid_classes
        self.assignments_ = assignments
        means = [fit.mean for fit in fits]
        same_length = len({len(m) for m in means}) == 1
        self.means_ = np.stack(means) if same_length else means
        if collection.equal_length and collection.manifold.point_shape == (1,):
            self.n_features_in_ = collection.max_length
        return self

    # ------------------------------------------------------------ transform
    def transform(self, X: Any) -> np.ndarray:
        """Manifold-DTW distance of every series to every mean (every centroid).

        Parameters
        ----------
        X : array-like or list of series
            Series of any length on the training manifold.

        Returns
        -------
        distances : ndarray of shape (n_series, n_means)
            One column per entry of ``means_`` (``n_classes`` columns, or
            ``n_centroids x n_classes`` with ``n_centroids > 1``; ``centroid_classes_``
            gives the class of each column).
        """
        check_is_fitted(self, "means_")
        collection = check_series_collection(X, self.manifold_, min_length=1)
        means = check_series_collection(self.means_, self.manifold_, name="means_")
        return dtw_pairwise_distance(collection, means, window=self.dtw_window, n_jobs=self.n_jobs)

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.allow_nan = False
        tags.non_deterministic = False
        return tags


class TTWAverager(RTWAverager):
    """Class means by Riemannian Trainable Time Warping (sine-series warps).

    Same parameters, attributes and input shapes (``(n_series, n_timepoints[,
    *point_shape])`` or a list of series) as :class:`RTWAverager`; engine defaults of
    ``"ttw"``.
    """

    _method = "ttw"


class NTWAverager(RTWAverager):
    """Class means by Riemannian Neural Time Warping (zero-initialised network, full sinc).

    Same parameters, attributes and input shapes (``(n_series, n_timepoints[,
    *point_shape])`` or a list of series) as :class:`RTWAverager`; engine defaults of
    ``"ntw"``.
    """

    _method = "ntw"


def _check_labels(y: Any, n_series: int, classification: bool) -> np.ndarray:
    if isinstance(y, (list, tuple)) and len({isinstance(v, str) for v in y}) > 1:
        y = np.array(y, dtype=object)  # keep mixed str/number labels as they are
    labels = column_or_1d(y, warn=True)
    if len(labels) != n_series:
        raise ValueError(f"X has {n_series} series but y has {len(labels)} labels")
    if labels.dtype == object:
        for i, value in enumerate(labels.tolist()):
            if value is None or (isinstance(value, float) and np.isnan(value)):
                raise ValueError(f"y[{i}] is {value!r}: labels must not be missing (None or NaN)")
    mixed = labels.dtype == object and len({type(v) for v in labels.tolist()}) > 1
    if classification and not mixed:  # scikit-learn cannot sort mixed str/int labels
        check_classification_targets(labels)
    elif labels.dtype.kind == "f" and np.isnan(labels).any():
        first = int(np.argmax(np.isnan(labels)))
        raise ValueError(f"y[{first}] is NaN: labels must not be missing")
    return labels


def _encode(labels: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sorted classes and integer codes; mixed label types are sorted by type, then value."""
    try:
        classes, codes = np.unique(labels, return_inverse=True)
        return classes, codes.ravel()
    except TypeError:
        ordered = sorted(set(labels.tolist()), key=lambda v: (type(v).__name__, v))
        classes = np.empty(len(ordered), dtype=object)
        classes[:] = ordered
        lookup = {v: i for i, v in enumerate(ordered)}
        return classes, np.array([lookup[v] for v in labels.tolist()])
