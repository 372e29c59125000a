"""A proximity tree: nodes split by the best of candidates their splitters draw.

A tree is grown from a seed of its own (the forest draws every tree's seed before any
work, so a forest's result does not depend on how many threads build it). At every node
each splitter (:mod:`._splitter`) draws its candidates in turn; every candidate routes
the node's series (:meth:`Split.route`) and is scored by its Gini gain; the first of the
largest gain is kept (once one splits the node perfectly the rest are only drawn, not
routed: the same tree for less work), and it marks the training series it holds
(:func:`~._splitter.adopt`), so the fitted tree keeps the exemplars of its splits alone.
A node of more than ``scoring_sample`` series draws and scores its candidates on a
random sample of them (:func:`split_node`) and routes them all by the one kept.
A node whose best split leaves every series in one branch (series that no candidate
tells apart), or that reaches ``max_depth``, becomes a leaf with its class proportions;
so does a pure node. A branch that receives no training series (its
exemplar tied at distance 0 with another class's) is a leaf with its parent's
proportions. Prediction routes every series down by the same splits; the tree never asks
which kind a split is.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from sklearn.base import BaseEstimator, ClassifierMixin
from sklearn.utils.validation import check_is_fitted

from .._random import check_generator
from ..utils import check_classes, check_series_collection
from ..utils._common_params import MANIFOLD, RANDOM_STATE
from ..utils._params import declare_parameters, validate_parameters
from ._gini import gini_gain
from ._params import (
    EXEMPLARS,
    MAX_DEPTH,
    N_CANDIDATES,
    REPRESENTATION,
    SCORING_SAMPLE,
    SPLITTERS,
    representations_read,
    resolve_splitters,
)
from ._series import NodeSeries, SeriesSet, SeriesView, TrainingSet, unit_frame
from ._splitter import Split, Splitter, adopt

if TYPE_CHECKING:
    from ..manifolds import Manifold


@dataclass(eq=False)
class ProximityNode:
    """A node of a proximity tree.

    Attributes
    ----------
    distribution : ndarray of shape (n_classes,)
        Class proportions of the training series that reached the node.
    n_series : int
        Training series that reached it.
    depth : int
        0 at the root.
    split : Split or None
        None for a leaf; otherwise the kept candidate (for the elastic splitter a
        :class:`~sk_rtw.forest.NearestExemplarSplit`: its ``measure``, the class of each
        branch and each branch's exemplar series).
    gain : float
        The split's Gini gain (0 for a leaf).
    children : list of ProximityNode
        One per branch of the split.
    """

    distribution: np.ndarray
    n_series: int
    depth: int
    split: Split | None = None
    gain: float = 0.0
    children: list[ProximityNode] = field(default_factory=list)

    @property
    def is_leaf(self) -> bool:
        return self.split is None

    def __reduce__(self):
        # the fields by position and the proportions as the class counts they came from
        # (integers; the proportions themselves where they are not counts over
        # n_series): a forest pickles thousands of nodes, the default form is 3-5x longer
        counts = np.rint(self.distribution * self.n_series)
        if self.n_series and np.array_equal(counts / counts.sum(), self.distribution):
            proportions = counts.astype(np.int64).tolist()
        else:
            proportions = self.distribution.tolist()
        return _proximity_node, (proportions, self.n_series, self.depth, self.split,
                                 self.gain, self.children)  # fmt: skip


def _proximity_node(proportions, n_series, depth, split, gain, children) -> ProximityNode:
    """A :class:`ProximityNode` from its pickled form (class counts or proportions)."""
    values = np.asarray(proportions)
    if values.dtype.kind == "i":  # counts, divided as the tree divided them
        values = values / values.sum()
    return ProximityNode(np.asarray(values, dtype=np.float64), n_series, depth, split, gain,
                         children)  # fmt: skip


def best_split(
    node: NodeSeries, splitters: tuple[Splitter, ...], rng: np.random.Generator
) -> tuple[Split, float, np.ndarray]:
    """Of the candidates every splitter draws at ``node`` (``n_candidates`` each, in the
    splitters' order), the one with the largest Gini gain (the first drawn of equal
    gains), its gain, and the branch of every series of the node.

    Once a candidate splits the node perfectly (its gain is the node's impurity: every
    branch pure), no later one can beat it: those are only drawn
    (:meth:`Splitter.skip`), not routed, and the tree is the same."""
    best: tuple[Split, float, np.ndarray] | None = None
    impurity = node.impurity
    for splitter in splitters:
        for _ in range(splitter.n_candidates or 0):
            if best is not None and best[1] >= impurity:
                splitter.skip(node, rng)
                continue
            split, branches = splitter.candidate(node, rng)
            gain = gini_gain(node.codes, branches, split.n_branches, node.n_classes,
                             impurity)  # fmt: skip
            if best is None or gain > best[1]:
                best = split, gain, branches
    assert best is not None  # every splitter draws at least one candidate
    return best


def split_node(
    node: NodeSeries,
    splitters: tuple[Splitter, ...],
    rng: np.random.Generator,
    scoring_sample: int | None = None,
) -> tuple[Split, float, np.ndarray]:
    """The split of ``node``: :func:`best_split` of its series, or, when it holds more
    than ``scoring_sample`` series, :func:`best_split` of a random sample of them, whose
    kept candidate then routes every series of the node. The sample is drawn first:
    ``scoring_sample`` series uniformly without replacement, and one more of every class
    of the node they miss (uniformly among its series, in the classes' order), so that
    every class of the node can be told apart; it is taken in the node's order. Returns
    the split, its Gini gain over the whole node and every series' branch."""
    n = len(node.indices)
    if scoring_sample is None or n <= scoring_sample:
        return best_split(node, splitters, rng)
    picked = rng.choice(n, size=scoring_sample, replace=False)
    missed = np.setdiff1d(node.present, node.codes[picked])
    if len(missed):  # a class too rare to be drawn: one of its series all the same
        extra = [rng.choice(np.flatnonzero(node.codes == c)) for c in missed]
        picked = np.concatenate((picked, extra))
    picked = np.sort(picked)
    sample = NodeSeries(node.training, node.indices[picked], node.codes[picked], node.stores)
    split, _, _ = best_split(sample, splitters, rng)
    branches = split.route(node.series)
    gain = gini_gain(node.codes, branches, split.n_branches, node.n_classes, node.impurity)
    return split, gain, branches


TREE_PARAMETERS = (
    MANIFOLD, SPLITTERS, N_CANDIDATES, REPRESENTATION, EXEMPLARS, MAX_DEPTH, SCORING_SAMPLE,
    RANDOM_STATE,
)  # fmt: skip
TREE_DEFAULTS = {
    "manifold": "euclidean",
    "splitters": None,
    "n_candidates": 5,
    "representation": "auto",
    "exemplars": "series",
    "max_depth": None,
    "scoring_sample": 1000,
    "random_state": None,
}


@declare_parameters(TREE_PARAMETERS, TREE_DEFAULTS)
class ProximityTree(ClassifierMixin, BaseEstimator):
    """One proximity tree: a classifier of its own, and the member of
    :class:`~sk_rtw.RTWProximityForest`.

    Every node draws candidate splits from its splitters (by default two kinds: the
    nearest of one exemplar per class under a manifold-DTW measure drawn at random,
    :class:`~sk_rtw.forest.ElasticSplitter`, and a geodesic dilated shapelet's feature at
    its best threshold, :class:`~sk_rtw.forest.ShapeletSplitter`), keeps the one with the
    largest Gini gain and splits until its leaves are pure. A forest averages many;
    alone, a tree is a quick, readable, high-variance classifier.

    Parameters
    ----------
    %(parameters)s

    Attributes
    ----------
    classes_ : ndarray of shape (n_classes,)
    manifold_ : Manifold
    splitters_ : tuple of Splitter
        The splitters resolved (the tree's values in place of their None).
    representations_ : tuple of str
        The representations the splitters read.
    root_ : ProximityNode
    n_nodes_, n_leaves_, depth_ : int
    n_features_in_ : int
        Time points of the training series, for equal-length univariate data fitted by
        the tree itself.
    scale_ : float
        What the series are divided by before any distance (a power of two for
        magnitudes beyond 1e+-100 on R^d and SPD(k), else 1): the tree is the same at any
        magnitude.
    seconds_ : float
        Time the tree took to grow.

    Examples
    --------
    >>> import numpy as np
    >>> from sk_rtw.forest import ProximityTree
    >>> t = np.linspace(0, 1, 30)
    >>> X = np.stack([np.sin(6 * t + s) for s in (0, 0.1, 0.2)]
    ...              + [np.cos(6 * t + s) for s in (0, 0.1, 0.2)])
    >>> tree = ProximityTree(random_state=0).fit(X, [0, 0, 0, 1, 1, 1])
    >>> tree.predict(X).tolist()
    [0, 0, 0, 1, 1, 1]
    """

    def __init__(
        self,
        manifold: str | Manifold = "euclidean",
        *,
        splitters: tuple[Splitter, ...] | None = None,
        n_candidates: int = 5,
        representation: str = "auto",
        exemplars: str = "series",
        max_depth: int | None = None,
        scoring_sample: int | None = 1000,
        random_state: int | np.random.RandomState | np.random.Generator | None = None,
    ) -> None:
        self.manifold = manifold
        self.splitters = splitters
        self.n_candidates = n_candidates
        self.representation = representation
        self.exemplars = exemplars
        self.max_depth = max_depth
        self.scoring_sample = scoring_sample
        self.random_state = random_state

    def fit(self, X: Any, y: Any) -> ProximityTree:
        """Grow the tree.

        Parameters
        ----------
        X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list
            Training series (a list of ``(T_i, *point_shape)`` arrays for unequal
            lengths); at least 2 time points each where the velocity is read.
        y : array-like of shape (n_series,)
            Labels of at least two classes.

        Returns
        -------
        self
        """
        params = validate_parameters(self)
        data = training_data(type(self).__name__, X, y, params)
        rng = check_generator(params["random_state"])
        self._grow(data.training, data.splitters, data.classes, data.manifold, rng, data.scale)
        if data.n_features is not None:
            self.n_features_in_ = data.n_features
        return self

    def _grow(
        self,
        training: TrainingSet,
        splitters: tuple[Splitter, ...],
        classes: np.ndarray,
        manifold: Manifold,
        rng: np.random.Generator,
        scale: float = 1.0,
    ) -> ProximityTree:
        """Grow on a training set prepared by the caller (a forest prepares it once for
        all its trees, divided by ``scale``), with checked, resolved splitters."""
        start = time.perf_counter()
        codes, n_classes = training.codes, training.n_classes
        stores = training.exemplar_stores()
        counts = np.bincount(codes, minlength=n_classes)
        root = ProximityNode(counts / counts.sum(), len(codes), 0)
        stack = [(root, np.arange(len(codes)))]
        n_nodes, n_leaves, depth = 1, 0, 0
        while stack:
            node, indices = stack.pop()
            depth = max(depth, node.depth)
            pure = np.count_nonzero(node.distribution) == 1
            if pure or (self.max_depth is not None and node.depth >= self.max_depth):
                n_leaves += 1
                continue
            split, gain, branches = split_node(
                NodeSeries(training, indices, codes[indices], stores), splitters, rng,
                self.scoring_sample,
            )
            sizes = np.bincount(branches, minlength=split.n_branches)
            if np.count_nonzero(sizes) < 2:  # no candidate told these series apart
                n_leaves += 1
                continue
            node.split, node.gain = split, gain
            adopt(split)
            for branch in range(split.n_branches):
                members = indices[branches == branch]
                if len(members):
                    counts = np.bincount(codes[members], minlength=n_classes)
                    child = ProximityNode(counts / counts.sum(), len(members), node.depth + 1)
                    stack.append((child, members))
                else:  # its exemplar tied with another class's: the parent's proportions
                    child = ProximityNode(node.distribution, 0, node.depth + 1)
                    n_leaves += 1
                node.children.append(child)
                n_nodes += 1
        for store in stores.values():
            store.compact()  # the exemplars its splits hold, not the training set
        self._stores = stores
        self.root_ = root
        self.n_nodes_, self.n_leaves_, self.depth_ = n_nodes, n_leaves, depth
        self.classes_ = classes
        self.manifold_ = manifold
        self.splitters_ = splitters
        self.representations_ = representations_read(splitters)
        self.scale_ = scale
        self.seconds_ = time.perf_counter() - start
        return self

    def _proba(self, data: SeriesSet, n_series: int) -> np.ndarray:
        """Class proportions of the leaf every series reaches (``data``: the series in
        every representation the splits read)."""
        out = np.empty((n_series, len(self.root_.distribution)))
        stack = [(self.root_, np.arange(n_series))]
        while stack:
            node, indices = stack.pop()
            if node.split is None:
                out[indices] = node.distribution
                continue
            branches = node.split.route(SeriesView(data, indices))
            for branch, child in enumerate(node.children):
                members = indices[branches == branch]
                if len(members):
                    stack.append((child, members))
        return out

    def predict_proba(self, X: Any) -> np.ndarray:
        """Class proportions of the leaf every series reaches.

        Parameters
        ----------
        X : array-like of shape (n_series, n_timepoints[, *point_shape]) or list

        Returns
        -------
        proba : ndarray of shape (n_series, n_classes)
        """
        check_is_fitted(self, "root_")
        data = prepare_representations(X, self.manifold_, self.representations_, self.scale_)
        return self._proba(data, data.n_series)

    def predict(self, X: Any) -> np.ndarray:
        """The class of the largest :meth:`predict_proba` (ties to the first class).

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


@dataclass(frozen=True, eq=False)
class TrainingData:
    """What a tree or a forest grows from: the resolved splitters, the training set in
    the representations they read (divided by ``scale``), the classes, the manifold,
    and the time points of equal-length univariate series (``n_features_in_``)."""

    splitters: tuple[Splitter, ...]
    training: TrainingSet
    classes: np.ndarray
    manifold: Manifold
    scale: float
    n_features: int | None


def training_data(estimator: str, X: Any, y: Any, params: Mapping[str, Any]) -> TrainingData:
    """Checked parameters and training data of a tree or a forest (``estimator`` names
    it in errors), in the form its trees grow from."""
    splitters = resolve_splitters(params)
    representations = representations_read(splitters)
    shortest = 2 if "velocity" in representations else 1
    collection = check_series_collection(X, params["manifold"], min_length=shortest)
    classes, codes = check_classes(estimator, y, collection.n_series)
    unit, scale = unit_frame(collection)
    training = TrainingSet.build(unit, representations, codes, len(classes))
    univariate = collection.equal_length and collection.manifold.point_shape == (1,)
    return TrainingData(splitters, training, classes, collection.manifold, scale,
                        collection.max_length if univariate else None)  # fmt: skip


def prepare_representations(
    X: Any, manifold: Manifold, representations: tuple[str, ...], scale: float
) -> SeriesSet:
    """Series to route: validated on the training ``manifold``, divided by the training
    set's ``scale`` and prepared once in every representation the splits read."""
    shortest = 2 if "velocity" in representations else 1
    collection, _ = unit_frame(check_series_collection(X, manifold, min_length=shortest), scale)
    return SeriesSet.build(collection, representations)
