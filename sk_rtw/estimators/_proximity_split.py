"""One node of a proximity tree: candidate splits drawn at random, the best kept by Gini.

Proximity Forest (Lucas et al. 2019) and Proximity Forest 2.0 (Herrmann et al. 2023)
split a node by nearness: a candidate draws a measure and one exemplar per class of the
node, every series of the node goes to the branch of its nearest exemplar, and of ``r``
candidates the one with the largest Gini gain is kept. Here every measure is manifold
DTW (:mod:`sk_rtw.dtw`), drawn as Proximity Forest 2.0 draws its DTW family:

* the representation, uniformly: the series (``"raw"``) or their tangent velocity
  (:func:`sk_rtw.tangent_velocity`, the manifold's derivative series);
* the point cost, uniformly: the geodesic distance to the power 1/2, 1 or 2
  (:data:`COST_EXPONENTS`, Proximity Forest 2.0's cost-function exponents);
* the measure, uniformly: DTW in a Sakoe-Chiba band of radius uniform in
  ``[0, MAX_WINDOW]`` of the length, or amerced DTW without a band, its penalty
  ``(i / PENALTY_STEPS) ** PENALTY_EXPONENT`` times the mean cost of the direct alignment
  of random pairs of the node's series, ``i`` uniform in ``0..PENALTY_STEPS - 1`` (0: DTW
  without a band);
* the exemplars: one training series per class of the node, uniformly (the published
  choice); or, with ``exemplars="mean"``, the DBA mean (:func:`sk_rtw.baselines.
  dba_average`, in the candidate's band and representation) of a random subset of
  ``ceil(sqrt(n_c))`` of the class's ``n_c`` series (at most :data:`MEAN_SUBSET`): a
  mean with randomness of its own, as a fixed exemplar takes the trees' diversity away.

The nearest exemplar is found by the package's nearest search (:func:`sk_rtw.dtw.
nearest_group`: lower bounds, early abandoning, the exhaustive search's answer; a tie
goes to the branch of the lowest class). Proximity Forest 2.0 also draws LCSS, and
samples the penalty's scale once from the whole training set; the scale here is the
node's own.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..baselines import dba_average
from ..dtw import PreparedSeries, mean_diagonal_cost, nearest_group, prepare_series
from ..utils import SeriesCollection, check_series_collection

#: The widest band drawn, as a fraction of the series' length (Proximity Forest's).
MAX_WINDOW = 0.25
#: Amerced DTW's penalties: ``(i / PENALTY_STEPS) ** PENALTY_EXPONENT`` times the scale,
#: ``i`` in ``0..PENALTY_STEPS - 1`` (Proximity Forest 2.0's grid).
PENALTY_STEPS = 100
PENALTY_EXPONENT = 5
#: Random pairs of the node's series whose direct alignment gives the penalty's scale.
PENALTY_PAIRS = 50
#: The most series of a class averaged into one exemplar (``exemplars="mean"``), and the
#: DBA iterations of that mean.
MEAN_SUBSET = 10
MEAN_ITERATIONS = 5
#: The measures drawn: DTW in a band, amerced DTW without one.
MEASURES = ("dtw", "adtw")
#: The point cost is the geodesic distance to one of these powers.
COST_EXPONENTS = (0.5, 1.0, 2.0)


@dataclass(frozen=True)
class Measure:
    """A drawn measure: the representation compared, the Sakoe-Chiba radius (None: no
    band), the point cost's exponent (the geodesic distance to that power), amerced DTW's
    penalty (0: DTW)."""

    representation: str
    window: float | None
    exponent: float
    warp_penalty: float

    def __str__(self) -> str:
        name = "DTW" if self.warp_penalty == 0 else f"ADTW (penalty {self.warp_penalty:.3g})"
        band = "no band" if self.window is None else f"band {self.window:.3f}"
        return (
            f"{name} on the {self.representation} series, {band}, point cost the distance "
            f"to the power {self.exponent:g}"
        )


@dataclass(frozen=True, eq=False)
class Split:
    """The split kept at a node: its measure, the class of each branch, each branch's
    exemplar (a training index, or -1 where it is a mean) and the Gini gain. With mean
    exemplars, ``means`` holds every branch's exemplar prepared for the search."""

    measure: Measure
    classes: np.ndarray
    exemplars: np.ndarray
    means: PreparedSeries | None
    gain: float


def gini(codes: np.ndarray, n_classes: int) -> float:
    """Gini impurity of class codes: ``1 - sum_c p_c^2``."""
    if len(codes) == 0:
        return 0.0
    p = np.bincount(codes, minlength=n_classes) / len(codes)
    return float(1.0 - p @ p)


def gini_gain(codes: np.ndarray, branches: np.ndarray, n_branches: int, n_classes: int) -> float:
    """The impurity of ``codes`` less the size-weighted impurity of its branches."""
    table = np.zeros((n_branches, n_classes))
    np.add.at(table, (branches, codes), 1.0)
    sizes = table.sum(1)
    filled = sizes > 0
    children = sizes[filled] - (table[filled] ** 2).sum(1) / sizes[filled]
    return gini(codes, n_classes) - float(children.sum()) / len(codes)


