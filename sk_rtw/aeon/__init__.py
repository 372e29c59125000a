"""aeon-native entry points: sk_rtw's classifiers as aeon estimators
(:class:`RTWClassifier`, the nearest-centroid classifier; :class:`RTWProximityForestClassifier`,
the proximity forest; :class:`GeodesicShapeletClassifier`, the shapelets).

For researchers who work in aeon (and tsml-eval): data as ``load_classification``
returns them, ``(n_cases, n_channels, n_timepoints)`` or a list of ``(n_channels, T_i)``
arrays, and estimators on aeon's :class:`~aeon.classification.base.BaseClassifier`.
Importing :mod:`sk_rtw` never imports aeon; importing this module needs it
(``pip install 'sk-rtw[aeon]'``).
"""

try:
    import aeon  # noqa: F401
except ImportError as exc:  # pragma: no cover - exercised without aeon only
    raise ImportError(
        "sk_rtw.aeon needs aeon: pip install 'sk-rtw[aeon]' (or use "
        "sk_rtw.RTWNearestCentroid with sk_rtw.utils.from_aeon(X))"
    ) from exc

from ._classifier import RTWClassifier
from ._forest import RTWProximityForestClassifier
from ._shapelets import GeodesicShapeletClassifier

__all__ = ["GeodesicShapeletClassifier", "RTWClassifier", "RTWProximityForestClassifier"]
