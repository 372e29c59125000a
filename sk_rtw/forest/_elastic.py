"""The elastic splitter: the nearest of one exemplar per class under a drawn manifold-DTW
measure (Proximity Forest).

Proximity Forest (Lucas et al. 2019) and Proximity Forest 2.0 (Herrmann et al. 2023)
split a node by nearness: a candidate draws a measure and one exemplar per class of the
node, and every series goes to the branch of its nearest exemplar. Here every measure
is manifold DTW (:mod:`sk_rtw.dtw`), drawn as Proximity Forest 2.0 draws its DTW family,
with the values of :class:`ElasticSplitter` (the recipe):

* the representation, uniformly among ``representation``'s: the series (``"raw"``) or
  their tangent velocity (:func:`sk_rtw.tangent_velocity`);
* the point cost, uniformly: the geodesic distance to one of ``exponents``;
* the measure, uniformly among ``measures``: DTW in a Sakoe-Chiba band of radius uniform
  in ``[0, max_window]`` of the length, or amerced DTW without a band, its penalty
  ``(i / penalty_steps) ** penalty_exponent`` times the mean cost of the direct alignment
  of ``penalty_pairs`` random pairs of the node's series, ``i`` uniform in
  ``0..penalty_steps - 1`` (0: DTW without a band);
* the exemplars: one training series per class of the node, uniformly (the published
  choice); or, with ``exemplars="mean"``, the DBA mean (:func:`sk_rtw.baselines.
  dba_average`, in the candidate's band and representation, ``mean_iterations``
  iterations) of a random subset of ``ceil(sqrt(n_c))`` of the class's ``n_c`` series
  (at most ``mean_subset``): a mean with randomness of its own, as a fixed exemplar takes
  the trees' diversity away.

The nearest exemplar is found by the package's nearest search (:func:`sk_rtw.dtw.
nearest_group`: lower bounds, early abandoning, the exhaustive search's answer; a tie
goes to the branch of the lowest class). Proximity Forest 2.0 also draws LCSS, and
samples the penalty's scale once from the whole training set; the scale here is the
node's own.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from numbers import Real
from typing import Any

import numpy as np

from ..baselines import dba_average
from ..dtw import EXPONENTS, PreparedSeries, mean_diagonal_cost, nearest_group, prepare_series
from ..representations import DEPRECATED_BOTH, REPRESENTATION_VALUES, drawn_representations
from ..utils import SeriesCollection, check_series_collection
from ..utils._constraints import Constant, Interval, InvalidParameterError, Options, Satisfies
from ..utils._params import Parameter, declare_parameters, validate_parameters
from ._series import ExemplarStore, NodeSeries
from ._splitter import Splitter

#: The measures a candidate may draw: DTW in a band, amerced DTW without one.
MEASURES = ("dtw", "adtw")
#: Representation values: :data:`~sk_rtw.representations.REPRESENTATION_VALUES` (``"auto"``
#: drawn for every candidate), and the deprecated ``"both"``, the same as ``"auto"``.
REPRESENTATION_OPTIONS = (*REPRESENTATION_VALUES, DEPRECATED_BOTH)
#: Exemplar kinds: a training series per class, or a DBA mean of a subset of it.
EXEMPLAR_KINDS = ("series", "mean")


def _distinct_subset(options: tuple[Any, ...]):
    def check(value: Any) -> bool:
        if isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
            return False
        values = tuple(value)
        if not values or len(set(values)) != len(values):
            return False
        return all(
            not isinstance(v, (bool, np.bool_)) and (isinstance(v, (str, Real)))
            and v in options for v in values
        )  # fmt: skip

    return check


def _count(low: int) -> Interval:
    return Interval(int, low)


ELASTIC_PARAMETERS = (
    Parameter(
        "n_candidates",
        (Constant(None, "the forest's n_candidates"), _count(1)),
        "Candidates of this kind drawn at every node (None: the forest's ``n_candidates``).",
    ),
    Parameter(
        "representation",
        (Constant(None, "the forest's representation"), Options(REPRESENTATION_OPTIONS)),
        'What the measures compare: "raw" the series, "velocity" their tangent velocity, '
        '"auto" drawn for every candidate (None: the forest\'s ``representation``).',
    ),
    Parameter(
        "exemplars",
        (Constant(None, "the forest's exemplars"), Options(EXEMPLAR_KINDS)),
        'Each branch\'s exemplar: "series" a training series of its class, "mean" a DBA '
        "mean of a random subset of it (None: the forest's ``exemplars``).",
    ),
    Parameter(
        "exponents",
        (
            Satisfies(
                "sequence of float",
                f"distinct values of {EXPONENTS}",
                predicate=_distinct_subset(EXPONENTS),
            ),
        ),
        "The point cost is the geodesic distance to one of these powers, drawn uniformly.",
    ),
    Parameter(
        "measures",
        (
            Satisfies(
                "sequence of str",
                f"distinct names of {MEASURES}",
                predicate=_distinct_subset(MEASURES),
            ),
        ),
        '"dtw": DTW in a drawn band; "adtw": amerced DTW without a band, its penalty drawn.',
    ),
    Parameter(
        "max_window",
        (Interval(float, 0.0, 1.0),),
        "The widest Sakoe-Chiba radius drawn for DTW, as a fraction of the length.",
    ),
    Parameter(
        "penalty_steps",
        (_count(1),),
        "Amerced DTW's penalty is ``(i / penalty_steps) ** penalty_exponent`` times the "
        "node's scale, ``i`` uniform in ``0..penalty_steps - 1``.",
    ),
    Parameter(
        "penalty_exponent",
        (Interval(float, 0.0, None, closed="neither"),),
        "The exponent of the penalty grid (large: most penalties small).",
    ),
    Parameter(
        "penalty_pairs",
        (_count(1),),
        "Random pairs of the node's series whose direct alignment gives the penalty's scale.",
    ),
    Parameter(
        "mean_subset",
        (_count(1),),
        'The most series of a class averaged into one exemplar (``exemplars="mean"``).',
    ),
    Parameter(
        "mean_iterations",
        (_count(1),),
        'DBA iterations of a mean exemplar (``exemplars="mean"``).',
    ),
)
ELASTIC_DEFAULTS = {
    "n_candidates": None,
    "representation": None,
    "exemplars": None,
    "exponents": EXPONENTS,
    "measures": MEASURES,
    "max_window": 0.25,
    "penalty_steps": 100,
    "penalty_exponent": 5.0,
    "penalty_pairs": 50,
    "mean_subset": 10,
    "mean_iterations": 5,
}
#: What a None of the splitter takes from the forest.
_INHERITED = ("n_candidates", "representation", "exemplars")


@dataclass(frozen=True)
class Measure:
    """A drawn measure: the representation compared, the Sakoe-Chiba radius (None: no
    band), the point cost's exponent (the geodesic distance to that power), amerced DTW's
    penalty (0: DTW)."""

    representation: str
    window: float | None
    exponent: float
    warp_penalty: float

    def __reduce__(self):
        # its four values alone: a forest pickles thousands (the default is 4x longer)
        return Measure, (self.representation, self.window, self.exponent, self.warp_penalty)

    def __str__(self) -> str:
        name = "DTW" if self.warp_penalty == 0 else f"ADTW (penalty {self.warp_penalty:.3g})"
        band = "no band" if self.window is None else f"band {self.window:.3f}"
        return (
            f"{name} on the {self.representation} series, {band}, point cost the distance "
            f"to the power {self.exponent:g}"
        )


@dataclass(frozen=True, eq=False)
class NearestExemplarSplit:
    """A split by the nearest exemplar: one branch per class of the node.

    Attributes
    ----------
    measure : Measure
    classes : ndarray of int
        The class of each branch (codes into the forest's ``classes_``).
    sources : ndarray of int
        Where each exemplar was drawn from: the index of a training series, or -1 for a
        mean.
    means : PreparedSeries or None
        The exemplars when they are means (held by the split itself).
    store : ExemplarStore or None
        Where training series exemplars are kept (once per forest).
    """

    measure: Measure
    classes: np.ndarray
    sources: np.ndarray
    means: PreparedSeries | None = None
    store: ExemplarStore | None = None

    @property
    def n_branches(self) -> int:
        return len(self.classes)

    @property
    def exemplars(self) -> PreparedSeries:
        """Each branch's exemplar, in the measure's representation, prepared for the
        search."""
        if self.means is not None:
            return self.means
        assert self.store is not None
        return self.store.take(self.sources)

    def __reduce__(self):
        # a few integers as lists: a numpy array of three pickles to about 150 bytes
        return _nearest_exemplar_split, (
            self.measure, self.classes.tolist(), self.sources.tolist(), self.means, self.store,
        )  # fmt: skip

    def adopt(self) -> None:
        """Mark the training series it holds as exemplars in its store (the tree keeps
        this split; :func:`~._splitter.adopt`)."""
        if self.store is not None:
            self.store.keep(self.sources)

    def route(self, series: Mapping[str, PreparedSeries]) -> np.ndarray:
        """The branch of the nearest exemplar of every series (ties to the lowest)."""
        m = self.measure
        return nearest_group(
            series[m.representation], self.exemplars, np.arange(self.n_branches),
            self.n_branches, m.window, m.exponent, m.warp_penalty,
        )  # fmt: skip

    def __str__(self) -> str:
        return f"nearest of {self.n_branches} exemplars by {self.measure}"


def _nearest_exemplar_split(measure, classes, sources, means, store) -> NearestExemplarSplit:
    """A :class:`NearestExemplarSplit` from its pickled form."""
    return NearestExemplarSplit(measure, np.asarray(classes, dtype=np.int64),
                                np.asarray(sources, dtype=np.int64), means, store)  # fmt: skip


@declare_parameters(ELASTIC_PARAMETERS, ELASTIC_DEFAULTS, positional=0)
class ElasticSplitter(Splitter):
    """Proximity Forest's split: the nearest of one exemplar per class under a manifold-DTW
    measure drawn at random (the recipe of the draw as parameters).

    Pass it in ``splitters=`` of :class:`~sk_rtw.RTWProximityForest` (the default forest
    holds ``ElasticSplitter()`` and ``ShapeletSplitter()``; ``[ElasticSplitter()]`` alone
    is Proximity Forest 2.0's elastic forest). Its parameters left as None take the forest's
    (``n_candidates``, ``representation``, ``exemplars``); the others are the measure
    family, Proximity Forest 2.0's DTW family by default: the geodesic distance to the
    power 1/2, 1 or 2, DTW in a band of radius up to a quarter of the length or amerced
    DTW with a penalty from a grid of 100 values. A grid search passes several splitters
    (``{"splitters": [(ElasticSplitter(),), (ElasticSplitter(exponents=(1.0, 2.0)),)]}``).

    Parameters
    ----------
    %(parameters)s

    See Also
    --------
    sk_rtw.RTWProximityForest : the forest that asks it for candidates.

    Examples
    --------
    >>> from sk_rtw import ElasticSplitter, RTWProximityForest
    >>> forest = RTWProximityForest(splitters=(ElasticSplitter(exponents=(1.0, 2.0)),))
    >>> ElasticSplitter().max_window
    0.25
    """

    def __init__(
        self,
        *,
        n_candidates: int | None = None,
        representation: str | None = None,
        exemplars: str | None = None,
        exponents: tuple[float, ...] = EXPONENTS,
        measures: tuple[str, ...] = MEASURES,
        max_window: float = 0.25,
        penalty_steps: int = 100,
        penalty_exponent: float = 5.0,
        penalty_pairs: int = 50,
        mean_subset: int = 10,
        mean_iterations: int = 5,
    ) -> None:
        self.n_candidates = n_candidates
        self.representation = representation
        self.exemplars = exemplars
        self.exponents = exponents
        self.measures = measures
        self.max_window = max_window
        self.penalty_steps = penalty_steps
        self.penalty_exponent = penalty_exponent
        self.penalty_pairs = penalty_pairs
        self.mean_subset = mean_subset
        self.mean_iterations = mean_iterations

    def resolved(self, defaults: Mapping[str, Any]) -> ElasticSplitter:
        try:
            values = validate_parameters(self)
        except InvalidParameterError as error:
            raise InvalidParameterError(f"{error} (in {self!r})") from None
        for name in _INHERITED:
            if values[name] is None:
                values[name] = defaults[name]
        if values["representation"] == DEPRECATED_BOTH:
            drawn_representations(DEPRECATED_BOTH)  # the warning
            values["representation"] = "auto"
        values["exponents"] = tuple(float(e) for e in values["exponents"])
        values["measures"] = tuple(str(m).lower() for m in values["measures"])
        return ElasticSplitter(**values)

    @property
    def representations(self) -> tuple[str, ...]:
        if self.representation is None:
            raise RuntimeError("an unresolved splitter: call resolved() first")
        return drawn_representations(self.representation)

    def draw_measure(self, node: NodeSeries, rng: np.random.Generator) -> Measure:
        """One measure, drawn as the module docstring says."""
        representations = self.representations
        representation = representations[int(rng.integers(len(representations)))]
        exponent = self.exponents[int(rng.integers(len(self.exponents)))]
        if self.measures[int(rng.integers(len(self.measures)))] == "dtw":
            return Measure(representation, float(rng.uniform(0.0, self.max_window)), exponent,
                           0.0)  # fmt: skip
        step = int(rng.integers(self.penalty_steps))
        scale = self._penalty_scale(node, representation, exponent, rng)
        penalty = (step / self.penalty_steps) ** self.penalty_exponent * scale
        return Measure(representation, None, exponent, float(penalty))

    def _penalty_scale(
        self, node: NodeSeries, representation: str, exponent: float, rng: np.random.Generator
    ) -> float:
        """The mean cost of the direct alignment of ``penalty_pairs`` random pairs of
        distinct series of the node (drawn once per node, representation and point cost)."""
        key = ("penalty scale", self.penalty_pairs, representation, exponent)
        if key not in node.memo:
            n, pairs = len(node.indices), self.penalty_pairs
            first = rng.integers(n, size=pairs)
            second = (first + 1 + rng.integers(n - 1, size=pairs)) % n
            node.memo[key] = mean_diagonal_cost(
                node.training.prepared[representation], node.indices[first],
                node.indices[second], exponent,
            )  # fmt: skip
        return node.memo[key]

    def skip(self, node: NodeSeries, rng: np.random.Generator) -> None:
        """The draws of :meth:`draw` alone: the measure, then the exemplars' indices (a
        mean's subsets, not averaged)."""
        self.draw_measure(node, rng)
        if self.exemplars == "mean":
            self._mean_subsets(rng, node.members)
            return
        rng.integers(node.member_counts)

    def draw(self, node: NodeSeries, rng: np.random.Generator) -> NearestExemplarSplit:
        present, members = node.present, node.members
        measure = self.draw_measure(node, rng)
        if self.exemplars == "mean":
            sources, means = self._mean_exemplars(
                rng, members, node.training.collections[measure.representation], measure
            )
            return NearestExemplarSplit(measure, present, sources, means=means)
        # one uniform draw per class: rng.choice(m)'s draw, and one call for all classes
        # draws what a call per class draws, in turn (numpy's stream; a test checks it)
        sources = node.member_series[node.member_starts + rng.integers(node.member_counts)]
        return NearestExemplarSplit(measure, present, sources,
                                    store=node.stores[measure.representation])  # fmt: skip

    def _mean_subsets(
        self, rng: np.random.Generator, members: list[np.ndarray]
    ) -> list[np.ndarray]:
        """The random subset of every class whose mean is its exemplar: about the square
        root of the class's size, at most ``mean_subset`` series, in the classes' order."""
        return [
            rng.choice(indices, size=min(self.mean_subset, math.ceil(math.sqrt(len(indices)))),
                       replace=False)
            for indices in members
        ]  # fmt: skip

    def _mean_exemplars(
        self,
        rng: np.random.Generator,
        members: list[np.ndarray],
        collection: SeriesCollection,
        measure: Measure,
    ) -> tuple[np.ndarray, PreparedSeries]:
        """Each class's exemplar as the DBA mean of a random subset of its series (a class
        subset of one series is that series): sources (-1 for a mean) and the exemplars
        prepared for the search."""
        sources = np.full(len(members), -1, dtype=np.int64)
        series = []
        for b, subset in enumerate(self._mean_subsets(rng, members)):
            if len(subset) == 1:
                sources[b] = subset[0]
                series.append(collection.series(int(subset[0])))
                continue
            mean = dba_average(
                collection.subset(subset), collection.manifold, window=measure.window,
                max_iter=self.mean_iterations,
            ).mean  # fmt: skip
            series.append(mean)
        checked = check_series_collection(series, collection.manifold, name="means",
                                          min_length=1)  # fmt: skip
        return sources, prepare_series(checked)

