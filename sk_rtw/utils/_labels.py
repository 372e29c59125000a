"""Class labels: checked once and encoded once, for every estimator of the package."""

from __future__ import annotations

from typing import Any

import numpy as np
from sklearn.utils import column_or_1d
from sklearn.utils.multiclass import check_classification_targets


def check_labels(y: Any, n_series: int, classification: bool) -> np.ndarray:
    """``y`` as a 1-d array of ``n_series`` labels, or a ``ValueError`` that names the
    problem (a count that does not match the series, a missing or infinite label; for
    ``classification``, a continuous target). Mixed str/number labels are kept as they
    are (an object array)."""
    if isinstance(y, (list, tuple)) and len({isinstance(v, str) for v in y}) > 1:
        y = np.array(y, dtype=object)  # keep mixed str/number labels as they are
    labels = column_or_1d(y, warn=True)
    if len(labels) != n_series:
        raise ValueError(
            f"X has {n_series} series but y has {len(labels)} labels: X holds one series per "
            "row, (n_series, n_timepoints[, *point_shape]), or is a list of series; a "
            "long-format table (one row per sample) must be pivoted first, e.g. "
            "df.pivot(index='series', columns='time', values='value')"
        )
    if labels.dtype == object:
        for i, value in enumerate(labels.tolist()):
            if value is None or (isinstance(value, float) and np.isnan(value)):
                raise ValueError(f"y[{i}] is {value!r}: labels must not be missing (None or NaN)")
    if labels.dtype.kind == "f" and not np.isfinite(labels).all():  # before any cast
        first = int(np.argmax(~np.isfinite(labels)))
        raise ValueError(
            f"y[{first}] is {labels[first]}: labels must not be missing (NaN) or infinite"
        )
    mixed = labels.dtype == object and len({type(v) for v in labels.tolist()}) > 1
    if classification and not mixed:  # scikit-learn cannot sort mixed str/int labels
        check_classification_targets(labels)
    return labels


def encode_labels(labels: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sorted classes and integer codes; mixed label types are sorted by type, then value."""
    try:
        classes, codes = np.unique(labels, return_inverse=True)
        return classes, codes.ravel()
    except TypeError:
        ordered = sorted(set(labels.tolist()), key=lambda v: (type(v).__name__, v))
        classes = np.empty(len(ordered), dtype=object)
        classes[:] = ordered
        lookup = {v: i for i, v in enumerate(ordered)}
        return classes, np.array([lookup[v] for v in labels.tolist()])


def check_classes(
    estimator: str, y: Any, n_series: int, minimum: int = 2
) -> tuple[np.ndarray, np.ndarray]:
    """A classifier's ``y``: checked (:func:`check_labels`), encoded (:func:`encode_labels`)
    and holding at least ``minimum`` classes; ``estimator`` names the caller in errors."""
    if y is None:
        raise ValueError(f"{estimator} requires y to be passed, but the target y is None")
    classes, codes = encode_labels(check_labels(y, n_series, True))
    if len(classes) < minimum:
        raise ValueError(
            f"{estimator} needs at least {minimum} classes in y; got {len(classes)} "
            f"class{'' if len(classes) == 1 else 'es'} ({classes.tolist()})"
        )
    return classes, codes
