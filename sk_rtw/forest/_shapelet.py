"""The shapelet splitter: a geodesic dilated shapelet, one of its features and the best
Gini threshold on it (TS-CHIEF's recipe with random dilated shapelets' features).

A candidate draws one shapelet from the node's series as
:class:`~sk_rtw.GeodesicShapeletTransform` draws its shapelets (a representation, a
length, a dilation, a normalisation with probability ``normalised_fraction``, its
occurrence threshold from another series of the node of its class), computes its three
features for every series of the node (the smallest window distance, where it lies,
the occurrences), draws one feature uniformly and splits at the threshold of the largest
Gini gain (the midpoint between two consecutive distinct values): series at or below it
go to the first branch. The split holds the shapelet, the feature and the threshold:
it routes any series by computing that feature. On Euclidean coordinates (the raw series
of R^d, the tangent velocity of any manifold) the shapelet is taken and its feature
computed by kernels that read the windows in place (:mod:`sk_rtw.shapelets._in_place`:
the same numbers as the gathered windows, without gathering them).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..representations import DEPRECATED_BOTH, drawn_representations
from ..shapelets import (
    FEATURES,
    LENGTHS,
    NORMALISED_FRACTION,
    THRESHOLD_PERCENTILES,
    Shapelet,
    ShapeletBank,
    default_length,
    draw_site,
    feature_in_place,
    features,
    reads_in_place,
    take_shapelet,
    take_shapelets,
    window_space,
)
from ..utils._constraints import Constant, Interval, InvalidParameterError, Options, Satisfies
from ..utils._params import Parameter, declare_parameters, validate_parameters
from ._elastic import REPRESENTATION_OPTIONS
from ._gini import best_threshold
from ._series import NodeSeries, SeriesView
from ._splitter import Splitter


def _is_features(value: Any) -> bool:
    if isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
        return False
    values = tuple(value)
    return bool(values) and len(set(values)) == len(values) and all(
        v in FEATURES for v in values
    )


SHAPELET_SPLITTER_PARAMETERS = (
    Parameter(
        "n_candidates",
        (Constant(None, "the forest's n_candidates"), Interval(int, 1)),
        "Shapelet candidates drawn at every node (None: the forest's ``n_candidates``).",
    ),
    Parameter(
        "representation",
        (Constant(None, "the forest's representation"), Options(REPRESENTATION_OPTIONS)),
        'Where shapelets are drawn: "raw", "velocity", "auto" either (None: the forest\'s).',
    ),
    LENGTHS,
    Parameter(
        "normalised_fraction",
        NORMALISED_FRACTION.constraints,
        "Probability that a shapelet compares shape without position (the manifold's "
        "z-normalisation).",
    ),
    Parameter(
        "threshold_percentiles",
        THRESHOLD_PERCENTILES.constraints,
        "A shapelet's occurrence threshold between these percentiles of its distances to "
        "another series of its class at the node.",
    ),
    Parameter(
        "features",
        (
            Satisfies(
                "sequence of str",
                f"distinct names of {FEATURES}",
                predicate=_is_features,
            ),
        ),
        "The features a candidate splits on, one drawn uniformly.",
    ),
)
SHAPELET_SPLITTER_DEFAULTS = {
    "n_candidates": None,
    "representation": None,
    "lengths": None,
    "normalised_fraction": 0.5,
    "threshold_percentiles": (5.0, 10.0),
    "features": FEATURES,
}


@dataclass(frozen=True, eq=False)
class ShapeletSplit:
    """A split by one feature of one shapelet: series whose value is at most
    ``threshold`` go to branch 0, the others to branch 1.

    Attributes
    ----------
    shapelet : Shapelet
    feature : str
        One of ``"min"``, ``"argmin"``, ``"count"``.
    threshold : float
    bank : ShapeletBank or None
        The shapelet in the kernels' form; None where its windows are read in place
        (Euclidean coordinates: :func:`~sk_rtw.shapelets.feature_in_place`).
    """

    shapelet: Shapelet
    feature: str
    threshold: float
    bank: ShapeletBank | None = None

    @property
    def n_branches(self) -> int:
        return 2

    def values(self, series: SeriesView) -> np.ndarray:
        """The shapelet's feature for every series of the view."""
        representation = self.shapelet.representation
        if self.bank is None:
            collection, rows = series.source(representation)
            return feature_in_place(collection, rows, self.shapelet, self.feature)
        collections = {representation: series.collection(representation)}
        return features(collections, self.bank)[:, 0, FEATURES.index(self.feature)]

    def route(self, series: Mapping[str, Any]) -> np.ndarray:
        if not isinstance(series, SeriesView):
            raise TypeError("a shapelet split routes a SeriesView (series as points)")
        return (self.values(series) > self.threshold).astype(np.int64)

    def __str__(self) -> str:
        s = self.shapelet
        kind = "normalised " if s.normalised else ""
        return (
            f"{self.feature} of a {kind}shapelet of {s.length} points at dilation "
            f"{s.dilation} on the {s.representation} series, threshold {self.threshold:.4g}"
        )


