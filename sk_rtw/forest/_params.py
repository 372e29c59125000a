"""The parameters a proximity tree and its forest share, declared once, and the
splitters they resolve to."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..representations import REPRESENTATIONS
from ..utils._constraints import Constant, Interval, Options, Satisfies
from ..utils._params import Parameter
from ._elastic import EXEMPLAR_KINDS, REPRESENTATION_OPTIONS, ElasticSplitter
from ._shapelet import ShapeletSplitter
from ._splitter import Splitter


def _is_splitters(value: Any) -> bool:
    if isinstance(value, (str, bytes, Splitter)) or not hasattr(value, "__iter__"):
        return False
    values = tuple(value)
    return bool(values) and all(isinstance(v, Splitter) for v in values)


SPLITTERS = Parameter(
    "splitters",
    (
        Constant(None, "(ElasticSplitter(), ShapeletSplitter())"),
        Satisfies(
            "sequence of Splitter",
            "a non-empty sequence of Splitter objects",
            predicate=_is_splitters,
        ),
    ),
    "The kinds of split a node draws candidates from, each with its recipe (None: "
    "``(ElasticSplitter(), ShapeletSplitter())``, Proximity Forest's elastic candidates "
    "and as many geodesic dilated shapelets, TS-CHIEF's recipe with RDST's features; "
    "``(ElasticSplitter(),)`` is Proximity Forest's alone); a node keeps the candidate of "
    "the largest Gini gain over all of them, the first drawn of equal gains.",
)
N_CANDIDATES = Parameter(
    "n_candidates",
    (Interval(int, 1),),
    "Candidate splits drawn at every node by each splitter that does not set its own, of "
    "which the one with the largest Gini gain is kept (Proximity Forest's r): more "
    "candidates, stronger but less diverse trees.",
)
REPRESENTATION = Parameter(
    "representation",
    (Options(REPRESENTATION_OPTIONS),),
    'What the splits compare, for every splitter that does not set its own: "raw" the '
    'series, "velocity" their tangent velocity (sk_rtw.tangent_velocity: the derivative '
    'series of the manifold), "auto" chosen split by split (drawn for every candidate, '
    'the Gini gain keeps one). "both", its former name, is deprecated.',
)
EXEMPLARS = Parameter(
    "exemplars",
    (Options(EXEMPLAR_KINDS),),
    'Each branch\'s exemplar: "series" one training series of its class, drawn at random '
    '(the published recipe); "mean" the DBA mean of a random subset of the class (about '
    "the square root of its size, at most 10 series): 1.7-3x the fit, and 0.5-1.4 points "
    "less accurate on the UCR page's halves (better on 4 of 30 datasets, worse on 13).",
)
MAX_DEPTH = Parameter(
    "max_depth",
    (Constant(None, "split until every leaf is pure"), Interval(int, 1)),
    "Deepest level of a tree; a node there is a leaf with its class proportions.",
)


SCORING_SAMPLE = Parameter(
    "scoring_sample",
    (Constant(None, "every series of a node scores every candidate"), Interval(int, 2)),
    "At a node of more training series than this, the candidates are drawn from and "
    "scored (Gini gain) on a uniform random sample of this many of its series (and one "
    "series of every class of the node the draw missed), and the "
    "one kept then routes them all: a large node costs one search of all its series "
    "instead of one per candidate. Nodes of at most this many series are split as "
    "without it, so a forest on a training set of at most this many series is the same "
    "as with None, bit for bit. The default 1000 takes the fit of Crop's 7,200 series to "
    "0.69x, ElectricDevices' 8,926 to 0.78x, at the same accuracy (UCR page).",
)


def resolve_splitters(values: Mapping[str, Any]) -> tuple[Splitter, ...]:
    """The splitters of checked parameter ``values``, each resolved against them (its
    None values replaced by the tree's or forest's)."""
    splitters = values["splitters"]
    if splitters is None:
        splitters = (ElasticSplitter(), ShapeletSplitter())
    return tuple(s.resolved(values) for s in splitters)


def representations_read(splitters: tuple[Splitter, ...]) -> tuple[str, ...]:
    """Every representation some splitter reads, in :data:`REPRESENTATIONS`' order."""
    wanted = {r for s in splitters for r in s.representations}
    return tuple(r for r in REPRESENTATIONS if r in wanted)
