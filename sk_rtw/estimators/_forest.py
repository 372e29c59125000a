"""RTWProximityForest: Proximity Forest on any manifold, with the tangent velocity."""

from __future__ import annotations

import sys
import time
from typing import TYPE_CHECKING, Any

import numpy as np
from sklearn.base import BaseEstimator, ClassifierMixin
from sklearn.utils.validation import check_is_fitted

from .._random import check_generator
from .._threads import limited_threads, resolve_n_jobs, thread_map
from ..dtw import PreparedSeries, prepare_series
from ..representations import REPRESENTATIONS, represent
from ..utils import check_series_collection
from ..utils._common_params import MANIFOLD, N_JOBS, RANDOM_STATE, VERBOSE
from ..utils._constraints import Constant, Interval, Options
from ..utils._params import Parameter, declare_parameters, validate_parameters
from ._averager import _check_labels, _encode
from ._proximity_tree import ProximityTree

if TYPE_CHECKING:
    from ..manifolds import Manifold

N_TREES = Parameter(
    "n_trees",
    (Interval(int, 1),),
    "Trees of the forest; fit and prediction time grow in proportion (Proximity Forest's "
    "100 is where its accuracy levels off).",
)
N_CANDIDATES = Parameter(
    "n_candidates",
    (Interval(int, 1),),
    "Candidate splits drawn at every node, of which the one with the largest Gini gain "
    "is kept (Proximity Forest's r): more candidates, stronger but less diverse trees.",
)
REPRESENTATION = Parameter(
    "representation",
    (Options(("both", *REPRESENTATIONS)),),
    'What the measures compare: "raw" the series, "velocity" their tangent velocity '
    "(sk_rtw.tangent_velocity: the derivative series of the manifold), \"both\" drawn "
    "for every candidate split.",
)
EXEMPLARS = Parameter(
    "exemplars",
    (Options(("series", "mean")),),
    'Each branch\'s exemplar: "series" one training series of its class, drawn at random '
    '(the published recipe); "mean" the DBA mean of a random subset of the class (about '
    "the square root of its size, at most 10 series): 1.7-3x the fit, and 0.5-1.4 points "
    "less accurate on the UCR page's halves (better on 4 of 30 datasets, worse on 13).",
)
MAX_DEPTH = Parameter(
    "max_depth",
    (Constant(None, "split until every leaf is pure"), Interval(int, 1)),
    "Deepest level of a tree; a node there is a leaf with its class proportions.",
)

FOREST_PARAMETERS = (
    MANIFOLD, N_TREES, N_CANDIDATES, REPRESENTATION, EXEMPLARS, MAX_DEPTH, N_JOBS,
    RANDOM_STATE, VERBOSE,
)  # fmt: skip
FOREST_DEFAULTS = {
    "manifold": "euclidean",
    "n_trees": 100,
    "n_candidates": 5,
    "representation": "both",
    "exemplars": "series",
    "max_depth": None,
    "n_jobs": None,
    "random_state": None,
    "verbose": 0,
}