@declare_parameters(SHAPELET_SPLITTER_PARAMETERS, SHAPELET_SPLITTER_DEFAULTS, positional=0)
class ShapeletSplitter(Splitter):
    """Splits by a local pattern: one feature of a geodesic dilated shapelet drawn at the
    node, at its best Gini threshold (TS-CHIEF's recipe with RDST's features).

    The default forest (:class:`~sk_rtw.RTWProximityForest`) draws it beside the
    elastic splitter, ``splitters=[ElasticSplitter(), ShapeletSplitter()]``: a node
    keeps the best of elastic and shapelet candidates. Its None values take the
    forest's (``n_candidates``, ``representation``); the shortest training series gives
    the default length.

    Parameters
    ----------
    %(parameters)s

    See Also
    --------
    sk_rtw.GeodesicShapeletTransform : the same shapelets as features.

    Examples
    --------
    >>> from sk_rtw import ElasticSplitter, RTWProximityForest
    >>> from sk_rtw.forest import ShapeletSplitter
    >>> forest = RTWProximityForest(splitters=[ElasticSplitter(), ShapeletSplitter()])
    """

    def __init__(
        self,
        *,
        n_candidates: int | None = None,
        representation: str | None = None,
        lengths: tuple[int, ...] | None = None,
        normalised_fraction: float = 0.5,
        threshold_percentiles: tuple[float, float] = (5.0, 10.0),
        features: tuple[str, ...] = FEATURES,
    ) -> None:
        self.n_candidates = n_candidates
        self.representation = representation
        self.lengths = lengths
        self.normalised_fraction = normalised_fraction
        self.threshold_percentiles = threshold_percentiles
        self.features = features

    def resolved(self, defaults: Mapping[str, Any]) -> ShapeletSplitter:
        try:
            values = validate_parameters(self)
        except InvalidParameterError as error:
            raise InvalidParameterError(f"{error} (in {self!r})") from None
        for name in ("n_candidates", "representation"):
            if values[name] is None:
                values[name] = defaults[name]
        if values["representation"] == DEPRECATED_BOTH:
            drawn_representations(DEPRECATED_BOTH)  # the warning
            values["representation"] = "auto"
        if values["lengths"] is not None:
            values["lengths"] = tuple(int(v) for v in values["lengths"])
        values["threshold_percentiles"] = tuple(float(v) for v in values["threshold_percentiles"])
        values["features"] = tuple(values["features"])
        return ShapeletSplitter(**values)

    @property
    def representations(self) -> tuple[str, ...]:
        if self.representation is None:
            raise RuntimeError("an unresolved splitter: call resolved() first")
        return drawn_representations(self.representation)

    def _lengths(self, node: NodeSeries) -> tuple[int, ...]:
        shortest = min(int(node.training.collections[r].lengths.min())
                       for r in self.representations)  # fmt: skip
        if self.lengths is None:
            return (default_length(shortest),)
        if max(self.lengths) > shortest:
            raise ValueError(
                f"ShapeletSplitter: a shapelet of {max(self.lengths)} points is longer than "
                f"the shortest training series ({shortest} points in the representations "
                "drawn): pass shorter lengths"
            )
        return self.lengths

    def candidate(self, node: NodeSeries, rng: np.random.Generator):
        shapelet, bank = self._shapelet(node, rng)
        feature = self.features[int(rng.integers(len(self.features)))]
        values = ShapeletSplit(shapelet, feature, 0.0, bank).values(node.series)
        threshold, _ = best_threshold(values, node.codes, node.n_classes, node.impurity)
        if not np.isfinite(threshold):  # every value equal: nothing to split
            threshold = float(values[0]) if len(values) else 0.0
        split = ShapeletSplit(shapelet, feature, threshold, bank)
        return split, (values > threshold).astype(np.int64)

    def skip(self, node: NodeSeries, rng: np.random.Generator) -> None:
        """The draws of :meth:`candidate` alone (its site and feature), no shapelet taken
        and no series read."""
        training = node.training
        lengths, shortest, classmates = self._pool(node)
        draw_site(rng, training.collections, training.codes, self.representations, lengths,
                  self.normalised_fraction, node.indices, shortest, classmates)  # fmt: skip
        rng.integers(len(self.features))

    def _shapelet(self, node: NodeSeries, rng: np.random.Generator) -> tuple[
        Shapelet, ShapeletBank | None
    ]:  # fmt: skip
        """One shapelet drawn from the node's series, and its bank (None where its
        windows are read in place): :func:`~sk_rtw.shapelets.draw_shapelets` of one."""
        training = node.training
        lengths, shortest, classmates = self._pool(node)
        sites = draw_site(rng, training.collections, training.codes, self.representations,
                          lengths, self.normalised_fraction, node.indices, shortest,
                          classmates)  # fmt: skip
        name = self.representations[int(sites.representation[0])]
        collection = training.collections[name]
        if reads_in_place(collection.manifold):
            shapelet = take_shapelet(collection, name, sites, 0, training.codes,
                                     self.threshold_percentiles)  # fmt: skip
            return shapelet, None
        (shapelet,) = take_shapelets(sites, training.collections, training.codes,
                                     self.representations, self.threshold_percentiles)  # fmt: skip
        space = window_space(collection.manifold, shapelet.normalised)
        return shapelet, ShapeletBank.build([shapelet], lambda r, normal: space)

    def _pool(self, node: NodeSeries) -> tuple[
        tuple[int, ...], dict[str, int], dict[int, np.ndarray]
    ]:  # fmt: skip
        """What every candidate at ``node`` draws from (kept in its memo): the lengths,
        the shortest series of the node in each representation, its series by class."""
        key = ("shapelet pool", self.representations, self.lengths)
        if key not in node.memo:
            collections = node.training.collections
            shortest = {name: int(collections[name].lengths[node.indices].min())
                        for name in self.representations}  # fmt: skip
            classmates = {int(c): members for c, members in zip(node.present, node.members,
                                                                  strict=True)}  # fmt: skip
            node.memo[key] = self._lengths(node), shortest, classmates
        return node.memo[key]

    def draw(self, node: NodeSeries, rng: np.random.Generator) -> ShapeletSplit:
        split, _ = self.candidate(node, rng)
        return split
