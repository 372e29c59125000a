"""scikit-learn estimators: class means by time warping, nearest-centroid classifiers."""

from ._averager import NTWAverager, RTWAverager, TTWAverager
from ._classifier import NTWNearestCentroid, RTWNearestCentroid, TTWNearestCentroid
from ._kmeans import RTWKMeans

__all__ = [
    "NTWAverager",
    "NTWNearestCentroid",
    "RTWAverager",
    "RTWKMeans",
    "RTWNearestCentroid",
    "TTWAverager",
    "TTWNearestCentroid",
]
