"""Proximity forests: the forest, its tree, and the splitters a node draws from.

Floors, from the bottom: ``_gini`` and ``_series`` (what a node is scored by and the
series it reads) import nothing of the package's forest; ``_splitter`` (the protocol),
then the kinds of split (``_elastic``, ``_shapelet``), ``_params`` (the parameters the tree and the
forest share), ``_tree``, ``_forest``. This module is the only door.
"""

from ._elastic import ElasticSplitter, Measure, NearestExemplarSplit
from ._forest import RTWProximityForest
from ._gini import gini, gini_gain
from ._series import NodeSeries, SeriesSet, SeriesView, TrainingSet
from ._shapelet import ShapeletSplit, ShapeletSplitter
from ._splitter import Split, Splitter
from ._tree import ProximityNode, ProximityTree

__all__ = [
    "ElasticSplitter",
    "Measure",
    "NearestExemplarSplit",
    "NodeSeries",
    "ProximityNode",
    "ProximityTree",
    "RTWProximityForest",
    "SeriesSet",
    "SeriesView",
    "ShapeletSplit",
    "ShapeletSplitter",
    "Split",
    "Splitter",
    "TrainingSet",
    "gini",
    "gini_gain",
]
