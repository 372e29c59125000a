"""A proximity tree: nodes split by the nearest of one exemplar per class.

A tree is grown from a seed of its own (the forest draws every tree's seed before any
work, so a forest's result does not depend on how many threads build it) on series
prepared once by the forest (:func:`sk_rtw.dtw.prepare_series`, one
:class:`~sk_rtw.dtw.PreparedSeries` per representation). A node splits by
:func:`~._proximity_split.best_split` until its series are of one class; a node whose
best split leaves every series in one branch (series that no measure drawn tells apart),
or that reaches ``max_depth``, becomes a leaf with its class proportions. A branch that
receives no training series (its exemplar tied at distance 0 with another class's) is a
leaf with its parent's proportions.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..dtw import PreparedSeries, nearest_group
from ..utils import SeriesCollection
from ._proximity_split import Measure, NodeSeries, Split, best_split


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
        None for a leaf. Otherwise its :attr:`measure`, the class of each branch
        (``split.classes``, codes into the forest's ``classes_``), each branch's exemplar
        (``split.exemplars``: the index of a training series, or -1 where the exemplar is
        a mean, held in ``split.means``) and the Gini gain.
    children : list of ProximityNode
        One per branch, in the order of ``split.classes``.
    """

    distribution: np.ndarray
    n_series: int
    depth: int
    split: Split | None = None
    children: list[ProximityNode] = field(default_factory=list)

    @property
    def is_leaf(self) -> bool:
        return self.split is None

    @property
    def measure(self) -> Measure | None:
        """The split's measure (None for a leaf)."""
        return None if self.split is None else self.split.measure


class ProximityTree:
    """One tree of :class:`~sk_rtw.RTWProximityForest`, grown from its own seed.

    Parameters
    ----------
    n_candidates : int
        Candidate splits drawn at every node.
    representations : tuple of str
        The representations a candidate draws from.
    exemplars : {"series", "mean"}
        One training series per class, or a DBA mean of a random subset of the class.
    max_depth : int or None
        Nodes at this depth become leaves (None: split until pure).
    seed : int
        The tree's random seed.

    Attributes
    ----------
    root_ : ProximityNode
    n_nodes_, n_leaves_, depth_ : int
    """

    def __init__(
        self,
        n_candidates: int,
        representations: tuple[str, ...],
        exemplars: str,
        max_depth: int | None,
        seed: int,
    ) -> None:
        self.n_candidates = n_candidates
        self.representations = representations
        self.exemplars = exemplars
        self.max_depth = max_depth
        self.seed = seed

    def fit(
        self,
        data: dict[str, PreparedSeries],
        collections: dict[str, SeriesCollection],
        codes: np.ndarray,
        n_classes: int,
    ) -> ProximityTree:
        """Grow the tree on the training series (``data``: prepared per representation;
        ``collections``: the same series, for means) with class ``codes``."""
        rng = np.random.default_rng(self.seed)
        counts = np.bincount(codes, minlength=n_classes)
        self.root_ = ProximityNode(counts / counts.sum(), len(codes), 0)
        stack = [(self.root_, np.arange(len(codes)))]
        n_nodes, n_leaves, depth = 1, 0, 0
        while stack:
            node, indices = stack.pop()
            depth = max(depth, node.depth)
            node_codes = codes[indices]
            pure = np.count_nonzero(node.distribution) == 1
            if pure or (self.max_depth is not None and node.depth >= self.max_depth):
                n_leaves += 1
                continue
            split, branches = best_split(
                rng, NodeSeries(indices, node_codes), data, collections, n_classes,
                self.n_candidates, self.representations, self.exemplars,
            )  # fmt: skip
            sizes = np.bincount(branches, minlength=len(split.classes))
            if np.count_nonzero(sizes) < 2:  # no measure drawn told these series apart
                n_leaves += 1
                continue
            node.split = split
            for branch in range(len(split.classes)):
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
        self.n_nodes_, self.n_leaves_, self.depth_ = n_nodes, n_leaves, depth
        return self

    def predict_proba(
        self, data: dict[str, PreparedSeries], train: dict[str, PreparedSeries]
    ) -> np.ndarray:
        """Class proportions of the leaf every series reaches (``data``: the series
        prepared per representation; ``train``: the training series the tree was grown
        on, whose exemplars it reads)."""
        n = next(iter(data.values())).n_series
        out = np.empty((n, len(self.root_.distribution)))
        stack = [(self.root_, np.arange(n))]
        while stack:
            node, indices = stack.pop()
            if node.split is None:
                out[indices] = node.distribution
                continue
            split = node.split
            measure = split.measure
            references = split.means
            if references is None:
                references = train[measure.representation].take(split.exemplars)
            branches = nearest_group(
                data[measure.representation].take(indices), references,
                np.arange(len(split.classes)), len(split.classes), measure.window,
                measure.exponent, measure.warp_penalty,
            )  # fmt: skip
            for branch, child in enumerate(node.children):
                members = indices[branches == branch]
                if len(members):
                    stack.append((child, members))
        return out
