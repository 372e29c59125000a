"""The series a tree reads: the training set once per representation, and views of a
subset of series taken only for the representations a split asks for."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from ..dtw import PreparedSeries, prepare_series
from ..representations import represent
from ..utils import SeriesCollection
from ._gini import gini


@dataclass(frozen=True, eq=False)
class SeriesSet:
    """Series in every representation the splits read: ``collections`` (validated, as
    points: for averaging and for windows) and ``prepared`` (the same in the DTW
    kernels' form, for the searches)."""

    collections: Mapping[str, SeriesCollection]
    prepared: Mapping[str, PreparedSeries]

    @staticmethod
    def represented(
        collection: SeriesCollection, representations: tuple[str, ...]
    ) -> tuple[dict[str, SeriesCollection], dict[str, PreparedSeries]]:
        collections = {r: represent(collection, r) for r in representations}
        return collections, {r: prepare_series(c) for r, c in collections.items()}

    @classmethod
    def build(cls, collection: SeriesCollection, representations: tuple[str, ...]) -> SeriesSet:
        return cls(*cls.represented(collection, representations))

    @property
    def n_series(self) -> int:
        return next(iter(self.prepared.values())).n_series


class ExemplarStore:
    r"""The training series a tree's splits hold as exemplars, each kept once.

    While the tree grows, :meth:`keep` hands out training series (read from the whole
    training set, prepared); :meth:`compact` then keeps only those, and a forest
    :meth:`rebase`\ s the stores of all its trees onto one shared array of the series
    any of them kept: the fitted forest holds every exemplar once, not the training set.
    """

    def __init__(self, prepared: PreparedSeries) -> None:
        self._full: PreparedSeries | None = prepared
        self._used: set[int] = set()
        self._data: PreparedSeries | None = None
        self._rows = np.empty(0, dtype=np.int64)

    def keep(self, rows: np.ndarray) -> None:
        """Mark training series ``rows`` as held by a split."""
        self._used.update(rows.tolist())

    @property
    def used(self) -> np.ndarray:
        """The training series held, ascending."""
        return np.array(sorted(self._used), dtype=np.int64)

    def take(self, rows: np.ndarray) -> PreparedSeries:
        """Training series ``rows`` (each kept), prepared for the search."""
        if self._data is None:
            assert self._full is not None
            return self._full.take(rows)
        return self._data.take(np.searchsorted(self._rows, rows))

    def compact(self) -> None:
        """Keep only the series handed out."""
        if self._full is not None:
            rows = self.used
            self.rebase(self._full.take(rows), rows)

    def rebase(self, data: PreparedSeries, rows: np.ndarray) -> None:
        """Read from ``data``, the training series ``rows`` (ascending; a superset of the
        ones kept here), from now on."""
        self._data, self._rows, self._full = data, rows, None

    def __getstate__(self) -> dict:
        self.compact()  # never the whole training set in a pickle
        return self.__dict__.copy()


@dataclass(frozen=True, eq=False)
class TrainingSet(SeriesSet):
    """The training series (a :class:`SeriesSet`) with their class codes."""

    codes: np.ndarray
    n_classes: int

    @classmethod
    def build(  # type: ignore[override]
        cls, collection: SeriesCollection, representations: tuple[str, ...],
        codes: np.ndarray, n_classes: int,
    ) -> TrainingSet:  # fmt: skip
        collections, prepared = cls.represented(collection, representations)
        return cls(collections, prepared, np.asarray(codes), int(n_classes))

    def exemplar_stores(self) -> dict[str, ExemplarStore]:
        """Empty exemplar stores, one per representation (a tree's own)."""
        return {r: ExemplarStore(p) for r, p in self.prepared.items()}


def unit_frame(collection: SeriesCollection, scale: float | None = None) -> tuple[
    SeriesCollection, float
]:  # fmt: skip
    """``collection`` divided by ``scale`` (default: the power of two the manifold gives
    for magnitudes beyond 1e+-100, :meth:`~sk_rtw.manifolds.Manifold.extreme_scale`; 1
    for the others), and that scale. On R^d and SPD(k) the forest is then the same at
    any magnitude: a power of two divides exactly, and neither the squared point costs
    nor the amerced penalties overflow or underflow."""
    if scale is None:
        scale = collection.manifold.extreme_scale(collection.data) or 1.0
    if scale == 1.0:
        return collection, 1.0
    return SeriesCollection(collection.data / scale, collection.lengths,
                            collection.manifold), float(scale)  # fmt: skip


class SeriesView(Mapping[str, PreparedSeries]):
    """Series ``indices`` of a :class:`SeriesSet`: ``view[representation]`` in the DTW
    kernels' form, :meth:`collection` as points, each taken the first time it is read (a
    split reads one or two representations)."""

    def __init__(self, series: SeriesSet, indices: np.ndarray) -> None:
        self._series = series
        self.indices = indices
        self._taken: dict[str, PreparedSeries] = {}
        self._collections: dict[str, SeriesCollection] = {}

    def __getitem__(self, representation: str) -> PreparedSeries:
        if representation not in self._taken:
            self._taken[representation] = self._series.prepared[representation].take(
                self.indices
            )
        return self._taken[representation]

    def collection(self, representation: str) -> SeriesCollection:
        """The series in ``representation`` as points of its manifold."""
        if representation not in self._collections:
            self._collections[representation] = self._series.collections[
                representation
            ].subset(self.indices)
        return self._collections[representation]

    def source(self, representation: str) -> tuple[SeriesCollection, np.ndarray]:
        """The whole set's series in ``representation`` (as points) and this view's rows
        of it: for kernels that read the series in place, nothing taken."""
        return self._series.collections[representation], self.indices

    def __iter__(self):
        return iter(self._series.prepared)

    def __len__(self) -> int:
        return len(self._series.prepared)

    @property
    def n_series(self) -> int:
        return len(self.indices)


@dataclass(eq=False)
class NodeSeries:
    """What a node's candidates share: the training set, the node's training
    ``indices`` and class ``codes``, the tree's exemplar stores (``stores``: where a
    split keeps training series it holds), its series per representation (:attr:`series`,
    taken as candidates read them) and a memo where a splitter keeps what every one of
    its candidates at this node would compute again (drawn with the node's generator,
    so at the first candidate that needs it)."""

    training: TrainingSet
    indices: np.ndarray
    codes: np.ndarray
    stores: dict[str, ExemplarStore] = field(default_factory=dict)
    series: SeriesView = field(init=False)
    memo: dict[Any, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.series = SeriesView(self.training, self.indices)
        if not self.stores:  # a node alone: stores of its own
            self.stores = self.training.exemplar_stores()

    @property
    def n_classes(self) -> int:
        return self.training.n_classes

    @cached_property
    def impurity(self) -> float:
        """The Gini impurity of the node's classes."""
        return gini(self.codes, self.n_classes)

    @cached_property
    def present(self) -> np.ndarray:
        """The classes of the node's series, ascending."""
        return np.flatnonzero(np.bincount(self.codes, minlength=self.n_classes))

    @cached_property
    def members(self) -> list[np.ndarray]:
        """The training indices of every present class, in :attr:`present`'s order."""
        return [self.indices[self.codes == c] for c in self.present]

    @cached_property
    def member_series(self) -> np.ndarray:
        """:attr:`members` end to end (class by class, as :attr:`member_starts` and
        :attr:`member_counts` delimit them)."""
        return self.indices[np.argsort(self.codes, kind="stable")].astype(np.int64, copy=False)

    @cached_property
    def member_counts(self) -> np.ndarray:
        """The number of training series of every present class."""
        return np.bincount(self.codes)[self.present]

    @cached_property
    def member_starts(self) -> np.ndarray:
        """Where every present class begins in :attr:`member_series`."""
        return np.concatenate(([0], np.cumsum(self.member_counts)[:-1]))
