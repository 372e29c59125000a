"""scikit-learn estimators: class means by time warping, nearest-centroid classifiers."""

from ._averager import NTWAverager, RTWAverager, TTWAverager
from ._classifier import NTWNearestCentroid, RTWNearestCentroid, TTWNearestCentroid

__all__ = [
    "NTWAverager",
    "NTWNearestCentroid",
    "RTWAverager",
    "RTWNearestCentroid",
    "TTWAverager",
    "TTWNearestCentroid",
]
