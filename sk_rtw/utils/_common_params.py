"""Parameters shared by :func:`sk_rtw.align` and the estimators, declared once."""

from __future__ import annotations

from numbers import Integral
from typing import Any

import numpy as np
from sklearn.base import is_classifier

from ..manifolds import Manifold
from ._constraints import Boolean, Constant, InstanceOf, Interval, Satisfies
from ._params import Parameter


def _seed_like(value: Any) -> bool:
    if isinstance(value, (np.random.Generator, np.random.RandomState)):
        return True
    return (
        isinstance(value, Integral)
        and not isinstance(value, (bool, np.bool_))
        and 0 <= int(value) < 2**32
    )


def _is_classifier(value: Any) -> bool:
    """A scikit-learn classifier: fit, predict and the classifier tag."""
    if not (hasattr(value, "fit") and hasattr(value, "predict")):
        return False
    try:
        return bool(is_classifier(value))
    except AttributeError:  # no scikit-learn tags
        return False


#: A readout's values: a scikit-learn classifier.
CLASSIFIER = Satisfies(
    "classifier", "a scikit-learn classifier (fit, predict)", predicate=_is_classifier
)
MANIFOLD = Parameter(
    "manifold",
    (
        InstanceOf(
            "str or Manifold", "a manifold name or a Manifold object", types=(str, Manifold)
        ),
    ),
    'Space of the samples: a name ("euclidean", "sphere", "quaternion", "spd", "pose") '
    "takes its dimension from the data, or a Manifold object (your own included).",
)
RANDOM_STATE = Parameter(
    "random_state",
    (
        Constant(None),
        Satisfies(
            "int, RandomState or Generator",
            "an int in [0, 2**32 - 1], a numpy RandomState or a Generator",
            predicate=_seed_like,
        ),
    ),
    "Seeds every random choice of the fit (network initialisation, the DTW start's medoid "
    "candidates, k-means++ seeding): equal seeds give identical results.",
)
N_JOBS = Parameter(
    "n_jobs",
    (
        Constant(None),
        Satisfies(
            "int",
            "a non-zero integer (-1: all cores)",
            predicate=lambda v: (
                isinstance(v, Integral) and not isinstance(v, (bool, np.bool_)) and v != 0
            ),
        ),
    ),
    "Threads of the fit and of the DTW computations, scikit-learn's convention (None: 1, "
    "-1: all cores); more than one only where the problem gains from them, and the "
    "caller's thread settings are restored afterwards. A grid search of a few seconds "
    "is quicker with the estimator's n_jobs=None and the search's workers as threads "
    '(GridSearchCV(..., n_jobs=2) inside joblib.parallel_config(backend="threading"); '
    "the kernels release the GIL): process workers each import torch and scikit-learn "
    "first (user guide: searching in parallel).",
)
VERBOSE = Parameter(
    "verbose",
    (Boolean(), Interval(int, 0)),
    "Progress on stderr: 1 (or True) a line per fitted group, 2 also the training loss.",
)
DTW_WINDOW = Parameter(
    "dtw_window",
    (Interval(float, 0.0, 1.0), Constant(None, "no band")),
    "Sakoe-Chiba band of the DTW, its radius as a fraction of the shorter series' "
    "length; None: no band.",
)
WARP_PENALTY = Parameter(
    "warp_penalty",
    (Interval(float, 0.0),),
    "Amerced DTW's penalty on every step off the diagonal, in the units of the point cost "
    "(0: DTW).",
)
