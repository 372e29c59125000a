"""What every averaging method is: an object holding its settings, one fit, one result.

The estimators take their averaging method as ``method="rtw"`` (a shorthand) or as an
object, ``method=RTW(hidden_size=64)``: a small scikit-learn parameter container, so
``GridSearchCV`` reaches its settings as ``method__hidden_size`` the way a ``Pipeline``
exposes its steps'. Every setting defaults to ``"auto"``, the preset's value; the preset
itself is the estimator's (one argument for all methods). A method object checks and
resolves its settings once per fit (:meth:`AveragingMethod.configure`: preset, then
method, then the values given), averages the groups of a stacked collection with that
configuration (:meth:`AveragingMethod.fit_groups`) and returns one result per group with
the fields of :class:`AveragingResult`. A method of your own is a subclass with its own
``__init__`` and ``fit_groups`` (see :class:`AveragingMethod`).
"""

from __future__ import annotations

from abc import abstractmethod
from dataclasses import dataclass
from typing import Any, ClassVar, Protocol, runtime_checkable

import numpy as np
from sklearn.base import BaseEstimator

from .._settings import ENGINE_METHODS, method_knobs, owners
from ..manifolds import Manifold
from ..utils import SeriesCollection
from ..utils._constraints import AUTO
from ..utils._params import declare_parameters, validate_parameters


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
        Sakoe–Chiba band of the method's DTW (DBA, the DTW start), as a fraction of the
        series length; an estimator that chooses it from the data configures the method
        with the chosen band (the shipped methods resolve it into their configuration).
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
        label = method.upper()
        mine = sorted(k.name for k in method_knobs(method))
        if others:
            return (
                f"{name} is a setting of {', '.join(m.upper() for m in others)}, not "
                f"of {label}; {label}'s settings are {mine}"
            )
        return f"{label}'s settings are {mine}"

    return hint


class AveragingMethod(BaseEstimator):
    """Base of the averaging methods: :class:`RTW`, :class:`TTW`, :class:`NTW`,
    :class:`DBA`, and yours.

    A method holds its settings as parameters (its written ``__init__`` stores them
    unchanged, scikit-learn's rule), resolves them once per fit (:meth:`configure`) and
    averages groups of series with that configuration (:meth:`fit_groups`). A subclass of
    your own is a ``method=`` value of every estimator like the shipped ones: ``clone``,
    ``get_params`` and ``GridSearchCV`` reach its settings as ``method__<setting>``. It
    writes ``__init__`` and ``fit_groups``; :meth:`configure` by default returns its
    parameters (checked first by the class's declaration, when it has one), and
    :meth:`describe` the result's cost and iterations. See the user guide's "Averaging
    methods" page for a complete example.
    """

    #: Short name of the method ("rtw", ...); a method of your own may leave it empty (its
    #: class name is used in messages and in the estimators' ``method_``).
    name: ClassVar[str] = ""

    @property
    def label(self) -> str:
        """The method's name as the estimators report it (``method_``)."""
        return self.name or type(self).__name__

    def __eq__(self, other: object) -> bool:
        """Value equality, as for manifolds: the same method with the same settings."""
        return type(self) is type(other) and self.get_params() == other.get_params()  # type: ignore[attr-defined]

    def __hash__(self) -> int:
        return hash((type(self), tuple(sorted(map(repr, self.get_params().items())))))

    def check_settings(self) -> None:
        """Check every setting, before a fit does any work (an estimator resolves them
        with :meth:`configure` once it knows the band it uses).

        The default checks the parameters against the class's declaration, when it has
        one; a method of your own may check more here, or leave it to :meth:`configure`.

        Raises
        ------
        InvalidParameterError
            Naming the setting and what it accepts.
        """
        if getattr(type(self), "_declaration", None) is not None:
            validate_parameters(self)

    def configure(self, context: FitContext) -> Any:
        """Check every setting and resolve it, once per fit: the configuration that
        :meth:`fit_groups` receives.

        Parameters
        ----------
        context : FitContext
            The estimator's preset, band, device, threads and verbosity.

        Returns
        -------
        config
            The shipped methods return a frozen record (``AlignmentConfig`` for RTW, TTW
            and NTW, :class:`DBAConfig` for DBA) with every value the fit will use; the
            default returns the parameters by name, canonical where the class declares
            them.

        Raises
        ------
        InvalidParameterError
            Naming the setting and what it accepts.
        """
        if getattr(type(self), "_declaration", None) is not None:
            return validate_parameters(self)
        return self.get_params(deep=False)

    @abstractmethod
    def fit_groups(
        self,
        collection: SeriesCollection,
        codes: np.ndarray,
        seeds: list[int],
        config: Any,
        context: FitContext,
        starts: list[np.ndarray] | None = None,
    ) -> list[Any]:
        """Average every group of ``collection``; one :class:`AveragingResult` per group.

        Parameters
        ----------
        collection : SeriesCollection
            The series of every group (``collection.series(i)``, ``collection.subset``,
            ``collection.manifold``).
        codes : ndarray of int, shape (N,)
            Group of every series, ``0..n_groups - 1``, none empty.
        seeds : list of int
            One seed per group.
        config
            What :meth:`configure` returned for this fit.
        context : FitContext
        starts : list of ndarray, optional
            A current average of every group (k-means' previous centroids), for methods
            that iterate from one (DBA); others may ignore it.

        Returns
        -------
        list
            One result per group, in group order.
        """

    def keeps_single_series(self, config: Any) -> bool:
        """Whether the average of a group of one series is that series, unchanged, under
        ``config``: the estimators then take the series as its group's centroid without
        a fit. False unless a method says so (the shipped ones do where it holds).

        Parameters
        ----------
        config
            What :meth:`configure` returned.

        Returns
        -------
        bool
        """
        return False

    def describe(self, result: Any) -> str:
        """A few words on one fitted group, for the estimators' ``verbose`` lines."""
        return f"cost {result.cost:.4g} after {result.n_iter} iterations"


def method_class(method: str, summary: str):
    """Class decorator: an :class:`AveragingMethod` named ``method`` whose parameters are
    its knobs, every one ``"auto"`` by default (checked against the written
    ``__init__``); the docstring is ``summary`` and the knobs' documentation."""
    knobs = [knob.with_auto() for knob in method_knobs(method)]
    decorate = declare_parameters(
        knobs, dict.fromkeys((k.name for k in knobs), AUTO), positional=0,
        hint=_knob_hint(method),
    )  # fmt: skip
    label = method.upper()
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
