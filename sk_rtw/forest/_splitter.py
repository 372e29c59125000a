"""The one protocol of every kind of split: a splitter draws candidates, a candidate
routes series.

A :class:`Splitter` is a recipe, a parameter object with defaults (scikit-learn's
``get_params`` and ``clone`` apply; a grid passes several of them): at a node it draws a
candidate :class:`Split` from the node's series (:class:`~._series.NodeSeries`) and the
tree's generator. A split holds what it needs to route (exemplar series prepared, a
shapelet and its threshold), never indices into the training set, and routes series the
same way when the tree grows and when it predicts (:meth:`Split.route`). The tree scores
the candidates by Gini gain and keeps the best (a split that holds training series marks
them when it is kept, its optional ``adopt``); it never asks which kind a split is, so
a new kind is one splitter class and one split class.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping
from typing import Any, Protocol, runtime_checkable

import numpy as np
from sklearn.base import BaseEstimator

from ..dtw import PreparedSeries
from ._series import NodeSeries


@runtime_checkable
class Split(Protocol):
    """A candidate split of a node: ``n_branches`` branches and the rule that sends a
    series to one of them."""

    @property
    def n_branches(self) -> int: ...

    def route(self, series: Mapping[str, PreparedSeries]) -> np.ndarray:
        """The branch (``0..n_branches - 1``) of every series; ``series`` maps a
        representation to the series in it (read only for the representations the split
        compares)."""
        ...


def adopt(split: Split) -> None:
    """Tell ``split`` that a tree keeps it: a split that holds training series (an
    elastic split's exemplars) marks them in its store here (its optional ``adopt``
    method), so that the fitted tree keeps the exemplars of its splits, not of every
    candidate drawn."""
    method = getattr(split, "adopt", None)
    if method is not None:
        method()


class Splitter(BaseEstimator, ABC):
    """A kind of split and its recipe (the base of :class:`ElasticSplitter` and of the
    kinds to come).

    A subclass declares its parameters, may leave ``n_candidates`` and
    ``representation`` as None (then the forest's values apply, :meth:`resolved`),
    implements :meth:`draw`, and may override :meth:`skip` with its random draws alone
    where drawing a candidate computes more than them.
    """

    n_candidates: int | None
    representation: str | None

    @abstractmethod
    def resolved(self, defaults: Mapping[str, Any]) -> Splitter:
        """A checked copy in which every None that means "the forest's value" is
        replaced by ``defaults[name]``."""

    @property
    @abstractmethod
    def representations(self) -> tuple[str, ...]:
        """The representations its candidates read (of a resolved splitter)."""

    @abstractmethod
    def draw(self, node: NodeSeries, rng: np.random.Generator) -> Split:
        """One candidate split of ``node`` (of a resolved splitter)."""

    def skip(self, node: NodeSeries, rng: np.random.Generator) -> None:
        """Make the random draws of one candidate at ``node`` and nothing else: what a
        tree asks for the candidates left once one has split the node perfectly (none
        can beat it), so that every later node draws what it would have drawn and the
        tree is the same, for less work. The default draws the candidate
        (:meth:`draw`) without routing the node's series; a kind whose draw computes
        more than its random choices overrides it with the draws alone."""
        self.draw(node, rng)

    def candidate(
        self, node: NodeSeries, rng: np.random.Generator
    ) -> tuple[Split, np.ndarray]:
        """One candidate and the branch of every series of ``node``: :meth:`draw`, then
        :meth:`Split.route` of the node's series. A kind whose draw already computes the
        branches (a threshold chosen on the node's values) returns them instead of
        routing twice; they must equal what ``route`` gives."""
        split = self.draw(node, rng)
        return split, split.route(node.series)