@dataclass
class NodeSeries:
    """What a node's candidates share: its training indices and class codes, and (filled
    as candidates need them) its series in each representation and the penalty scales."""

    indices: np.ndarray
    codes: np.ndarray
    prepared: dict[str, PreparedSeries] = field(default_factory=dict)
    scales: dict[tuple[str, float], float] = field(default_factory=dict)

    def series(self, data: dict[str, PreparedSeries], representation: str) -> PreparedSeries:
        if representation not in self.prepared:
            self.prepared[representation] = data[representation].take(self.indices)
        return self.prepared[representation]

    def penalty_scale(
        self, data: dict[str, PreparedSeries], representation: str, exponent: float,
        rng: np.random.Generator,
    ) -> float:  # fmt: skip
        """The mean cost of the direct alignment of :data:`PENALTY_PAIRS` random pairs of
        distinct series of the node (drawn once per representation and point cost)."""
        key = (representation, exponent)
        if key not in self.scales:
            n = len(self.indices)
            first = rng.integers(n, size=PENALTY_PAIRS)
            second = (first + 1 + rng.integers(n - 1, size=PENALTY_PAIRS)) % n
            self.scales[key] = mean_diagonal_cost(
                data[representation], self.indices[first], self.indices[second], exponent
            )
        return self.scales[key]


def draw_measure(
    rng: np.random.Generator,
    representations: tuple[str, ...],
    node: NodeSeries,
    data: dict[str, PreparedSeries],
) -> Measure:
    """One measure, drawn as the module docstring says."""
    representation = representations[int(rng.integers(len(representations)))]
    exponent = COST_EXPONENTS[int(rng.integers(len(COST_EXPONENTS)))]
    if MEASURES[int(rng.integers(len(MEASURES)))] == "dtw":
        return Measure(representation, float(rng.uniform(0.0, MAX_WINDOW)), exponent, 0.0)
    step = int(rng.integers(PENALTY_STEPS))
    scale = node.penalty_scale(data, representation, exponent, rng)
    penalty = (step / PENALTY_STEPS) ** PENALTY_EXPONENT * scale
    return Measure(representation, None, exponent, float(penalty))


def _mean_exemplars(
    rng: np.random.Generator,
    members: list[np.ndarray],
    collection: SeriesCollection,
    measure: Measure,
) -> tuple[np.ndarray, PreparedSeries]:
    """Each class's exemplar as the DBA mean of a random subset of its series (a class
    subset of one series is that series): training indices (-1 for a mean) and the
    exemplars prepared for the search."""
    exemplars = np.full(len(members), -1, dtype=np.int64)
    series = []
    for b, indices in enumerate(members):
        size = min(MEAN_SUBSET, math.ceil(math.sqrt(len(indices))))
        subset = rng.choice(indices, size=size, replace=False)
        if size == 1:
            exemplars[b] = subset[0]
            series.append(collection.series(int(subset[0])))
            continue
        mean = dba_average(
            collection.subset(subset), collection.manifold, window=measure.window,
            max_iter=MEAN_ITERATIONS,
        ).mean  # fmt: skip
        series.append(mean)
    checked = check_series_collection(series, collection.manifold, name="means", min_length=1)
    return exemplars, prepare_series(checked)


def best_split(
    rng: np.random.Generator,
    node: NodeSeries,
    data: dict[str, PreparedSeries],
    collections: dict[str, SeriesCollection],
    n_classes: int,
    n_candidates: int,
    representations: tuple[str, ...],
    exemplar_kind: str,
) -> tuple[Split, np.ndarray]:
    """The candidate split of ``node`` with the largest Gini gain (the first drawn of
    equal gains), of ``n_candidates`` drawn, and the branch of every series of the
    node."""
    present = np.flatnonzero(np.bincount(node.codes, minlength=n_classes))
    members = [node.indices[node.codes == c] for c in present]
    best: tuple[Split, np.ndarray] | None = None
    for _ in range(n_candidates):
        measure = draw_measure(rng, representations, node, data)
        if exemplar_kind == "mean":
            exemplars, references = _mean_exemplars(
                rng, members, collections[measure.representation], measure
            )
            means: PreparedSeries | None = references
        else:
            exemplars = np.array([rng.choice(m) for m in members], dtype=np.int64)
            references, means = data[measure.representation].take(exemplars), None
        branches = nearest_group(
            node.series(data, measure.representation), references,
            np.arange(len(present)), len(present), measure.window, measure.exponent,
            measure.warp_penalty,
        )  # fmt: skip
        gain = gini_gain(node.codes, branches, len(present), n_classes)
        if best is None or gain > best[0].gain:
            best = Split(measure, present, exemplars, means, gain), branches
    assert best is not None  # n_candidates >= 1
    return best
