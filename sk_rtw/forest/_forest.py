"""RTWProximityForest: Proximity Forest on any manifold, with the tangent velocity."""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING, Any

import numpy as np
from joblib import Parallel, delayed
from sklearn.base import BaseEstimator, ClassifierMixin
from sklearn.utils.validation import check_is_fitted

from .._random import check_generator
from .._threads import limited_threads, resolve_n_jobs
from ..utils._common_params import MANIFOLD, N_JOBS, RANDOM_STATE, VERBOSE
from ..utils._constraints import Interval
from ..utils._params import Parameter, declare_parameters, validate_parameters
from ._params import (
    EXEMPLARS,
    MAX_DEPTH,
    N_CANDIDATES,
    REPRESENTATION,
    SCORING_SAMPLE,
    SPLITTERS,
    representations_read,
)
from ._series import TrainingSet
from ._splitter import Splitter
from ._tree import ProximityTree, prepare_representations, training_data

if TYPE_CHECKING:
    from ..manifolds import Manifold

N_TREES = Parameter(
    "n_trees",
    (Interval(int, 1),),
    "Trees of the forest; fit and prediction time grow in proportion (Proximity Forest's "
    "100 is where its accuracy levels off).",
)

FOREST_PARAMETERS = (
    MANIFOLD, N_TREES, SPLITTERS, N_CANDIDATES, REPRESENTATION, EXEMPLARS, MAX_DEPTH,
    SCORING_SAMPLE, N_JOBS, RANDOM_STATE, VERBOSE,
)  # fmt: skip
FOREST_DEFAULTS = {
    "manifold": "euclidean",
    "n_trees": 100,
    "splitters": None,
    "n_candidates": 5,
    "representation": "auto",
    "exemplars": "series",
    "max_depth": None,
    "scoring_sample": 1000,
    "n_jobs": None,
    "random_state": None,
    "verbose": 0,
}


def share_exemplars(trees: list[ProximityTree], training: TrainingSet) -> None:
    """One array of the training series any tree holds as an exemplar, per
    representation, read by every tree's store (grown in this process or elsewhere)."""
    for representation, prepared in training.prepared.items():
        stores = [tree._stores[representation] for tree in trees]
        rows = np.unique(np.concatenate([s.used for s in stores])).astype(np.int64)
        shared = prepared.take(rows)
        for store in stores:
            store.rebase(shared, rows)


