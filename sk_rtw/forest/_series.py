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
class TrainingSet:
    """The training series in every representation a forest's splitters read
    (``collections``: validated series, for averaging; ``prepared``: the same in the DTW
    kernels' form, for the searches), with their class codes."""

    collections: Mapping[str, SeriesCollection]
    prepared: Mapping[str, PreparedSeries]
    codes: np.ndarray
    n_classes: int

    @classmethod
    def build(
        cls, collection: SeriesCollection, representations: tuple[str, ...],
        codes: np.ndarray, n_classes: int,
    ) -> TrainingSet:  # fmt: skip
        collections = {r: represent(collection, r) for r in representations}
        prepared = {r: prepare_series(c) for r, c in collections.items()}
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
    """Series ``indices`` of ``data`` per representation, taken the first time a
    representation is read (a split reads one or two of them)."""

    def __init__(self, data: Mapping[str, PreparedSeries], indices: np.ndarray) -> None:
        self._data = data
        self.indices = indices
        self._taken: dict[str, PreparedSeries] = {}

    def __getitem__(self, representation: str) -> PreparedSeries:
        if representation not in self._taken:
            self._taken[representation] = self._data[representation].take(self.indices)
        return self._taken[representation]

    def __iter__(self):
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)

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
        self.series = SeriesView(self.training.prepared, self.indices)

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
