"""The candidates and the rule of every choice an estimator makes from its training data.

:class:`AutoChoice` is a parameter value (``choice=AutoChoice(...)``), like the grid of
scikit-learn's ``RidgeCV(alphas=...)``: the ``"auto"`` band and centroids
(:mod:`~sk_rtw.estimators._selection`), the ``"auto"`` representation and the
prototype classifier's ``decision="auto"`` all ask it, and nothing else holds a grid.
"""

from __future__ import annotations

import math
from fractions import Fraction
from numbers import Integral, Real
from typing import Any

import numpy as np
from sklearn.base import BaseEstimator

from ..representations import REPRESENTATIONS
from ..utils._constraints import InvalidParameterError, Satisfies
from ..utils._params import Parameter, declare_parameters, validate_parameters


def _is_count(value: Any) -> bool:
    return isinstance(value, Integral) and not isinstance(value, (bool, np.bool_))


def _is_window(value: Any) -> bool:
    return value is None or (
        isinstance(value, Real) and not isinstance(value, (bool, np.bool_))
        and 0.0 <= float(value) <= 1.0
    )  # fmt: skip


def _is_centroids(value: Any) -> bool:
    if _is_count(value):
        return value >= 1
    return (
        isinstance(value, Real) and not isinstance(value, (bool, np.bool_))
        and 0.0 < float(value) <= 1.0
    )  # fmt: skip


def _is_grid(value: Any, member: Any) -> bool:
    if isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
        return False
    values = tuple(value)
    return bool(values) and all(member(v) for v in values)


def _is_prior(value: Any) -> bool:
    if isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
        return False
    values = tuple(value)
    return len(values) == 2 and _is_window(values[0]) and _is_centroids(values[1])


def _is_representations(value: Any) -> bool:
    if not _is_grid(value, lambda v: v in REPRESENTATIONS):
        return False
    return len(set(value)) == len(tuple(value))


def _window(value: Any) -> float | None:
    return None if value is None else float(value)


def _centroids(value: Any) -> int | float:
    return int(value) if _is_count(value) else float(value)


_WINDOWS = Satisfies(
    "sequence of float or None",
    "a non-empty sequence of numbers in [0, 1] or None",
    predicate=lambda v: _is_grid(v, _is_window),
)
_CENTROIDS = Satisfies(
    "sequence of int or float",
    "a non-empty sequence of counts (integers >= 1) or fractions (floats in (0, 1])",
    predicate=lambda v: _is_grid(v, _is_centroids),
)
_PRIOR = Satisfies(
    "(window, centroids)", "a pair (window, centroids) of the kinds above", predicate=_is_prior
)
_REPRESENTATIONS = Satisfies(
    "sequence of str", f"distinct names of {REPRESENTATIONS}", predicate=_is_representations
)
_THRESHOLD = Satisfies(
    "float",
    "a number, inf included (not NaN)",
    predicate=lambda v: isinstance(v, Real) and not isinstance(v, (bool, np.bool_))
    and not math.isnan(float(v)),
)
CHOICE_PARAMETERS = (
    Parameter(
        "windows",
        (_WINDOWS,),
        'Candidate Sakoe-Chiba radii of ``dtw_window="auto"``, fractions of the series '
        "length; None: no band.",
    ),
    Parameter(
        "centroids",
        (_CENTROIDS,),
        'Candidate centroids of ``n_centroids="auto"``: a count per class (an integer), or '
        "a fraction of every class (a float in (0, 1]; 1.0: every series, 1-NN DTW within "
        "the band).",
    ),
    Parameter(
        "prior",
        (_PRIOR,),
        "The choice unless the training data clearly prefer another candidate (scored "
        "beside the grid where it is not on it).",
    ),
    Parameter(
        "z_threshold",
        (_THRESHOLD,),
        "Standard errors by which a candidate must beat the prior on the held-out series "
        "(McNemar's statistic); ``inf`` always keeps the prior.",
    ),
    Parameter(
        "representations",
        (_REPRESENTATIONS,),
        'What ``representation="auto"`` compares, the first being its prior.',
    ),
)
CHOICE_DEFAULTS = {
    "windows": (0.0, 0.05, 0.1, 0.2, None),
    "centroids": (1, 0.125, 0.25, 0.5, 1.0),
    "prior": (None, 0.25),
    "z_threshold": 1.0,
    "representations": REPRESENTATIONS,
}


