"""What every averaging method is: an object holding its settings, one fit, one result.

The estimators take their averaging method as ``method="rtw"`` (a shorthand) or as an
object, ``method=RTW(hidden_size=64)``: a small scikit-learn parameter container, so
``GridSearchCV`` reaches its settings as ``method__hidden_size`` the way a ``Pipeline``
exposes its steps'. Every setting defaults to ``"auto"``, the preset's value; the preset
itself is the estimator's (one argument for all methods). A method object checks its
settings (:meth:`AveragingMethod.settings`), averages the groups of a stacked collection
(:meth:`AveragingMethod.fit_groups`) and returns one result per group with the fields of
:class:`AveragingResult`.
"""

from __future__ import annotations

from abc import abstractmethod
from dataclasses import dataclass
from typing import Any, ClassVar, Protocol, runtime_checkable

import numpy as np
from sklearn.base import BaseEstimator, clone

from ..align._config import METHOD_LABELS, check_knobs
from ..align._knobs import ENGINE_METHODS, METHODS, method_knobs, owners
from ..manifolds import Manifold
from ..utils import SeriesCollection
from ..utils._params import AUTO, InstanceOf, Options, Parameter


@runtime_checkable
class AveragingResult(Protocol):
    """The fields every method's result has, per averaged group.

    ``mean`` ``(Z, *point_shape)`` on the manifold; ``aligned`` ``(N, Z, *point_shape)``,
    every series resampled on the mean's time axis; ``warps`` ``(N, Z)`` in [0, 1];
    ``cost``, the objective the method minimised at the returned result; ``n_iter``,
    epochs or iterations run; ``config``, the resolved settings; ``manifold``;
    ``fit_time`` in seconds.
    """

    mean: np.ndarray
    aligned: np.ndarray
    warps: np.ndarray
    cost: float
    n_iter: int
    config: Any
    manifold: Manifold
    fit_time: float


#: The fields of :class:`AveragingResult`.
RESULT_FIELDS = ("mean", "aligned", "warps", "cost", "n_iter", "config", "manifold", "fit_time")


@dataclass(frozen=True)
class FitContext:
    """What an estimator tells its method besides the method's own settings.

    Attributes
    ----------
    preset : str
        Name of the preset whose values ``"auto"`` settings take.
    dtw_window : float or None
        Sakoe–Chiba band of the method's DTW (DBA), as a fraction of the series length.
    device : str
        Torch device of the engine's optimisation.
    n_jobs : int or None
        Threads (scikit-learn's convention).
    verbose : int
        2 and more: the engine's loss reports.
    """

    preset: str = "class-means"
    dtw_window: float | None = None
    device: str = "cpu"
    n_jobs: int | None = None
    verbose: int = 0


def _knob_hint(method: str):
    def hint(name: str) -> str:
        others = owners(name)
        label = METHOD_LABELS[method]
        mine = sorted(k.name for k in method_knobs(method))
        if others:
            return (
                f"{name} is a setting of {', '.join(METHOD_LABELS[m] for m in others)}, not "
                f"of {label}; {label}'s settings are {mine}"
            )
        return f"{label}'s settings are {mine}"

    return hint


class AveragingMethod(BaseEstimator):
    """Base of the averaging methods (:class:`RTW`, :class:`TTW`, :class:`NTW`, :class:`DBA`).

    Subclasses are declared with their knobs (:func:`method_class`) and implement
    :meth:`fit_groups`.
    """

    #: Registry name of the method ("rtw", ...).
    name: ClassVar[str] = ""

    def __eq__(self, other: object) -> bool:
        """Value equality, as for manifolds: the same method with the same settings."""
        return type(self) is type(other) and self.get_params() == other.get_params()  # type: ignore[attr-defined]

    def __hash__(self) -> int:
        return hash((type(self), tuple(sorted(self.get_params().items()))))

    def settings(self) -> dict[str, Any]:
        """The settings given explicitly, checked, in canonical form (``"auto"`` dropped).

        Returns
        -------
        dict
            Knob name to value.

        Raises
        ------
        InvalidParameterError
            Naming the setting and what it accepts.
        """
        return check_knobs(self.name, self.get_params(deep=False), owner=type(self).__name__)

    @abstractmethod
    def fit_groups(
        self,
        collection: SeriesCollection,
        codes: np.ndarray,
        seeds: list[int],
        context: FitContext,
        starts: list[np.ndarray] | None = None,
    ) -> list[Any]:
        """Average every group of ``collection``; one :class:`AveragingResult` per group.

        Parameters
        ----------
        collection : SeriesCollection
        codes : ndarray of int, shape (N,)
            Group of every series, ``0..n_groups - 1``, none empty.
        seeds : list of int
            One seed per group.
        context : FitContext
        starts : list of ndarray, optional
            A current average of every group (k-means' previous centroids), for methods
            that iterate from one (DBA); the engine's methods start from their own.

        Returns
        -------
        list
            One result per group, in group order.
        """

    def describe(self, result: Any) -> str:
        """A few words on one fitted group, for the estimators' ``verbose`` lines."""
        return f"cost {result.cost:.4g} after {result.n_iter} iterations"


def method_class(method: str, summary: str):
    """Class decorator: an :class:`AveragingMethod` named ``method`` with its knobs as
    parameters, every one ``"auto"`` by default; the docstring is ``summary`` and the
    knobs' documentation."""
    from ..utils._params import declare_parameters

    knobs = [knob.with_auto() for knob in method_knobs(method)]
    label = METHOD_LABELS[method]
    decorate = declare_parameters(
        knobs, dict.fromkeys((k.name for k in knobs), AUTO), positional=0,
        hint=_knob_hint(method),
    )  # fmt: skip

    where = " or of :func:`sk_rtw.align`" if method in ENGINE_METHODS else ""

    def build(cls):
        cls.name = method
        cls.__doc__ = (
            f"{summary}\n\n    The settings of the {label} averaging of an estimator\n"
            f"    (``RTWNearestCentroid(method={label}(...))``, each searchable as "
            f"``method__<setting>``){where}.\n"
            '    Every setting defaults to ``"auto"``: the value of the preset (see the '
            "presets table\n    of the user guide).\n\n"
            "    Parameters\n    ----------\n    %(parameters)s\n    "
        )
        return decorate(cls)

    return build


def _registry() -> dict[str, type[AveragingMethod]]:
    from ._dba import DBA
    from ._engine import NTW, RTW, TTW

    return {"rtw": RTW, "ttw": TTW, "ntw": NTW, "dba": DBA}


def get_method(method: str | AveragingMethod) -> AveragingMethod:
    """A fresh method object: the class named ``method`` with its defaults, or a clone.

    Parameters
    ----------
    method : {"rtw", "ttw", "ntw", "dba"} or AveragingMethod

    Returns
    -------
    AveragingMethod
    """
    if isinstance(method, AveragingMethod):
        return clone(method)
    name = Parameter("method", (Options(METHODS),), "").check(method)
    return _registry()[name]()


def method_parameter(doc: str) -> Parameter:
    """The estimators' ``method`` parameter: a name or an :class:`AveragingMethod`."""
    return Parameter(
        "method",
        (
            Options(METHODS),
            InstanceOf(
                "AveragingMethod", "an AveragingMethod such as RTW()", types=(AveragingMethod,)
            ),
        ),
        doc,
    )
