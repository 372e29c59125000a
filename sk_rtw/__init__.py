"""sk_rtw: Riemannian Time Warping for scikit-learn.

Align, average and classify time series whose samples live on Riemannian manifolds.
"""

from . import baselines, datasets, forest, methods, metrics, shapelets, statistics

# ``sk_rtw.align`` is the function (the paper's verb, ``sk_rtw.align(X, manifold=...)``):
# as an attribute the name shadows the engine's package, whose records are therefore
# imported from it (``from sk_rtw.align import PRESETS, KNOBS``), not read off the
# function. Renaming either would break every user's first line; the import form works
# for both, and help(sk_rtw.align) shows the function.
from .align import Alignment, align
from .dtw import (
    dtw_cost_matrix,
    dtw_distance,
    dtw_nearest_distance,
    dtw_pairwise_distance,
    dtw_path,
)
from .estimators import (
    AutoChoice,
    NTWAverager,
    NTWNearestCentroid,
    RTWAverager,
    RTWKMeans,
    RTWNearestCentroid,
    RTWPrototypeClassifier,
    TangentVelocity,
    TTWAverager,
    TTWNearestCentroid,
)
from .forest import ElasticSplitter, RTWProximityForest, ShapeletSplitter
from .manifolds import (
    SPD,
    Euclidean,
    Manifold,
    Product,
    Quaternion,
    Sphere,
    available_manifolds,
    check_manifold,
    get_manifold,
)
from .methods import DBA, NTW, RTW, TTW
from .representations import tangent_velocity
from .shapelets import GeodesicShapeletClassifier, GeodesicShapeletTransform
from .statistics import AlignedStatistics, ConfidenceTube, aligned_statistics

__version__ = "0.1.0.dev0"

__all__ = [
    "DBA",
    "NTW",
    "RTW",
    "SPD",
    "TTW",
    "AlignedStatistics",
    "Alignment",
    "AutoChoice",
    "ConfidenceTube",
    "ElasticSplitter",
    "Euclidean",
    "GeodesicShapeletClassifier",
    "GeodesicShapeletTransform",
    "Manifold",
    "NTWAverager",
    "NTWNearestCentroid",
    "Product",
    "Quaternion",
    "RTWAverager",
    "RTWKMeans",
    "RTWNearestCentroid",
    "RTWPrototypeClassifier",
    "RTWProximityForest",
    "ShapeletSplitter",
    "Sphere",
    "TTWAverager",
    "TTWNearestCentroid",
    "TangentVelocity",
    "__version__",
    "align",
    "aligned_statistics",
    "available_manifolds",
    "baselines",
    "check_manifold",
    "datasets",
    "dtw_cost_matrix",
    "dtw_distance",
    "dtw_nearest_distance",
    "dtw_pairwise_distance",
    "dtw_path",
    "forest",
    "get_manifold",
    "methods",
    "metrics",
    "shapelets",
    "statistics",
    "tangent_velocity",
]
