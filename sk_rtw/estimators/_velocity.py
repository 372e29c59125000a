"""TangentVelocity: the tangent velocity as a scikit-learn transformer, for any
classifier (aeon's included)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from sklearn.base import BaseEstimator, TransformerMixin
from sklearn.utils.validation import check_is_fitted

from ..representations import tangent_velocity
from ..utils import check_series_collection, to_aeon
from ..utils._common_params import MANIFOLD
from ..utils._constraints import Options
from ..utils._params import Parameter, declare_parameters, validate_parameters

if TYPE_CHECKING:
    from ..manifolds import Manifold

OUTPUT = Parameter(
    "output",
    (Options(("series", "aeon", "tabular")),),
    '"series": time-major velocity series, ``(n, T - 1, d)`` (sk_rtw\'s layout, for its '
    'estimators with manifold="euclidean"); "aeon": channels first, ``(n, d, T - 1)`` '
    '(a list of ``(d, T_i - 1)`` arrays for unequal lengths), for aeon\'s classifiers; '
    '"tabular": ``(n, (T - 1) d)``, one row per series, for any scikit-learn estimator '
    "(equal lengths only).",
)


@declare_parameters((MANIFOLD, OUTPUT), {"manifold": "euclidean", "output": "series"})
class TangentVelocity(TransformerMixin, BaseEstimator):
    """The tangent velocity of manifold-valued series, as a transformer.

    :func:`sk_rtw.tangent_velocity` in a ``Pipeline``: every step ``log_{x_t}(x_{t+1})``
    in coordinates that compare across time (the body angular velocity of unit
    quaternions, the whitened logarithm of SPD steps in isometric coordinates, first
    differences on R^d), so that a classifier that knows no manifold -- aeon's
    MiniRocket, a scikit-learn model -- reads the motion rather than the coordinates.
    The quaternion velocity is in the body frame: a demonstration recorded in another
    world frame (``q -> g q``, any sign) gives the same velocity.

    Stateless: ``fit`` only checks the data and resolves the manifold.

    Parameters
    ----------
    %(parameters)s

    Attributes
    ----------
    manifold_ : Manifold

    See Also
    --------
    sk_rtw.tangent_velocity : the function.

    Examples
    --------
    >>> import numpy as np
    >>> from sk_rtw.estimators import TangentVelocity
    >>> X = np.array([[0.0, 1.0, 3.0], [0.0, 2.0, 2.0]])
    >>> TangentVelocity(output="tabular").fit_transform(X)
    array([[1., 2.],
           [2., 0.]])
    """

    def __init__(self, manifold: str | Manifold = "euclidean", *, output: str = "series"):
        self.manifold = manifold
        self.output = output

    def fit(self, X: Any, y: Any = None) -> TangentVelocity:
        """Check the series and resolve the manifold.

        Parameters
        ----------
        X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list
        y : ignored

        Returns
        -------
        self
        """
        validate_parameters(self)
        collection = check_series_collection(X, self.manifold, min_length=2)
        self.manifold_ = collection.manifold
        if collection.equal_length and collection.manifold.point_shape == (1,):
            self.n_features_in_ = collection.max_length
        return self

    def transform(self, X: Any) -> np.ndarray | list:
        """The velocity of every series, in the ``output`` layout.

        Parameters
        ----------
        X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list
            Series of at least 2 samples on the fitted manifold.

        Returns
        -------
        velocity : ndarray or list of ndarray
        """
        check_is_fitted(self, "manifold_")
        output = validate_parameters(self, ("output",))["output"]
        if not isinstance(X, (list, tuple, np.ndarray)) and hasattr(X, "__array__"):
            X = np.asarray(X)  # array-likes (a DataFrame's values) as arrays
        velocity = tangent_velocity(X, self.manifold_)
        if output == "series":
            return velocity
        if output == "aeon":
            return to_aeon(velocity)
        if isinstance(velocity, list):
            raise ValueError(
                'output="tabular" needs series of equal length; use output="aeon" (a list '
                "of unequal series for aeon's classifiers) or pad the series"
            )
        return velocity.reshape(len(velocity), -1)

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.allow_nan = False
        tags.requires_fit = True
        return tags
