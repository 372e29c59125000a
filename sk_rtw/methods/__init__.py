"""Averaging methods as objects holding their settings: RTW, TTW, NTW, DBA, and yours.

``RTWNearestCentroid(method=RTW(hidden_size=64))`` averages each class with RTW and a
width-64 warp network; ``GridSearchCV`` reaches the setting as ``method__hidden_size``.
The names of :data:`METHODS` (``"rtw"``, ``"ttw"``, ``"ntw"``, ``"dba"``) are shorthands
for the objects with every setting ``"auto"`` (the estimator's preset decides). A
subclass of :class:`AveragingMethod` of your own is a ``method=`` value like these.
"""

from .._settings import PRESETS
from ._base import RESULT_FIELDS, AveragingMethod, AveragingResult, FitContext
from ._dba import DBA, DBAConfig
from ._engine import NTW, RTW, TTW, EngineMethod
from ._registry import METHODS, get_method

__all__ = [
    "DBA",
    "METHODS",
    "NTW",
    "PRESETS",
    "RESULT_FIELDS",
    "RTW",
    "TTW",
    "AveragingMethod",
    "AveragingResult",
    "DBAConfig",
    "EngineMethod",
    "FitContext",
    "get_method",
]