@declare_parameters(CHOICE_PARAMETERS, CHOICE_DEFAULTS, positional=0)
class AutoChoice(BaseEstimator):
    """What ``"auto"`` chooses from, and how: the candidate bands, centroids and
    representations, the prior and the evidence needed to leave it.

    Pass it as ``choice=`` to :class:`~sk_rtw.RTWNearestCentroid`,
    :class:`~sk_rtw.RTWAverager` or :class:`~sk_rtw.RTWPrototypeClassifier` (None: this
    default). Every candidate is scored by leave-one-out nearest-medoid classification of
    the training series (computed once, scored many times); the prior is kept unless a
    candidate classifies the held-out series better by at least ``z_threshold``
    standard errors of the paired difference (McNemar's statistic). Ties go to fewer
    centroids, then to the narrower band. The same threshold decides the tangent velocity
    over the series (``representation="auto"``) and the prototype classifier's readout
    over the nearest centroid (``decision="auto"``). Its parameters are searchable like
    any nested estimator's (``choice__z_threshold``), or pass several objects to a grid.

    Parameters
    ----------
    %(parameters)s

    See Also
    --------
    sklearn.linear_model.RidgeCV : a candidate grid held as a parameter.

    Notes
    -----
    Why these values: the UCR benchmark page (measured with
    ``benchmarks/studies/candidates.py`` on half A of the development archive and on half C1
    of the large training sets, confirmed on halves B and C2).

    Examples
    --------
    >>> from sk_rtw import AutoChoice, RTWNearestCentroid
    >>> choice = AutoChoice(windows=(0.1, None), centroids=(1, 1.0), z_threshold=2.0)
    >>> clf = RTWNearestCentroid(method="dba", choice=choice)
    >>> AutoChoice().z_threshold
    1.0
    """

    def __init__(
        self,
        *,
        windows: tuple[float | None, ...] = (0.0, 0.05, 0.1, 0.2, None),
        centroids: tuple[int | float, ...] = (1, 0.125, 0.25, 0.5, 1.0),
        prior: tuple[float | None, int | float] = (None, 0.25),
        z_threshold: float = 1.0,
        representations: tuple[str, ...] = REPRESENTATIONS,
    ) -> None:
        self.windows = windows
        self.centroids = centroids
        self.prior = prior
        self.z_threshold = z_threshold
        self.representations = representations

    def checked(self) -> AutoChoice:
        """A copy with every value checked (``ValueError`` naming the rule) and in
        canonical form: tuples, floats for bands and fractions, ints for counts."""
        try:
            values = validate_parameters(self)
        except InvalidParameterError as error:
            raise InvalidParameterError(f"{error} (in {self!r})") from None
        return AutoChoice(
            windows=tuple(_window(w) for w in values["windows"]),
            centroids=tuple(_centroids(k) for k in values["centroids"]),
            prior=(_window(values["prior"][0]), _centroids(values["prior"][1])),
            z_threshold=float(values["z_threshold"]),
            representations=tuple(values["representations"]),
        )

    def candidates(self, window: Any, n_centroids: Any):
        """The bands, the centroids and the prior for the estimator's values (``"auto"``
        or a fixed value, which is then the only candidate of its kind)."""
        windows = self.windows if window == "auto" else (window,)
        counts = self.centroids if n_centroids == "auto" else (n_centroids,)
        prior = (
            self.prior[0] if window == "auto" else window,
            self.prior[1] if n_centroids == "auto" else counts[0],
        )
        return windows, counts, prior

    def prefers(self, z: float) -> bool:
        """True when a candidate ``z`` standard errors better than the prior is chosen."""
        return bool(z >= self.z_threshold)

    def describe(self) -> str:
        """The candidates and the prior in words (rendered into the estimators'
        docstrings from the default, so that they never restate the grid by hand)."""
        bands = [("none" if w is None else f"{w:g}") for w in self.windows]
        counts = [_centroid_words(k) for k in self.centroids]
        window, n_centroids = self.prior
        return (
            f"bands {_listing(bands)} (radii as fractions of the series length), "
            f"centroids per class {_listing(counts)}; the prior is "
            f"{'no band' if window is None else f'band {window:g}'} with "
            f"{_centroid_words(n_centroids)} as centroids, kept unless a candidate is better by "
            f"{self.z_threshold:g} standard error{'' if self.z_threshold == 1 else 's'}"
        )


def _listing(words: list[str]) -> str:
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " or " + words[-1]


def _centroid_words(k: int | float) -> str:
    if _is_count(k):
        return "one" if k == 1 else str(int(k))
    if float(k) == 1.0:
        return "every series"
    fraction = Fraction(float(k)).limit_denominator(64)
    return f"{fraction} of the class" if float(fraction) == float(k) else f"{k:g} of the class"


def mcnemar(candidate: np.ndarray, prior: np.ndarray) -> float:
    """Paired difference of two 0/1 outcome vectors in standard errors (McNemar)."""
    better = int(np.sum(candidate & ~prior))
    worse = int(np.sum(~candidate & prior))
    return (better - worse) / np.sqrt(better + worse) if better + worse else 0.0


#: The choice of an estimator given ``choice=None``.
DEFAULT_CHOICE = AutoChoice()
