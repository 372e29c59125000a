"""Parameters shared by :func:`sk_rtw.align` and the estimators, declared once."""

from __future__ import annotations

from numbers import Integral
from typing import Any

import numpy as np

from ..manifolds import Manifold
from ._params import Boolean, Constant, InstanceOf, Interval, Parameter, Satisfies


def _seed_like(value: Any) -> bool:
    if isinstance(value, (np.random.Generator, np.random.RandomState)):
        return True
    return (
        isinstance(value, Integral)
        and not isinstance(value, (bool, np.bool_))
        and 0 <= int(value) < 2**32
    )


MANIFOLD = Parameter(
    "manifold",
    (InstanceOf((str, Manifold), "str or Manifold", "a manifold name or a Manifold object"),),
    'Space of the samples: a name ("euclidean", "sphere", "quaternion", "spd", "pose") '
    "takes its dimension from the data, or a Manifold object (your own included).",
)
RANDOM_STATE = Parameter(
    "random_state",
    (
        Constant(None),
        Satisfies(
            _seed_like,
            "int, RandomState or Generator",
            "an int in [0, 2**32 - 1], a numpy RandomState or a Generator",
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
            lambda v: isinstance(v, Integral) and not isinstance(v, (bool, np.bool_)) and v != 0,
            "int",
            "a non-zero integer (-1: all cores)",
        ),
    ),
    "Threads of the fit and of the DTW computations, scikit-learn's convention (None: 1, "
    "-1: all cores); more than one only where the problem gains from them, and the "
    "caller's thread settings are restored afterwards.",
)
VERBOSE = Parameter(
    "verbose",
    (Boolean(), Interval(int, 0)),
    "Progress on stderr: 1 (or True) a line per fitted group, 2 also the training loss.",
)
