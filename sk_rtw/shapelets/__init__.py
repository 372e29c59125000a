"""Local patterns on any manifold: geodesic dilated shapelets.

Floors, from the bottom: ``_windows`` (windows of series, normalised by the manifold,
in the kernels' form), ``_shapelet`` (a shapelet, how it is drawn, its features, from
:func:`sk_rtw.dtw.shapelet_features`), ``_transform`` (the transformer),
``_classifier`` (the transform read by a ridge classifier); ``_in_place`` (one shapelet
against Euclidean series with their windows read in place, for the forest). This module is the only
door; the forest's shapelet splits draw and score shapelets through it.
"""

from ._classifier import GeodesicShapeletClassifier
from ._in_place import feature_in_place, reads_in_place, take_shapelet
from ._shapelet import (
    FEATURES,
    Shapelet,
    ShapeletBank,
    Sites,
    draw_shapelets,
    draw_site,
    draw_sites,
    features,
    profile,
    take_shapelets,
)
from ._transform import (
    LENGTHS,
    NORMALISED_FRACTION,
    THRESHOLD_PERCENTILES,
    GeodesicShapeletTransform,
    default_length,
)
from ._windows import Windows, gather_windows, window_space

__all__ = [
    "FEATURES",
    "LENGTHS",
    "NORMALISED_FRACTION",
    "THRESHOLD_PERCENTILES",
    "GeodesicShapeletClassifier",
    "GeodesicShapeletTransform",
    "Shapelet",
    "ShapeletBank",
    "Sites",
    "Windows",
    "default_length",
    "draw_shapelets",
    "draw_site",
    "draw_sites",
    "feature_in_place",
    "features",
    "gather_windows",
    "profile",
    "reads_in_place",
    "take_shapelet",
    "take_shapelets",
    "window_space",
]
