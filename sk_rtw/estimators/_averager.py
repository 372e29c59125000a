"""Class-mean estimators: one Riemannian time-warping mean per class (or several)."""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np
from sklearn.base import BaseEstimator, TransformerMixin
from sklearn.utils.validation import check_is_fitted

from .._random import check_random_state
from .._settings import PRESETS
from ..dtw import dtw_pairwise_distance
from ..methods import FitContext, get_method
from ..representations import represent, represented_manifold
from ..utils import SeriesCollection, check_labels, check_series_collection, encode_labels
from ..utils._params import declare_parameters, validate_parameters
from ._choice import DEFAULT_CHOICE, AutoChoice, mcnemar
from ._core import _label
from ._params import (
    AVERAGER_DEFAULTS,
    AVERAGER_PARAMETERS,
    document_settings,
    set_params_with_hints,
    setting_hint,
)
from ._partition import partition
from ._record import CentroidFitRecord
from ._selection import choose

if TYPE_CHECKING:
    import torch

    from ..manifolds import Manifold
    from ..methods import AveragingMethod


@document_settings
@declare_parameters(AVERAGER_PARAMETERS, AVERAGER_DEFAULTS, hint=setting_hint)
class RTWAverager(TransformerMixin, BaseEstimator):
    """Learn one Riemannian Time Warping mean per class (or several); transform to DTW
    distances.

    ``fit`` averages the series of each class -- with the alignment engine of
    :func:`sk_rtw.align` (RTW, TTW, NTW; every class in one batched optimisation) or with
    manifold DTW barycenter averaging (``method="dba"``) -- and keeps the class means;
    ``transform`` returns the manifold-DTW distance of each series to each mean (like
    ``KMeans.transform``). With ``n_centroids=k`` every class is split into ``k`` parts
    (with a fraction, that share of its series) by k-medoids on the DTW matrix of its
    series and every part is averaged, and ``transform`` returns the distance to every
    centroid: features for a downstream classifier.

    What to set: ``manifold`` for your data; ``method`` and ``preset`` choose the
    averaging (the default, density-weighted RTW means of the median class length, is
    the one mean per class that classifies best on the UCR development archive;
    ``preset="paper"`` is the paper's configuration); ``n_centroids`` for classes of
    several shapes (``n_centroids="auto", dtw_window="auto"`` choose both from the
    training labels, as :class:`RTWNearestCentroid` does by default); the method's own
    settings go in its object, ``method=RTW(n_epochs=64)``.

    Parameters
    ----------
    %(parameters)s

    Attributes
    ----------
    classes_ : ndarray of shape (n_classes,)
        Class labels (``[0]`` when fitted without ``y``).
    means_ : ndarray of shape (n_means, Z, *point_shape) or list of ndarray
        Every centroid, on the manifold (one per class unless ``n_centroids > 1``); a list
        when they differ in length (DBA on series of unequal lengths).
    centroid_classes_ : ndarray of shape (n_means,)
        Class index (into ``classes_``) of every entry of ``means_``.
    alignments_ : list of Alignment or sk_rtw.baselines.MultipleAlignment
        Per entry of ``means_``: the method's result (mean, aligned series, warps, cost,
        iterations run, resolved ``config``; see :class:`sk_rtw.methods.AveragingResult`).
    assignments_ : ndarray of shape (n_series,)
        Entry of ``means_`` that every training series was averaged into
        (``alignments_[k].aligned`` holds the series with ``assignments_ == k``).
    method_ : str
        The averaging method used.
    manifold_ : Manifold
        The manifold resolved against the training data.
    dtw_window_ : float or None
        The Sakoe-Chiba band used in the fit and by ``transform`` (``dtw_window``, or
        the one chosen for ``"auto"``).
    n_centroids_ : int or float
        Centroids of every class: ``n_centroids``, or the value chosen for ``"auto"``
        (a count, or a fraction of every class; ``np.bincount(centroid_classes_)`` gives
        each class's number).
    selection_ : dict
        The training-data scores behind the ``"auto"`` choices (empty without them):
        ``"criterion"``, ``"prior"`` (the choice unless the data clearly prefer another),
        ``"candidates"`` (every candidate band and number of centroids with its
        leave-one-out accuracy and its advantage over the prior in standard errors,
        ``"z"``), ``"class_centroids"`` (the chosen number of every class),
        ``"n_series"`` and ``"sampled"`` (the series it was made on: a stratified sample
        of a large training set) and ``"seconds"`` (part of the fit).
    n_features_in_ : int
        Length of the training series when they all have the same length (a
        scikit-learn convention; series of any length are accepted by ``transform``).

    Notes
    -----
    %(method_settings)s

    Examples
    --------
    >>> import numpy as np
    >>> from sk_rtw import RTW, RTWAverager
    >>> t = np.linspace(0, 1, 40)
    >>> X = np.stack([np.sin(2 * np.pi * t ** p) for p in (0.8, 1.0, 1.2, 0.9)])
    >>> averager = RTWAverager(method=RTW(n_epochs=10), random_state=0).fit(X, [0, 0, 1, 1])
    >>> averager.means_.shape, averager.transform(X).shape
    ((2, 40, 1), (4, 2))
    >>> RTWAverager(method="dba").fit(X, [0, 0, 1, 1]).means_.shape
    (2, 40, 1)
    """

    def __init__(
        self,
        manifold: str | Manifold = "euclidean",
        *,
        method: str | AveragingMethod = "rtw",
        preset: str = "class-means",
        n_centroids: int | str = 1,
        dtw_window: float | str | None = None,
        representation: str = "raw",
        choice: AutoChoice | None = None,
        n_jobs: int | None = None,
        random_state: int | np.random.RandomState | np.random.Generator | None = None,
        device: str | torch.device = "cpu",
        verbose: bool | int = 0,
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

    def set_params(self, **params):
        """Set parameters, scikit-learn's way; ``method__<setting>`` also works when
        ``method`` is a name (it becomes the method's object), and a setting that is no
        parameter says where it belongs.

        Parameters
        ----------
        **params : dict
            Estimator parameters, and ``method__<setting>`` for the method's settings.

        Returns
        -------
        self
        """
        set_params_with_hints(self, params, super().set_params)
        return self

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

    def _fit_means(self, X, y, require_two_classes) -> CentroidFitRecord:
        """Validate every parameter, resolve the "auto" choices into the fit's record,
        fit the centroids from it and set the fitted attributes; returns the record
        (also kept as ``_fit_record``)."""
        record, collection = self._plan_fit(X, y, require_two_classes)
        fits = record.fit(collection)
        self._fit_record = record
        self.classes_ = record.classes
        self.method_ = record.method.label
        self.representation_ = record.representation
        self.dtw_window_ = record.dtw_window
        self.n_centroids_ = record.n_centroids
        self.selection_ = {} if record.selection is None else record.selection.report
        self.alignments_ = fits
        self.centroid_classes_ = np.array(record.owners)
        self.assignments_ = np.array(record.groups)
        means = [fit.mean for fit in fits]
        same_length = len({len(m) for m in means}) == 1
        self.means_ = np.stack(means) if same_length else means
        return record

    def _plan_fit(self, X, y, require_two_classes) -> tuple[CentroidFitRecord, SeriesCollection]:
        """Everything the fit resolves before any centroid is averaged: the record, and
        the training series in its representation."""
        params = validate_parameters(self)
        method = get_method(params["method"])
        choice = (DEFAULT_CHOICE if params["choice"] is None else params["choice"]).checked()
        context = FitContext(
            preset=params["preset"], device=params["device"], n_jobs=params["n_jobs"],
            verbose=int(params["verbose"]),
        )  # fmt: skip
        method.check_settings()  # every setting checked before any work
        collection = check_series_collection(X, self.manifold)
        self.manifold_ = collection.manifold
        if collection.equal_length and collection.manifold.point_shape == (1,):
            self.n_features_in_ = collection.max_length
        series = collection  # on the manifold, for a representation still to choose
        representation = params["representation"]
        if representation != "auto":
            collection = represent(collection, representation)
        if y is None:
            labels = np.zeros(collection.n_series, dtype=int)
        else:
            labels = check_labels(y, collection.n_series, require_two_classes)
        classes, codes = encode_labels(labels)
        if require_two_classes and len(classes) < 2:
            raise ValueError(
                f"{type(self).__name__} needs at least 2 classes in y; got {len(classes)} "
                f"class ({classes.tolist()})"
            )
        window, n_centroids = params["dtw_window"], params["n_centroids"]
        selection = None
        chooses = "auto" in (window, n_centroids) and PRESETS[params["preset"]].chooses
        if representation == "auto" and not chooses:  # nothing is chosen: the series
            representation = choice.representations[0]
            collection = represent(series, representation)
        if chooses and representation == "auto":
            representation, collection, selection = self._select_representation(
                series, codes, window, n_centroids, choice, params
            )
        elif chooses:
            selection = self._select(collection, codes, window, n_centroids, choice, params)
        if selection is not None:
            window, n_centroids = selection.dtw_window, selection.n_centroids
        elif "auto" in (window, n_centroids):  # the paper's protocol: one mean, no band
            window = None if window == "auto" else window
            n_centroids = 1 if n_centroids == "auto" else n_centroids
        context = replace(context, dtw_window=window)
        config = method.configure(context)  # resolved once, with the band chosen
        if isinstance(n_centroids, int) and n_centroids == 1:
            groups, owners = codes, np.arange(len(classes))
            names, kind = list(classes), "class"
        else:
            groups, owners = partition(
                collection, codes, n_centroids, window, selection=selection,
                random_state=self.random_state, n_jobs=params["n_jobs"],
            )  # fmt: skip
            rank = np.concatenate([np.arange(n) for n in np.bincount(owners)])
            names = [f"{_label(classes[c])}/{r + 1}" for c, r in zip(owners, rank, strict=True)]
            kind = "centroid"
        seeds = check_random_state(self.random_state).randint(2**31 - 1, size=len(owners))
        record = CentroidFitRecord.create(
            method=method, config=config, context=context, representation=representation,
            dtw_window=window, n_centroids=n_centroids, classes=classes, codes=codes,
            groups=groups, owners=owners, seeds=seeds, names=names, kind=kind,
            selection=selection, owner=type(self).__name__,
        )  # fmt: skip
        return record, collection

    def _select(self, collection, codes, window, n_centroids, choice, params):
        """Resolve ``dtw_window="auto"`` and ``n_centroids="auto"`` (see
        :mod:`sk_rtw.estimators._selection`)."""
        if len(np.unique(codes)) < 2:
            raise ValueError(
                '"auto" choices are made by classifying the training series: they need y '
                "with at least 2 classes (or set n_centroids and dtw_window)"
            )
        return choose(
            collection, codes, window, n_centroids, choice, random_state=self.random_state,
            n_jobs=params["n_jobs"], verbose=int(params["verbose"]), owner=type(self).__name__,
        )  # fmt: skip

    def _select_representation(self, series, codes, window, n_centroids, choice, params):
        """``representation="auto"``: the band and the centroids chosen on every
        representation of ``choice.representations``; another than the first only where
        its choice classifies the held-out series better than the first's by
        ``choice.z_threshold`` standard errors (McNemar, on the series both scored; the
        best such). Returns the representation, the collection in it and its selection
        (whose report says what the others scored)."""
        choices = {}
        for name in choice.representations:
            collection = represent(series, name)
            choices[name] = (collection, self._select(collection, codes, window, n_centroids,
                                                      choice, params))  # fmt: skip
        correct = {}
        for name, (_, selection) in choices.items():
            held_out = selection.held_out
            right = held_out.argmin(1) == codes[selection.sample]
            correct[name] = dict(zip(selection.sample.tolist(), right.tolist(), strict=True))
        first, *others = choice.representations
        chosen, report = first, {"chosen": first}
        best = -np.inf
        accuracy = {}
        for name in others:
            common = sorted(set(correct[first]) & set(correct[name]))
            prior = np.array([correct[first][i] for i in common], dtype=bool)
            candidate = np.array([correct[name][i] for i in common], dtype=bool)
            z = float(mcnemar(candidate, prior))
            accuracy[first], accuracy[name] = float(prior.mean()), float(candidate.mean())
            if choice.prefers(z) and z > best:
                chosen, best = name, z
            report.setdefault("z", z)
            report.setdefault("n_series", len(common))
        report["chosen"] = chosen
        if chosen != first:
            report["z"] = best
        report["accuracy"] = accuracy
        collection, selection = choices[chosen]
        selection.report["representation"] = report
        return chosen, collection, selection

    def _represented(self, X: Any) -> tuple[SeriesCollection, SeriesCollection]:
        """``X`` validated on the fitted manifold and the centroids, both in the fitted
        representation."""
        check_is_fitted(self, "means_")
        shortest = 2 if self.representation_ == "velocity" else 1
        collection = check_series_collection(X, self.manifold_, min_length=shortest)
        space = represented_manifold(self.manifold_, self.representation_)
        means = check_series_collection(self.means_, space, name="means_", min_length=1)
        return represent(collection, self.representation_), means

    def _centroid_distances(self, X: Any) -> np.ndarray:
        """Manifold-DTW distance of every series to every entry of ``means_``."""
        collection, means = self._represented(X)
        return dtw_pairwise_distance(collection, means, window=self.dtw_window_,
                                     n_jobs=self.n_jobs)  # fmt: skip

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
        return self._centroid_distances(X)

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.allow_nan = False
        tags.non_deterministic = False
        return tags


@document_settings
@declare_parameters(defaults={"method": "ttw"})
class TTWAverager(RTWAverager):
    """Class means by Riemannian Trainable Time Warping (sine-series warps).

    :class:`RTWAverager` with ``method="ttw"``: the same attributes and input shapes
    (``(n_series, n_timepoints[, *point_shape])`` or a list of series).

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
        n_centroids: int | str = 1,
        dtw_window: float | str | None = None,
        representation: str = "raw",
        choice: AutoChoice | None = None,
        n_jobs: int | None = None,
        random_state: int | np.random.RandomState | np.random.Generator | None = None,
        device: str | torch.device = "cpu",
        verbose: bool | int = 0,
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
        )


@document_settings
@declare_parameters(defaults={"method": "ntw"})
class NTWAverager(RTWAverager):
    """Class means by Riemannian Neural Time Warping (zero-initialised network, full sinc).

    :class:`RTWAverager` with ``method="ntw"``: the same attributes and input shapes
    (``(n_series, n_timepoints[, *point_shape])`` or a list of series).

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
        n_centroids: int | str = 1,
        dtw_window: float | str | None = None,
        representation: str = "raw",
        choice: AutoChoice | None = None,
        n_jobs: int | None = None,
        random_state: int | np.random.RandomState | np.random.Generator | None = None,
        device: str | torch.device = "cpu",
        verbose: bool | int = 0,
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
        )
