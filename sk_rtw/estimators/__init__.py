"""scikit-learn estimators: class means by time warping, nearest-centroid and prototype
classifiers (the proximity forest is :mod:`sk_rtw.forest`)."""

from ._averager import NTWAverager, RTWAverager, TTWAverager
from ._choice import AutoChoice
from ._classifier import NTWNearestCentroid, RTWNearestCentroid, TTWNearestCentroid
from ._kmeans import RTWKMeans
from ._prototypes import RTWPrototypeClassifier
from ._ridge_readout import RidgeGCVClassifier
from ._velocity import TangentVelocity

__all__ = [
    "AutoChoice",
    "NTWAverager",
    "NTWNearestCentroid",
    "RTWAverager",
    "RTWKMeans",
    "RTWNearestCentroid",
    "RTWPrototypeClassifier",
    "RidgeGCVClassifier",
    "TTWAverager",
    "TTWNearestCentroid",
    "TangentVelocity",
]