@declare_parameters(FOREST_PARAMETERS, FOREST_DEFAULTS)
class RTWProximityForest(ClassifierMixin, BaseEstimator):
    """Proximity Forest on any manifold, with local patterns: trees that split by the
    nearest exemplar under a randomly drawn manifold-DTW measure or by a geodesic
    dilated shapelet, on the series or their tangent velocity.

    Each tree splits a node by drawing candidate splits from its splitters and keeping
    the one with the largest Gini gain. An elastic candidate
    (:class:`~sk_rtw.forest.ElasticSplitter`, Proximity Forest's) draws one training
    series per class of the node as exemplars and a measure of the manifold-DTW family,
    and sends every series of the node to the branch of its nearest exemplar. The
    measure draws, as Proximity Forest 2.0 (Herrmann et al. 2023) draws its DTW family:
    the representation (the series, or their tangent velocity: the manifold's derivative
    series, :func:`sk_rtw.tangent_velocity`), the point cost (the geodesic distance to
    the power 1/2, 1 or 2), and either DTW in a Sakoe-Chiba band of radius up to a
    quarter of the length, or amerced DTW without a band (a penalty on every step off
    the diagonal, drawn on a scale taken from the node's series). A shapelet candidate
    (:class:`~sk_rtw.forest.ShapeletSplitter`, TS-CHIEF's recipe with RDST's features)
    draws a dilated subsequence of one of the node's series and one of its features (the
    minimum sliding geodesic distance, its position, or how often the distance falls
    below a threshold) and splits at the feature's best Gini threshold: it sees a short
    pattern wherever it occurs, which whole-series measures miss. By default a node
    draws ``n_candidates`` of each kind; ``splitters=(ElasticSplitter(),)`` is Proximity
    Forest 2.0's elastic forest alone, and ``splitters=`` takes any kinds of split that
    follow the protocol, each with its recipe. Trees split until their leaves are pure;
    ``predict_proba`` averages the class proportions of the leaves the series reach in
    every tree (with pure leaves: the trees' vote). The nearest exemplar is found by the
    package's nearest search (lower bounds, early abandoning, the exhaustive answer).

    When to pick it: it is the most accurate forest of the package (UCR page of the
    documentation: ahead of :class:`RTWNearestCentroid` on most datasets), its shapelet
    candidates see short patterns anywhere in the series, and the tangent velocity
    makes it strong on manifold-valued demonstrations (R-LASA page). It costs more: an
    elastic candidate computes about one DTW distance per series of the node and class
    (most abandoned early), so a forest's fit computes about
    ``n_trees x n_candidates x depth x n_classes`` distances per training series and
    prediction ``n_trees x depth x n_classes`` per series, where a nearest-centroid
    classifier computes one per centroid; it gives no class means to plot or to feed
    movement models (its exemplars are training series). Fit and prediction time grow
    with ``n_trees``; ``n_jobs`` builds and queries the trees on several threads with
    the same result. The fitted forest keeps what routing needs (every elastic split's
    exemplar series, every shapelet), not the training set.

    Measured (UCR page, one thread, 100 trees, three seeds): on UCR datasets of 16-180
    training series, 0.906-0.925 mean accuracy per half where
    :class:`RTWNearestCentroid` reads 0.85-0.86 (published: Proximity Forest 2.0
    0.90-0.93, TS-CHIEF 0.92-0.93, MiniRocket 0.92-0.93), 0.753-0.760 on four large
    training sets (Proximity Forest 2.0 and TS-CHIEF 0.748); fit 0.1 s to 45 s per dataset,
    within Proximity Forest 2.0's C++ time on the same machine (0.96-0.97x over a half,
    1.13x on the large sets), prediction 0.68-0.79x it. A training set of 7,200 short
    series (Crop) takes about 3 minutes to fit and 1.2 minutes to predict its 16,800
    (nodes of more than ``scoring_sample`` series choose their split on a sample).
    ``splitters=[ElasticSplitter()]`` is Proximity Forest 2.0's elastic forest alone
    (this forest's default before shapelet candidates): 0.94-1.01x the fit, 1.4-1.6x
    the prediction, 0.1 and 0.8 points less on the development halves (three seeds)
    and 1.0-1.8 on the large sets (three seeds).

    Parameters
    ----------
    %(parameters)s

    Attributes
    ----------
    classes_ : ndarray of shape (n_classes,)
    manifold_ : Manifold
        The manifold resolved against the training data.
    trees_ : list of ProximityTree
        The fitted trees (:class:`~sk_rtw.forest.ProximityTree`, each a classifier of its
        own); ``trees_[k].root_`` is a tree's root (:class:`~sk_rtw.forest.ProximityNode`:
        its ``split`` holds what routes a series, for the elastic splitter the measure
        and each branch's exemplar series).
    splitters_ : tuple of Splitter
        The splitters resolved (the forest's values in place of their None).
    representations_ : tuple of str
        The representations the splitters read.
    scale_ : float
        What the series are divided by before any distance (a power of two for
        magnitudes beyond 1e+-100 on R^d and SPD(k), else 1): the forest is the same at
        any magnitude.
    n_features_in_ : int
        Time points of the training series, for equal-length univariate data only.

    See Also
    --------
    sk_rtw.forest.ElasticSplitter : the recipe of the elastic split.
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
        splitters: tuple[Splitter, ...] | None = None,
        n_candidates: int = 5,
        representation: str = "auto",
        exemplars: str = "series",
        max_depth: int | None = None,
        scoring_sample: int | None = 1000,
        n_jobs: int | None = None,
        random_state: int | np.random.RandomState | np.random.Generator | None = None,
        verbose: bool | int = 0,
    ) -> None:
        self.manifold = manifold
        self.n_trees = n_trees
        self.splitters = splitters
        self.n_candidates = n_candidates
        self.representation = representation
        self.exemplars = exemplars
        self.max_depth = max_depth
        self.scoring_sample = scoring_sample
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
        data = training_data(type(self).__name__, X, y, params)
        rng = check_generator(self.random_state)
        seeds = rng.integers(np.iinfo(np.int64).max, size=params["n_trees"])  # before any work
        splitters, training, classes, manifold = (
            data.splitters, data.training, data.classes, data.manifold
        )
        tree_params = {name: params[name] for name in ProximityTree._declaration.names
                       if name not in ("manifold", "random_state")}  # fmt: skip
        trees = [ProximityTree(self.manifold, **tree_params, random_state=int(seed))
                 for seed in seeds]  # fmt: skip
        verbose, total, scale = int(params["verbose"]), len(trees), data.scale

        def grow(position: int) -> ProximityTree:
            tree = trees[position]._grow(
                training, splitters, classes, manifold, np.random.default_rng(seeds[position]),
                scale,
            )
            if verbose:
                print(
                    f"{type(self).__name__}: tree {position + 1}/{total}: {tree.n_nodes_} "
                    f"nodes, depth {tree.depth_}, {tree.seconds_:.2f} s",
                    file=sys.stderr, flush=True,
                )  # fmt: skip
            return tree

        # trees through joblib, preferring threads (the kernels release the GIL): a user's
        # joblib.parallel_config decides where they run (a dask cluster's workers
        # included); every seed was drawn above, so the forest is the same anywhere
        with limited_threads(1):  # one thread per tree, each tree on one core
            self.trees_ = Parallel(n_jobs=params["n_jobs"], prefer="threads")(
                delayed(grow)(position) for position in range(total)
            )
        share_exemplars(self.trees_, training)
        self.classes_ = classes
        self.manifold_ = manifold
        self.splitters_ = splitters
        self.representations_ = representations_read(splitters)
        self.scale_ = scale
        if data.n_features is not None:
            self.n_features_in_ = data.n_features
        return self

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
        check_is_fitted(self, "trees_")
        data = prepare_representations(X, self.manifold_, self.representations_, self.scale_)
        n = data.n_series
        with limited_threads(1):  # the test series are shared: threads, as scikit-learn
            votes = Parallel(n_jobs=resolve_n_jobs(self.n_jobs), require="sharedmem")(
                delayed(tree._proba)(data, n) for tree in self.trees_
            )
        total = np.zeros((n, len(self.classes_)))
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
