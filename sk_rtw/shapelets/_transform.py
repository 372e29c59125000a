"""GeodesicShapeletTransform: random dilated shapelets on any manifold."""

from __future__ import annotations

import sys
import time
from numbers import Integral, Real
from typing import TYPE_CHECKING, Any

import numpy as np
from sklearn.base import BaseEstimator, TransformerMixin
from sklearn.utils.validation import check_is_fitted

from .._random import check_generator
from .._threads import limited_threads, resolve_n_jobs, thread_map
from ..representations import (
    DEPRECATED_BOTH,
    REPRESENTATION_VALUES,
    drawn_representations,
    represent,
)
from ..utils import check_labels, check_series_collection, encode_labels
from ..utils._common_params import MANIFOLD, N_JOBS, RANDOM_STATE, VERBOSE
from ..utils._constraints import Constant, Interval, Options, Satisfies
from ..utils._params import Parameter, declare_parameters, validate_parameters
from ._shapelet import FEATURES, ShapeletBank, draw_shapelets, features
from ._windows import window_space

if TYPE_CHECKING:
    from ..manifolds import Manifold

#: Series per block of the transform (each block one task of the threads).
BLOCK = 32


def _is_lengths(value: Any) -> bool:
    if isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
        return False
    values = tuple(value)
    return bool(values) and all(
        isinstance(v, Integral) and not isinstance(v, (bool, np.bool_)) and int(v) >= 1
        for v in values
    )


def _is_percentiles(value: Any) -> bool:
    if isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
        return False
    values = tuple(value)
    return (
        len(values) == 2
        and all(isinstance(v, Real) and not isinstance(v, (bool, np.bool_)) for v in values)
        and 0.0 <= values[0] <= values[1] <= 100.0
    )


LENGTHS = Parameter(
    "lengths",
    (
        Constant(None, "min(max(2, T // 2), 11) of the shortest series"),
        Satisfies("sequence of int", "a non-empty sequence of integers >= 1",
                  predicate=_is_lengths),
    ),
    "Points of a shapelet, drawn uniformly from these (each at most the shortest "
    "training series' length).",
)
NORMALISED_FRACTION = Parameter(
    "normalised_fraction",
    (Interval(float, 0.0, 1.0),),
    "Probability that a shapelet compares shape without position: its windows "
    "normalised by the manifold (mean and scale on R^d, a left translation on unit "
    "quaternions, a congruence on SPD, each factor of a product; "
    ":meth:`~sk_rtw.manifolds.Manifold.normalise_windows`). On a space without a "
    "normalisation (spheres S^d, d < 3) every shapelet compares points as they are.",
)
THRESHOLD_PERCENTILES = Parameter(
    "threshold_percentiles",
    (Satisfies("(float, float)", "two percentiles 0 <= low <= high <= 100",
               predicate=_is_percentiles),),
    "A shapelet's occurrence threshold is drawn uniformly between these percentiles "
    "of its distances to the windows of another training series of its class.",
)
SHAPELET_PARAMETERS = (
    MANIFOLD,
    Parameter(
        "n_shapelets",
        (Interval(int, 1),),
        "Shapelets drawn; three features each (RDST's 10,000 by default).",
    ),
    LENGTHS,
    NORMALISED_FRACTION,
    Parameter(
        "representation",
        (Options((*REPRESENTATION_VALUES, DEPRECATED_BOTH)),),
        'Where shapelets are drawn: "raw" the series, "velocity" their tangent velocity, '
        '"auto" either, shapelet by shapelet (uniformly; the readout weighs them). "both", '
        "the forest's former word for it, is deprecated.",
    ),
    THRESHOLD_PERCENTILES,
    N_JOBS,
    RANDOM_STATE,
    VERBOSE,
)
SHAPELET_DEFAULTS = {
    "manifold": "euclidean",
    "n_shapelets": 10_000,
    "lengths": None,
    "normalised_fraction": 0.5,
    "representation": "auto",
    "threshold_percentiles": (5.0, 10.0),
    "n_jobs": None,
    "random_state": None,
    "verbose": 0,
}


def representations_of(value: str) -> tuple[str, ...]:
    """The representations a ``representation`` value draws from."""
    return drawn_representations(value)


