"""Averaging methods as objects holding their settings: RTW, TTW, NTW and DBA.

``RTWNearestCentroid(method=RTW(hidden_size=64))`` averages each class with RTW and a
width-64 warp network; ``GridSearchCV`` reaches the setting as ``method__hidden_size``.
The names ``"rtw"``, ``"ttw"``, ``"ntw"``, ``"dba"`` are shorthands for the objects with
every setting ``"auto"`` (the estimator's preset decides).
"""

from ._base import RESULT_FIELDS, AveragingMethod, AveragingResult, FitContext, get_method
from ._dba import DBA, DBAConfig
from ._engine import NTW, RTW, TTW, EngineMethod

__all__ = [
    "DBA",
    "NTW",
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
