"""Prototype classification: a linear readout over the manifold-DTW distances to every centroid."""

from __future__ import annotations

import warnings
from numbers import Integral
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy.special import softmax
from sklearn.base import BaseEstimator, ClassifierMixin, TransformerMixin, clone
from sklearn.pipeline import Pipeline, make_pipeline
from sklearn.preprocessing import StandardScaler
from sklearn.utils.metaestimators import available_if
from sklearn.utils.validation import check_is_fitted

from .._random import check_random_state
from ..utils._common_params import CLASSIFIER
from ..utils._constraints import Constant, Interval, Options
from ..utils._params import Parameter, declare_parameters, validate_parameters
from ._choice import DEFAULT_CHOICE, mcnemar
from ._classifier import RTWNearestCentroid, fit_temperature
from ._out_of_fold import fold_count, out_of_fold_distances
from ._params import (
    AVERAGER_DEFAULTS,
    AVERAGER_PARAMETERS,
    document_settings,
    set_params_with_hints,
    setting_hint,
)
from ._readout_cv import cross_validated_predictions
from ._ridge_readout import RidgeGCVClassifier

if TYPE_CHECKING:
    import torch

    from ..manifolds import Manifold
    from ..methods import AveragingMethod
    from ._choice import AutoChoice


READOUT = Parameter(
    "readout",
    (
        Constant(None, "the default readout"),
        CLASSIFIER,
    ),
    "Classifier fitted on the features log(1 + d / s) of the out-of-fold distances d to "
    "every centroid (s: their median, ``distance_scale_``); cloned in fit. None: "
    "StandardScaler then sk_rtw.estimators.RidgeGCVClassifier (alphas 1e-3..1e3: "
    "RidgeClassifierCV's fit, by scikit-learn's faster SVD mode where the series "
    "outnumber the centroids), a linear readout (``readout_weights_``).",
)
DECISION = Parameter(
    "decision",
    (Options(("auto", "readout", "nearest")),),
    '"readout": the readout classifies. "nearest": the nearest centroid does (the readout '
    'is still fitted, for its weights). "auto": the readout where, cross-validated on the '
    "out-of-fold distances, it classifies the training series better than their nearest "
    "out-of-fold centroid by at least one standard error of the paired difference "
    "(McNemar, the rule of the centroids' choice); the nearest centroid otherwise. The "
    "default readout is cross-validated by its exact leave-one-out predictions (closed "
    "form, no refit), any other readout by refits on the folds of the out-of-fold "
    "distances.",
)
CV = Parameter(
    "cv",
    (Interval(int, 2),),
    "Stratified folds of the out-of-fold training distances: every centroid that "
    "averaged series of a fold is refitted without them, once per fold.",
)

#: The nearest-centroid fit's parameters this classifier passes on unchanged.
CENTROID_PARAMETERS = tuple(p.name for p in AVERAGER_PARAMETERS)


def default_readout() -> Pipeline:
    """The readout of ``readout=None``: standardised features, ridge-regularised linear
    classifier with its penalty chosen by efficient leave-one-out."""
    return make_pipeline(StandardScaler(), RidgeGCVClassifier(alphas=np.logspace(-3, 3, 13)))


def _check_readout_parameters(readout: Any) -> None:
    """The readout's own parameters checked before the centroids are fitted (scikit-learn
    checks them only inside the readout's ``fit``, which comes after the out-of-fold
    refits): ``_validate_params`` of every scikit-learn estimator in it that has one."""
    steps = [step for _, step in readout.steps] if isinstance(readout, Pipeline) else [readout]
    for step in steps:
        validate = getattr(step, "_validate_params", None)
        if callable(validate):
            try:
                validate()
            except (TypeError, ValueError) as error:  # InvalidParameterError is both
                raise type(error)(f"readout: {error}") from error


def _readout_has(name: str):
    """The method exists where the fitted decision is the nearest centroid's (which has
    it) or the readout has it."""

    def check(self) -> bool:
        if getattr(self, "decision_", None) == "nearest":
            return True
        readout = getattr(self, "readout_", None)
        if readout is None:
            readout = default_readout() if self.readout is None else self.readout
        if not hasattr(readout, name):
            final = readout[-1] if isinstance(readout, Pipeline) else readout
            raise AttributeError(
                f"{type(self).__name__} has no {name} here: its readout "
                f"({type(final).__name__}) has none, and the fitted decision is the "
                "readout's. Pass a readout that has it, e.g. readout=LogisticRegression(), "
                'or decision="nearest" (the nearest centroid\'s softmax)'
            )
        return True

    return check