def default_length(shortest: int) -> int:
    """RDST's shapelet length for series of at least ``shortest`` points."""
    return max(1, min(max(2, shortest // 2), 11, shortest))


@declare_parameters(SHAPELET_PARAMETERS, SHAPELET_DEFAULTS)
class GeodesicShapeletTransform(TransformerMixin, BaseEstimator):
    """Random dilated shapelets on any manifold: for every shapelet, the smallest sliding
    geodesic distance to a series, where it lies, and how often it falls below a
    threshold.

    Random dilated shapelets (RDST, Guillaume et al. 2022) with the geodesic distance:
    a shapelet is ``l`` points of a training series taken every ``d`` samples (length
    and dilation drawn, ``d = floor(2^u)`` with ``u`` uniform up to
    ``log2((T - 1) / (l - 1))``), from the series or their tangent velocity
    (:func:`sk_rtw.tangent_velocity`). Its distance to a window of a series is the sum
    of the geodesic distances of their points (on R^1, RDST's Manhattan distance). A
    fraction of the shapelets (``normalised_fraction``) compare shape without position:
    the manifold's form of z-normalisation removes its group action from the shapelet
    and from every window (mean and scale on R^d, a left translation on unit
    quaternions, any congruence on SPD matrices through each point's spectrum relative
    to the window's mean), so a demonstration recorded in another world frame gives
    the same features. The threshold of a shapelet is drawn between two percentiles of
    its distances to the windows of another training series of its class (of any
    series without ``y``; the series itself when its class has no other).

    Three features per shapelet, in the order of ``shapelets_``: the smallest distance,
    the first window where it occurs, and how many windows lie closer than the
    threshold. The sliding distance is compiled once
    (:func:`sk_rtw.dtw.shapelet_features`, with early abandoning: the features of the
    full sums) and shared with the forest's shapelet splits.

    Differences from aeon's ``RandomDilatedShapeletTransform``: no alpha-similarity
    mask (shapelets may overlap), one dilation bound per shapelet from the shortest
    series, and the point distance of the manifold (on several Euclidean channels the
    Euclidean norm of the point, where aeon sums absolute differences).

    Parameters
    ----------
    %(parameters)s

    Attributes
    ----------
    shapelets_ : list of Shapelet
        The shapelets, each with its points, length, dilation, threshold, whether it is
        normalised and where it was drawn (``source``).
    manifold_ : Manifold
    representations_ : tuple of str
    lengths_ : tuple of int
        The lengths drawn from.
    n_features_in_ : int
        Time points of the training series, for equal-length univariate data only.

    See Also
    --------
    GeodesicShapeletClassifier : the features read by a ridge classifier.

    References
    ----------
    Guillaume, Vrain and Elloumi, "Random Dilated Shapelet Transform: a new approach for
    time series shapelets", ICPRAI 2022.

    Examples
    --------
    >>> import numpy as np
    >>> from sk_rtw.shapelets import GeodesicShapeletTransform
    >>> X = np.random.default_rng(0).standard_normal((6, 40))
    >>> GeodesicShapeletTransform(n_shapelets=5, random_state=0).fit_transform(X).shape
    (6, 15)
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
        self.n_jobs = n_jobs
        self.random_state = random_state
        self.verbose = verbose

    def fit(self, X: Any, y: Any = None) -> GeodesicShapeletTransform:
        """Draw the shapelets from the training series.

        Parameters
        ----------
        X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list
            Training series (a list of ``(T_i, *point_shape)`` arrays for unequal
            lengths).
        y : array-like of shape (n_series,), optional
            Labels: each threshold comes from a series of the shapelet's class.

        Returns
        -------
        self
        """
        params = validate_parameters(self)
        representations = representations_of(params["representation"])
        shortest = 2 if "velocity" in representations else 1
        collection = check_series_collection(X, self.manifold, min_length=shortest)
        if y is None:
            codes = np.zeros(collection.n_series, dtype=np.int64)
        else:
            codes = encode_labels(check_labels(y, collection.n_series, False))[1]
        collections = {r: represent(collection, r) for r in representations}
        shortest = min(int(c.lengths.min()) for c in collections.values())
        lengths = params["lengths"]
        lengths = (default_length(shortest),) if lengths is None else tuple(map(int, lengths))
        if max(lengths) > shortest:
            raise ValueError(
                f"a shapelet of {max(lengths)} points is longer than the shortest training "
                f"series ({shortest} points"
                + (", its tangent velocity one fewer than the series" if "velocity" in
                   representations else "")
                + "): pass shorter lengths"
            )
        rng = check_generator(params["random_state"])
        start = time.perf_counter()
        low, high = (float(p) for p in params["threshold_percentiles"])
        self.shapelets_ = draw_shapelets(
            rng, params["n_shapelets"], collections, codes, representations, lengths,
            params["normalised_fraction"], (low, high),
        )
        if params["verbose"]:
            print(
                f"{type(self).__name__}: {len(self.shapelets_)} shapelets drawn in "
                f"{time.perf_counter() - start:.2f} s",
                file=sys.stderr, flush=True,
            )  # fmt: skip
        self.manifold_ = collection.manifold
        self.representations_ = representations
        self.lengths_ = lengths
        self._bank = ShapeletBank.build(
            self.shapelets_,
            lambda r, normal: window_space(collections[r].manifold, normal),
        )
        if collection.equal_length and collection.manifold.point_shape == (1,):
            self.n_features_in_ = collection.max_length
        return self

    def transform(self, X: Any) -> np.ndarray:
        """The three features of every shapelet for every series.

        Parameters
        ----------
        X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list
            Series on the training manifold (at least 2 samples where the velocity is
            read). A series shorter than a shapelet's span is read as padded with its
            last point: one window.

        Returns
        -------
        features : ndarray of shape (n_series, 3 * n_shapelets)
            Per shapelet: the smallest distance, where it lies, the occurrences.
        """
        check_is_fitted(self, "shapelets_")
        collections = self._collections(X)
        n = next(iter(collections.values())).n_series
        blocks = [np.arange(a, min(a + BLOCK, n)) for a in range(0, n, BLOCK)]

        def block_features(rows: np.ndarray) -> np.ndarray:
            part = {r: c.subset(rows) for r, c in collections.items()}
            return features(part, self._bank)

        with limited_threads(1):
            parts = thread_map(block_features, blocks, resolve_n_jobs(self.n_jobs))
        return np.concatenate(parts, axis=0).reshape(n, -1) if parts else np.empty((0, 0))

    def _collections(self, X: Any) -> dict:
        shortest = 2 if "velocity" in self.representations_ else 1
        collection = check_series_collection(X, self.manifold_, min_length=shortest)
        return {r: represent(collection, r) for r in self.representations_}

    def get_feature_names_out(self, input_features: Any = None) -> np.ndarray:
        """``shapelet{j}_{min|argmin|count}`` for every shapelet ``j``."""
        check_is_fitted(self, "shapelets_")
        return np.array([f"shapelet{j}_{name}" for j in range(len(self.shapelets_))
                         for name in FEATURES], dtype=object)  # fmt: skip

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.allow_nan = False
        tags.non_deterministic = False
        return tags

