"""GeodesicShapeletClassifier: geodesic dilated shapelets read by a ridge classifier."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from sklearn.base import BaseEstimator, ClassifierMixin, clone
from sklearn.pipeline import Pipeline, make_pipeline
from sklearn.preprocessing import StandardScaler
from sklearn.utils.validation import check_is_fitted

from ..estimators import RidgeGCVClassifier
from ..utils import check_classes, check_series_collection
from ..utils._common_params import CLASSIFIER
from ..utils._constraints import Constant
from ..utils._params import Parameter, declare_parameters, validate_parameters
from ._transform import SHAPELET_DEFAULTS, SHAPELET_PARAMETERS, GeodesicShapeletTransform

if TYPE_CHECKING:
    from ..manifolds import Manifold

#: RDST's ridge penalties.
ALPHAS = tuple(float(a) for a in np.logspace(-4, 4, 20))


READOUT = Parameter(
    "readout",
    (
        Constant(None, "the default readout"),
        CLASSIFIER,
    ),
    "Classifier fitted on the shapelet features; cloned in fit. None: StandardScaler then "
    "RidgeGCVClassifier with RDST's penalties (20 from 1e-4 to 1e4), RDST's readout.",
)


def default_readout() -> Pipeline:
    """The readout of ``readout=None``: standardised features, ridge by leave-one-out."""
    return make_pipeline(StandardScaler(), RidgeGCVClassifier(alphas=ALPHAS))


@declare_parameters(
    (*SHAPELET_PARAMETERS[:-3], READOUT, *SHAPELET_PARAMETERS[-3:]),
    {**SHAPELET_DEFAULTS, "readout": None},
)
class GeodesicShapeletClassifier(ClassifierMixin, BaseEstimator):
    """Random dilated shapelets on any manifold, read by a ridge classifier.

    :class:`GeodesicShapeletTransform` (its parameters, but ``readout``) then, by
    default, standardised features and a ridge classifier whose penalty is chosen by
    leave-one-out (RDST's readout, Guillaume et al. 2022; MiniRocket's too). Local
    patterns decide: a short shape anywhere in the series, whatever its frame where the
    manifold has a normalisation (a left translation on quaternions, a congruence on
    SPD, mean and scale on R^d).

    When to pick it: where classes differ by short patterns at any position (where an
    elastic whole-series measure sees mostly noise); its cost is the transform's, about
    ``n_shapelets x n_windows x length`` point distances per series, abandoned early.

    Parameters
    ----------
    %(parameters)s

    Attributes
    ----------
    classes_ : ndarray of shape (n_classes,)
    transform_ : GeodesicShapeletTransform
        The fitted transform (its ``shapelets_``).
    readout_ : classifier
        The fitted readout.
    n_features_in_ : int
        Time points of the training series, for equal-length univariate data only.

    See Also
    --------
    sk_rtw.RTWProximityForest : whole-series elastic measures; shapelet splits too.

    Examples
    --------
    >>> import numpy as np
    >>> from sk_rtw.shapelets import GeodesicShapeletClassifier
    >>> rng = np.random.default_rng(0)
    >>> X = rng.standard_normal((20, 50))
    >>> X[10:, 20:25] += 4.0                     # a bump: class 1
    >>> y = [0] * 10 + [1] * 10
    >>> clf = GeodesicShapeletClassifier(n_shapelets=50, random_state=0).fit(X, y)
    >>> clf.score(X, y)
    1.0
    """

    def __init__(
        self,
        manifold: str | Manifold = "euclidean",
        *,
        n_shapelets: int = 10_000,
        lengths: tuple[int, ...] | None = None,
        normalised_fraction: float = 0.5,
        representation: str = "auto",
        threshold_percentiles: tuple[float, float] = (5.0, 10.0),
        readout: Any = None,
        n_jobs: int | None = None,
        random_state: int | np.random.RandomState | np.random.Generator | None = None,
        verbose: bool | int = 0,
    ) -> None:
        self.manifold = manifold
        self.n_shapelets = n_shapelets
        self.lengths = lengths
        self.normalised_fraction = normalised_fraction
        self.representation = representation
        self.threshold_percentiles = threshold_percentiles
        self.readout = readout
        self.n_jobs = n_jobs
        self.random_state = random_state
        self.verbose = verbose

    def fit(self, X: Any, y: Any) -> GeodesicShapeletClassifier:
        """Draw the shapelets and fit the readout on their features.

        Parameters
        ----------
        X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list
        y : array-like of shape (n_series,)
            Labels of at least two classes.

        Returns
        -------
        self
        """
        params = validate_parameters(self)
        n_series = check_series_collection(X, self.manifold, min_length=1).n_series
        classes, codes = check_classes(type(self).__name__, y, n_series)
        names = GeodesicShapeletTransform._declaration.names  # type: ignore[attr-defined]
        transform = GeodesicShapeletTransform(**{n: params[n] for n in names})
        transform = transform.set_params(random_state=self.random_state)
        features = transform.fit_transform(X, codes)
        readout = default_readout() if params["readout"] is None else clone(params["readout"])
        self.readout_ = readout.fit(features, codes)
        self.transform_ = transform
        self.classes_ = classes
        if hasattr(transform, "n_features_in_"):
            self.n_features_in_ = transform.n_features_in_
        return self

    def _features(self, X: Any) -> np.ndarray:
        check_is_fitted(self, "readout_")
        return self.transform_.transform(X)

    def predict(self, X: Any) -> np.ndarray:
        """The readout's class of every series.

        Parameters
        ----------
        X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list

        Returns
        -------
        labels : ndarray of shape (n_series,)
        """
        features = self._features(X)
        return self.classes_[np.asarray(self.readout_.predict(features), dtype=int)]

    def decision_function(self, X: Any) -> np.ndarray:
        """The readout's decision function on the shapelet features.

        Parameters
        ----------
        X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list

        Returns
        -------
        scores : ndarray of shape (n_series,) or (n_series, n_classes)
        """
        features = self._features(X)
        return self.readout_.decision_function(features)

    def predict_proba(self, X: Any) -> np.ndarray:
        """The readout's probabilities where it has them; else 1 for the predicted class
        (aeon's convention for RDST's ridge).

        Parameters
        ----------
        X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list

        Returns
        -------
        proba : ndarray of shape (n_series, n_classes)
        """
        features = self._features(X)
        if hasattr(self.readout_, "predict_proba"):
            return self.readout_.predict_proba(features)
        codes = np.asarray(self.readout_.predict(features), dtype=int)
        return np.eye(len(self.classes_))[codes]

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.allow_nan = False
        tags.non_deterministic = False
        return tags
