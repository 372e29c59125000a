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
it routes any series by computing that feature.
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
    draw_shapelets,
    features,
    window_space,
)
from ..utils._constraints import Constant, Interval, InvalidParameterError, Options, Satisfies
from ..utils._params import Parameter, declare_parameters, validate_parameters
from ._elastic import REPRESENTATION_OPTIONS
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
    """

    shapelet: Shapelet
    feature: str
    threshold: float
    bank: ShapeletBank

    @property
    def n_branches(self) -> int:
        return 2

    def values(self, series: SeriesView) -> np.ndarray:
        """The shapelet's feature for every series of the view."""
        collections = {self.shapelet.representation: series.collection(
            self.shapelet.representation)}  # fmt: skip
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


def best_threshold(values: np.ndarray, codes: np.ndarray, n_classes: int) -> tuple[float, float]:
    """The threshold of the largest Gini gain on ``values`` (a midpoint between two
    consecutive distinct values; the first of equal gains) and that gain; ``(nan, 0)``
    when the values are all equal."""
    order = np.argsort(values, kind="stable")
    ordered, labels = values[order], codes[order]
    n = len(values)
    cuts = np.flatnonzero(ordered[1:] > ordered[:-1])  # split after position cut
    if len(cuts) == 0:
        return float("nan"), 0.0
    counts = np.bincount(labels, minlength=n_classes)
    left = np.cumsum(np.eye(n_classes)[labels], axis=0)[cuts]
    right = counts - left
    n_left = cuts + 1.0
    n_right = n - n_left
    total = counts / n
    parent = 1.0 - total @ total
    impurity = (n_left - (left**2).sum(1) / n_left) + (n_right - (right**2).sum(1) / n_right)
    gains = parent - impurity / n
    best = int(np.argmax(gains))
    cut = cuts[best]
    return float(0.5 * (ordered[cut] + ordered[cut + 1])), float(gains[best])


@declare_parameters(SHAPELET_SPLITTER_PARAMETERS, SHAPELET_SPLITTER_DEFAULTS, positional=0)
class ShapeletSplitter(Splitter):
    """Splits by a local pattern: one feature of a geodesic dilated shapelet drawn at the
    node, at its best Gini threshold (TS-CHIEF's recipe with RDST's features).

    Pass it with the elastic splitter in ``splitters=`` of
    :class:`~sk_rtw.RTWProximityForest`: a node then keeps the best of elastic and
    shapelet candidates. Its None values take the forest's (``n_candidates``,
    ``representation``); the shortest training series gives the default length.

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
        training = node.training
        (shapelet,) = draw_shapelets(
            rng, 1, training.collections, training.codes, self.representations,
            self._lengths(node), self.normalised_fraction, self.threshold_percentiles,
            candidates=node.indices,
        )  # fmt: skip
        feature = self.features[int(rng.integers(len(self.features)))]
        space = window_space(training.collections[shapelet.representation].manifold,
                             shapelet.normalised)  # fmt: skip
        bank = ShapeletBank.build([shapelet], lambda r, normal: space)
        split = ShapeletSplit(shapelet, feature, 0.0, bank)
        values = split.values(node.series)
        threshold, _ = best_threshold(values, node.codes, node.n_classes)
        if not np.isfinite(threshold):  # every value equal: nothing to split
            threshold = float(values[0]) if len(values) else 0.0
        split = ShapeletSplit(shapelet, feature, threshold, bank)
        return split, (values > threshold).astype(np.int64)

    def draw(self, node: NodeSeries, rng: np.random.Generator) -> ShapeletSplit:
        split, _ = self.candidate(node, rng)
        return split
