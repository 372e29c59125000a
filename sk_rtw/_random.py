"""Random-state handling shared by the engine, the estimators and the data generators."""

from __future__ import annotations

from typing import Any

import numpy as np
from sklearn.utils import check_random_state as _sklearn_check_random_state

RANDOM_STATE_TYPES = "None, an int in [0, 2**32 - 1], a numpy RandomState or a Generator"


def check_random_state_value(random_state: Any) -> None:
    """Raise a clear error unless ``random_state`` is usable as a seed or generator."""
    if random_state is None or isinstance(
        random_state, (np.random.Generator, np.random.RandomState)
    ):
        return
    if isinstance(random_state, bool) or not isinstance(random_state, (int, np.integer)):
        raise TypeError(
            f"random_state must be {RANDOM_STATE_TYPES}; got {type(random_state).__name__}"
        )
    if not 0 <= int(random_state) < 2**32:
        raise ValueError(f"random_state must be {RANDOM_STATE_TYPES}; got {random_state}")


def check_generator(random_state=None) -> np.random.Generator:
    """Turn ``None``, an int, a ``RandomState`` or a ``Generator`` into a ``Generator``."""
    check_random_state_value(random_state)
    if isinstance(random_state, np.random.Generator):
        return random_state
    if isinstance(random_state, np.random.RandomState):
        return np.random.default_rng(random_state.randint(np.iinfo(np.int32).max))
    return np.random.default_rng(random_state)


def check_random_state(random_state=None) -> np.random.RandomState:
    """scikit-learn's ``check_random_state`` (None: numpy's global ``RandomState``; an int:
    a new one seeded with it; a ``RandomState``: itself), plus a ``Generator``: a new
    ``RandomState`` seeded by one draw from it (so a Generator is consumed, as a
    ``RandomState`` is)."""
    check_random_state_value(random_state)
    if isinstance(random_state, np.random.Generator):
        return np.random.RandomState(int(random_state.integers(0, 2**32)))
    return _sklearn_check_random_state(random_state)
