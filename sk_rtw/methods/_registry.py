"""The averaging methods by name: the one place that lists them.

``method="rtw"`` in an estimator is ``METHODS["rtw"]()``, the method with every setting
``"auto"``. A method of your own needs no entry: pass its object,
``RTWNearestCentroid(method=MyMethod(...))``.
"""

from __future__ import annotations

from typing import Any

from sklearn.base import clone

from ..utils._constraints import InstanceOf, Satisfies
from ..utils._params import Parameter
from ._base import AveragingMethod
from ._dba import DBA
from ._engine import NTW, RTW, TTW

#: Every averaging method shipped, by name.
METHODS: dict[str, type[AveragingMethod]] = {cls.name: cls for cls in (RTW, TTW, NTW, DBA)}


def _known_name(value: Any) -> bool:
    return isinstance(value, str) and value.lower() in METHODS


def method_parameter(doc: str) -> Parameter:
    """The estimators' ``method`` parameter: a name of :data:`METHODS` or any
    :class:`AveragingMethod` object (a shipped one with settings, or your own)."""
    names = ", ".join(f'"{name}"' for name in METHODS)
    return Parameter(
        "method",
        (
            Satisfies("{" + names + "}", "one of " + names, predicate=_known_name),
            InstanceOf(
                "AveragingMethod", "an AveragingMethod such as RTW()", types=(AveragingMethod,)
            ),
        ),
        doc,
    )


def get_method(method: str | AveragingMethod) -> AveragingMethod:
    """A fresh method object: the method named ``method`` with its defaults, or a clone.

    Parameters
    ----------
    method : str or AveragingMethod
        A key of :data:`METHODS` (any case), or a method object (yours included).

    Returns
    -------
    AveragingMethod
    """
    if isinstance(method, AveragingMethod):
        return clone(method)
    name = method_parameter("").check(method)
    return METHODS[name.lower()]()