@document_settings
@declare_parameters(
    (*AVERAGER_PARAMETERS, READOUT, DECISION, CV),
    {
        **AVERAGER_DEFAULTS,
        "n_centroids": "auto",
        "dtw_window": "auto",
        "readout": None,
        "decision": "auto",
        "cv": 5,
    },
    hint=setting_hint,
    notes={
        "n_centroids": "The centroids are RTWNearestCentroid's (the same choice); every "
        "centroid is a feature.",
    },
)
class RTWPrototypeClassifier(ClassifierMixin, TransformerMixin, BaseEstimator):
    """Classifier reading out the manifold-DTW distances to every centroid of every class.

    ``fit`` learns the centroids exactly as :class:`RTWNearestCentroid` does (its
    parameters, defaults and choice of band and centroids; the fitted nearest-centroid
    classifier is ``centroids_``), measures every training series against centroids that
    did not see it (out of fold: each centroid that averaged series of a fold is
    refitted without them), and fits a readout on those distances. A series is then
    classified by its distances to every centroid, those of the other classes included,
    instead of by the nearest one alone; the centroids stay series one can plot, and
    ``readout_weights_`` says which of them weigh for and against each class.

    What to set: ``manifold`` for your data, nothing else to start with. ``cv`` trades
    fit time for out-of-fold features (every fold refits the centroids it touches);
    ``readout`` takes any scikit-learn classifier (``LogisticRegression`` for
    probabilities); ``decision="auto"`` keeps the nearest centroid where the readout
    does not clearly classify the training series better, cross-validated
    (``decision_``), and ``decision="readout"`` always uses the readout. Why out of
    fold: a series' distance to a centroid averaged from it is small, and a readout
    trained on such distances learns from values that never occur at prediction time.

    What to expect (the UCR benchmark page, measured against nearest centroid, 1-NN DTW
    and MiniRocket): with tens of training series per class the readout rarely beats the
    nearest centroid, ``decision="auto"`` keeps the latter, and the accuracy is
    :class:`RTWNearestCentroid`'s at about twice its fit time; the readout pays with
    hundreds of series per class (ElectricDevices: 0.725 against 0.631). aeon's
    MiniRocket is more accurate on most UCR sets (7-9 points on the development
    archive) and, on the raw coordinates, on R-LASA's quaternion and SPD handwriting
    (manifold classification page); what this classifier adds is centroids on the
    manifold that one can plot and read, and a decision by manifold DTW.

    Parameters
    ----------
    %(parameters)s

    Attributes
    ----------
    centroids_ : RTWNearestCentroid
        The nearest-centroid fit whose centroids are the features (fitted with
        ``temperature=1.0``; never modified after its fit).
    temperature_ : float
        The temperature of the nearest centroid's probabilities
        (``decision_ == "nearest"``), fitted on the out-of-fold class distances.
    readout_ : classifier
        The fitted readout (a clone of ``readout``), trained on class indices
        ``0..n_classes - 1``.
    classes_ : ndarray of shape (n_classes,)
    means_ : ndarray of shape (n_means, Z, *point_shape) or list of ndarray
        Every centroid (``centroids_.means_``): the columns of :meth:`transform`.
    centroid_classes_ : ndarray of shape (n_means,)
        Class index of every centroid.
    dtw_window_ : float or None
        The band of the fit and of prediction.
    n_centroids_ : int or float
        Centroids of every class (as ``RTWNearestCentroid.n_centroids_``).
    decision_ : {"readout", "nearest"}
        What classifies: the readout, or the nearest centroid (``decision``).
    n_folds_ : int
        The folds of the out-of-fold distances: ``cv``, or fewer where the largest class
        has fewer series (a warning says so).
    cv_accuracy_ : dict
        Behind ``decision="auto"`` (empty otherwise): ``"readout"`` (its cross-validated
        accuracy on the out-of-fold distances), ``"nearest"`` (the nearest out-of-fold
        centroid's) and ``"z"`` (the readout's advantage in standard errors).
    distance_scale_ : float
        Median out-of-fold training distance, the unit of the readout's features.
    oof_distances_ : ndarray of shape (n_series, n_means)
        The out-of-fold distances of the training series the readout was fitted on.
    readout_weights_ : ndarray of shape (n_classes, n_means)
        Weight of every centroid's feature in every class's score (the linear readout's
        ``coef_``, on standardised features for the default; for two classes the
        negated row for ``classes_[0]`` and the row for ``classes_[1]``): positive where
        being far from the centroid speaks for the class. Only for a linear readout.

    Notes
    -----
    %(method_settings)s

    Examples
    --------
    >>> import numpy as np
    >>> from sk_rtw import RTWPrototypeClassifier
    >>> from sk_rtw.methods import DBA
    >>> t = np.linspace(0, 1, 40)
    >>> X = np.stack([np.sin(2 * np.pi * t ** p) for p in (0.7, 0.8, 0.9, 1.1, 1.2, 1.3)]
    ...              + [np.cos(2 * np.pi * t ** p) for p in (0.7, 0.8, 0.9, 1.1, 1.2, 1.3)])
    >>> y = ["sin"] * 6 + ["cos"] * 6
    >>> clf = RTWPrototypeClassifier(method=DBA(), cv=3, random_state=0).fit(X, y)
    >>> clf.predict(X[[0, -1]]).tolist()
    ['sin', 'cos']
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
        readout: Any = None,
        decision: str = "auto",
        cv: int = 5,
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
        self.readout = readout
        self.decision = decision
        self.cv = cv

    def set_params(self, **params):
        """Set parameters, scikit-learn's way; ``method__<setting>`` also works when
        ``method`` is a name, as for :class:`RTWNearestCentroid`.

        Parameters
        ----------
        **params : dict
            Estimator parameters, ``method__<setting>`` and ``readout__<parameter>``.

        Returns
        -------
        self
        """
        set_params_with_hints(self, params, super().set_params)
        return self

    def fit(self, X: Any, y: Any = None):
        """Learn the centroids, the out-of-fold distances to them, and the readout.

        Parameters
        ----------
        X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list
            Training series (a list of ``(T_i, *point_shape)`` arrays for unequal lengths).
        y : array-like of shape (n_series,)
            Labels of at least two classes.

        Returns
        -------
        self
        """
        if y is None:
            raise ValueError(
                f"{type(self).__name__} requires y to be passed, but the target y is None"
            )
        params = validate_parameters(self)  # every parameter checked before any work
        readout = default_readout() if params["readout"] is None else clone(params["readout"])
        _check_readout_parameters(readout)
        # one integer seed for the whole fit, drawn once from random_state (an int, None,
        # a RandomState or a Generator): the centroids, the folds of the out-of-fold
        # distances and the decision's cross-validation follow from it
        seed = self.random_state
        if not isinstance(seed, Integral):
            seed = int(check_random_state(seed).randint(2**31 - 1))
        shared = {name: getattr(self, name) for name in CENTROID_PARAMETERS}
        centroids = RTWNearestCentroid(**{**shared, "random_state": seed}, temperature=1.0)
        centroids.fit(X, y)
        record = centroids._fit_record
        collection, _ = centroids._represented(X)
        codes = record.codes
        self.n_folds_ = fold_count(params["cv"], codes)
        if self.n_folds_ < params["cv"]:
            warnings.warn(
                f"{type(self).__name__}: cv={params['cv']} asks for more folds than the "
                f"largest class has series; {self.n_folds_} folds are used (n_folds_)",
                UserWarning, stacklevel=2,
            )  # fmt: skip
        distances = out_of_fold_distances(
            record, list(centroids.means_), collection, params["cv"], random_state=seed,
            owner=type(self).__name__,
        )  # fmt: skip
        class_distances = np.stack(
            [distances[:, centroids.centroid_classes_ == c].min(1)
             for c in range(len(centroids.classes_))], axis=1,
        )  # fmt: skip
        self.temperature_ = fit_temperature(class_distances, codes)
        positive = distances[distances > 0]
        self.distance_scale_ = float(np.median(positive)) if len(positive) else 1.0
        features = self._features(distances)
        unfitted = clone(readout)
        readout.fit(features, codes)
        choice = (DEFAULT_CHOICE if params["choice"] is None else params["choice"]).checked()
        self.decision_, self.cv_accuracy_ = self._decide(
            params["decision"], unfitted, readout, features, class_distances, codes,
            params["cv"], seed, choice,
        )  # fmt: skip
        self.centroids_ = centroids
        self.readout_ = readout
        self.oof_distances_ = distances
        self.classes_ = centroids.classes_
        self.means_ = centroids.means_
        self.centroid_classes_ = centroids.centroid_classes_
        self.dtw_window_ = centroids.dtw_window_
        self.n_centroids_ = centroids.n_centroids_
        if hasattr(centroids, "n_features_in_"):
            self.n_features_in_ = centroids.n_features_in_
        return self

    def _decide(self, decision, readout, fitted, features, class_distances, codes, n_folds,
                seed, choice):  # fmt: skip
        """``decision_`` and the cross-validated accuracies behind it: the default
        readout's leave-one-out predictions (closed form, from ``fitted``), any other
        readout refitted on the folds of the out-of-fold distances (drawn from ``seed``
        as they were)."""
        if decision != "auto":
            return decision, {}
        fold_seed = check_random_state(seed).randint(2**31 - 1)
        predicted = cross_validated_predictions(
            readout, fitted, features, codes, n_folds, fold_seed
        )
        by_readout = predicted == codes
        by_nearest = class_distances.argmin(1) == codes
        z = mcnemar(by_readout, by_nearest)
        scores = {
            "readout": float(by_readout.mean()), "nearest": float(by_nearest.mean()),
            "z": float(z),
        }  # fmt: skip
        return ("readout" if choice.prefers(z) else "nearest"), scores

    def _features(self, distances: np.ndarray) -> np.ndarray:
        return np.log1p(distances / self.distance_scale_)

    def transform(self, X: Any) -> np.ndarray:
        """Manifold-DTW distance of every series to every centroid.

        Parameters
        ----------
        X : array-like or list of series
            Series of any length on the training manifold.

        Returns
        -------
        distances : ndarray of shape (n_series, n_means)
            One column per entry of ``means_`` (``centroid_classes_`` gives its class).
        """
        check_is_fitted(self, "readout_")
        return self.centroids_.transform(X)

    def predict(self, X: Any) -> np.ndarray:
        """The readout's class from the distances to every centroid.

        Parameters
        ----------
        X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list
            Series on the training manifold; any length (a list for unequal lengths).

        Returns
        -------
        labels : ndarray of shape (n_series,)
        """
        check_is_fitted(self, "readout_")
        if self.decision_ == "nearest":
            return self.centroids_.predict(X)
        features = self._features(self.transform(X))
        return self.classes_[np.asarray(self.readout_.predict(features), dtype=np.int64)]

    @available_if(_readout_has("predict_proba"))
    def predict_proba(self, X: Any) -> np.ndarray:
        """Class probabilities: the readout's (where it has them), or the nearest
        centroid's (``decision_ == "nearest"``: the softmax of the negative class
        distances, ``centroids_.class_distances``, over ``temperature_``).

        Parameters
        ----------
        X : array-like or list of series

        Returns
        -------
        proba : ndarray of shape (n_series, n_classes)
        """
        check_is_fitted(self, "readout_")
        if self.decision_ == "nearest":
            return softmax(-self.centroids_.class_distances(X) / self.temperature_, axis=1)
        return self.readout_.predict_proba(self._features(self.transform(X)))

    @available_if(_readout_has("decision_function"))
    def decision_function(self, X: Any) -> np.ndarray:
        """Scores: the readout's (where it has them), or the nearest centroid's
        (``decision_ == "nearest"``: ``centroids_.decision_function``).

        Parameters
        ----------
        X : array-like or list of series

        Returns
        -------
        scores : ndarray of shape (n_series, n_classes) or (n_series,)
            For two classes the 1-D score, positive towards ``classes_[1]``.
        """
        check_is_fitted(self, "readout_")
        if self.decision_ == "nearest":
            return self.centroids_.decision_function(X)
        return self.readout_.decision_function(self._features(self.transform(X)))

    @property
    def readout_weights_(self) -> np.ndarray:
        check_is_fitted(self, "readout_")
        final = self.readout_[-1] if isinstance(self.readout_, Pipeline) else self.readout_
        coef = getattr(final, "coef_", None)
        if coef is None:
            raise AttributeError(
                f"readout_weights_ needs a linear readout (one with coef_); "
                f"{type(final).__name__} has none"
            )
        coef = np.atleast_2d(np.asarray(coef, dtype=float))
        if coef.shape[0] == 1 and len(self.classes_) == 2:
            coef = np.vstack([-coef[0], coef[0]])
        return coef

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.allow_nan = False
        tags.non_deterministic = False
        return tags
