"""Local patterns on any manifold: geodesic dilated shapelets.

Floors, from the bottom: ``_windows`` (windows of series, normalised by the manifold,
in the kernels' form), ``_shapelet`` (a shapelet, how it is drawn, its features, from
:func:`sk_rtw.dtw.shapelet_features`), ``_transform`` (the transformer),
``_classifier`` (the transform read by a ridge classifier). This module is the only
door; the forest's shapelet splits draw and score shapelets through it.
"""

from ._classifier import GeodesicShapeletClassifier
from ._shapelet import FEATURES, Shapelet, ShapeletBank, draw_shapelets, features, profile
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
    "Windows",
    "default_length",
    "draw_shapelets",
    "features",
    "gather_windows",
    "profile",
    "window_space",
]