@declare_parameters(FOREST_PARAMETERS, FOREST_DEFAULTS)
class RTWProximityForest(ClassifierMixin, BaseEstimator):
    """Proximity Forest on any manifold: trees that split by the nearest exemplar under
    a randomly drawn manifold-DTW measure, on the series or their tangent velocity.

    Each tree splits a node by drawing ``n_candidates`` candidate splits and keeping the
    one with the largest Gini gain; a candidate draws one training series per class of
    the node as exemplars and a measure of the manifold-DTW family, and sends every
    series of the node to the branch of its nearest exemplar. The measure draws, as
    Proximity Forest 2.0 (Herrmann et al. 2023) draws its DTW family: the representation
    (the series, or their tangent velocity: the manifold's derivative series,
    :func:`sk_rtw.tangent_velocity`), the point cost (the geodesic distance to the power
    1/2, 1 or 2), and either DTW in a Sakoe-Chiba band of radius up to a quarter of the
    length, or amerced DTW without a band (a penalty on every step off the diagonal,
    drawn on a scale taken from the node's series). Trees split until their leaves are
    pure; ``predict_proba`` averages the class proportions of the leaves the series
    reach in every tree (with pure leaves: the trees' vote). The nearest exemplar is found by the
    package's nearest search (lower bounds, early abandoning, the exhaustive answer).

    When to pick it: it is the most accurate classifier of the package where classes
    differ in shape details (UCR page of the documentation: ahead of
    :class:`RTWNearestCentroid` on most datasets), and the tangent velocity makes it
    strong on manifold-valued demonstrations (R-LASA page). It costs more: a forest's fit
    computes about ``n_trees x n_candidates x depth x n_classes`` DTW distances per
    training series and prediction ``n_trees x depth x n_classes`` per series, where a
    nearest-centroid classifier computes one per centroid; it gives no class means to
    plot or to feed movement models (its exemplars are training series). Fit and
    prediction time grow with ``n_trees``; ``n_jobs`` builds and queries the trees on
    several threads with the same result.

    Measured (UCR page, one thread, 100 trees): on UCR datasets of 16-180 training
    series, 0.90-0.93 mean accuracy where :class:`RTWNearestCentroid` reads 0.85-0.86
    (Proximity Forest 1.0's published 0.90, MiniRocket's 0.92-0.93); fit 0.4 s to
    3 minutes per dataset, 1.5-2x Proximity Forest 2.0's published single-CPU time;
    prediction about 3x aeon's 1-NN DTW (median per dataset). A training set of 8,926
    short series takes half an hour to fit.

    Parameters
    ----------
    %(parameters)s

    Attributes
    ----------
    classes_ : ndarray of shape (n_classes,)
    manifold_ : Manifold
        The manifold resolved against the training data.
    trees_ : list of ProximityTree
        The fitted trees; ``trees_[k].root_`` is a tree's root
        (:class:`~sk_rtw.estimators._proximity_tree.ProximityNode`: its ``split`` holds
        the measure and each branch's exemplar, a training series' index).
    representations_ : tuple of str
        The representations drawn from.
    n_features_in_ : int
        Time points of the training series, for equal-length univariate data only.

    See Also
    --------
    RTWNearestCentroid : fewer, readable centroids; faster, less accurate.
    sk_rtw.tangent_velocity : the velocity representation.

    References
    ----------
    Lucas et al., "Proximity Forest: an effective and scalable distance-based classifier
    for time series", Data Mining and Knowledge Discovery 33 (2019). Herrmann, Tan,
    Salehi and Webb, "Proximity Forest 2.0: a new effective and scalable
    similarity-based classifier for time series", arXiv:2304.05800 (2023).

    Examples
    --------
    >>> import numpy as np
    >>> from sk_rtw import RTWProximityForest
    >>> t = np.linspace(0, 1, 40)
    >>> X = np.stack([np.sin(2 * np.pi * t ** p) for p in (0.8, 1.0, 1.2)]
    ...              + [np.cos(2 * np.pi * t ** p) for p in (0.8, 1.0, 1.2)])
    >>> y = ["sin"] * 3 + ["cos"] * 3
    >>> forest = RTWProximityForest(n_trees=10, random_state=0).fit(X, y)
    >>> forest.predict(X[[0, 5]]).tolist()
    ['sin', 'cos']
    """

    def __init__(
        self,
        manifold: str | Manifold = "euclidean",
        *,
        n_trees: int = 100,
        n_candidates: int = 5,
        representation: str = "both",
        exemplars: str = "series",
        max_depth: int | None = None,
        n_jobs: int | None = None,
        random_state: int | np.random.RandomState | np.random.Generator | None = None,
        verbose: bool | int = 0,
    ) -> None:
        self.manifold = manifold
        self.n_trees = n_trees
        self.n_candidates = n_candidates
        self.representation = representation
        self.exemplars = exemplars
        self.max_depth = max_depth
        self.n_jobs = n_jobs
        self.random_state = random_state
        self.verbose = verbose

    def fit(self, X: Any, y: Any) -> RTWProximityForest:
        """Grow the trees.

        Parameters
        ----------
        X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list
            Training series (a list of ``(T_i, *point_shape)`` arrays for unequal
            lengths); at least 2 time points each where the velocity is drawn.
        y : array-like of shape (n_series,)
            Labels of at least two classes.

        Returns
        -------
        self
        """
        params = validate_parameters(self)
        representations = (
            REPRESENTATIONS if params["representation"] == "both" else (params["representation"],)
        )
        shortest = 2 if "velocity" in representations else 1
        collection = check_series_collection(X, self.manifold, min_length=shortest)
        if y is None:
            raise ValueError(
                f"{type(self).__name__} requires y to be passed, but the target y is None"
            )
        labels = _check_labels(y, collection.n_series, True)
        classes, codes = _encode(labels)
        if len(classes) < 2:
            raise ValueError(
                f"{type(self).__name__} needs at least 2 classes in y; got {len(classes)} "
                f"class ({classes.tolist()})"
            )
        rng = check_generator(self.random_state)
        seeds = rng.integers(np.iinfo(np.int64).max, size=params["n_trees"])  # before any work
        collections = {r: represent(collection, r) for r in representations}
        data = {r: prepare_series(c) for r, c in collections.items()}
        settings = (params["n_candidates"], representations, params["exemplars"],
                    params["max_depth"])  # fmt: skip
        trees = [ProximityTree(*settings, int(seed)) for seed in seeds]
        verbose, total = int(params["verbose"]), len(trees)

        def grow(position: int) -> ProximityTree:
            start = time.perf_counter()
            tree = trees[position].fit(data, collections, codes, len(classes))
            if verbose:
                print(
                    f"{type(self).__name__}: tree {position + 1}/{total}: {tree.n_nodes_} "
                    f"nodes, depth {tree.depth_}, {time.perf_counter() - start:.2f} s",
                    file=sys.stderr, flush=True,
                )  # fmt: skip
            return tree

        with limited_threads(1):  # one thread per tree, each tree on one core
            self.trees_ = thread_map(grow, range(total), resolve_n_jobs(params["n_jobs"]))
        self.classes_ = classes
        self.manifold_ = collection.manifold
        self.representations_ = representations
        self._train = data
        if collection.equal_length and collection.manifold.point_shape == (1,):
            self.n_features_in_ = collection.max_length
        return self

    def _prepared(self, X: Any) -> dict[str, PreparedSeries]:
        check_is_fitted(self, "trees_")
        shortest = 2 if "velocity" in self.representations_ else 1
        collection = check_series_collection(X, self.manifold_, min_length=shortest)
        return {r: prepare_series(represent(collection, r)) for r in self.representations_}

    def predict_proba(self, X: Any) -> np.ndarray:
        """The mean over the trees of the class proportions of the leaf each series
        reaches (with pure leaves, the fraction of trees voting for each class).

        Parameters
        ----------
        X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list
            Series on the training manifold; any length.

        Returns
        -------
        proba : ndarray of shape (n_series, n_classes)
        """
        data = self._prepared(X)
        n_jobs = resolve_n_jobs(self.n_jobs)
        with limited_threads(1):
            votes = thread_map(lambda tree: tree.predict_proba(data, self._train), self.trees_,
                               n_jobs)  # fmt: skip
        total = np.zeros((next(iter(data.values())).n_series, len(self.classes_)))
        for vote in votes:  # in the trees' order: the same sum for any n_jobs
            total += vote
        return total / len(votes)

    def predict(self, X: Any) -> np.ndarray:
        """The class with the largest :meth:`predict_proba` (ties to the first class).

        Parameters
        ----------
        X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list

        Returns
        -------
        labels : ndarray of shape (n_series,)
        """
        proba = self.predict_proba(X)
        return self.classes_[np.argmax(proba, axis=1)]

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.input_tags.allow_nan = False
        tags.non_deterministic = False
        return tags

