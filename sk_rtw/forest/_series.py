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
    ``indices`` and class ``codes``, its series per representation (:attr:`series`,
    taken as candidates read them) and a memo where a splitter keeps what every one of
    its candidates at this node would compute again (drawn with the node's generator,
    so at the first candidate that needs it)."""

    training: TrainingSet
    indices: np.ndarray
    codes: np.ndarray
    series: SeriesView = field(init=False)
    memo: dict[Any, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.series = SeriesView(self.training, self.indices)

    @property
    def n_classes(self) -> int:
        return self.training.n_classes

    @cached_property
    def present(self) -> np.ndarray:
        """The classes of the node's series, ascending."""
        return np.flatnonzero(np.bincount(self.codes, minlength=self.n_classes))

    @cached_property
    def members(self) -> list[np.ndarray]:
        """The training indices of every present class, in :attr:`present`'s order."""
        return [self.indices[self.codes == c] for c in self.present]
