"""Gini impurity and the gain of a split: what every candidate of a node is scored by,
and the best threshold on one value per series (a shapelet split's)."""

from __future__ import annotations

import numpy as np
from numba import njit

from ..dtw import numpy_column_sum


def gini(codes: np.ndarray, n_classes: int) -> float:
    """Gini impurity of class codes: ``1 - sum_c p_c^2``."""
    if len(codes) == 0:
        return 0.0
    p = np.bincount(codes, minlength=n_classes) / len(codes)
    return float(1.0 - p @ p)


def gini_gain(
    codes: np.ndarray,
    branches: np.ndarray,
    n_branches: int,
    n_classes: int,
    impurity: float | None = None,
) -> float:
    """The impurity of ``codes`` less the size-weighted impurity of its branches;
    ``impurity``: :func:`gini` of ``codes``, if known."""
    if len(branches) != len(codes):
        raise ValueError(f"{len(branches)} branches for {len(codes)} class codes")
    if impurity is None:
        impurity = gini(codes, n_classes)
    children = _children_impurity(np.asarray(codes, dtype=np.int64),
                                  np.asarray(branches, dtype=np.int64), int(n_branches),
                                  int(n_classes))  # fmt: skip
    if np.isnan(children):
        raise ValueError(
            f"a branch outside 0..{n_branches - 1} or a class code outside "
            f"0..{n_classes - 1}"
        )
    return float(impurity) - children / len(codes)


@njit(cache=True, nogil=True)
def _children_impurity(codes, branches, n_branches, n_classes):
    """``sum_b (n_b - sum_c n_bc^2 / n_b)`` over the non-empty branches, summed as numpy
    sums that array (its pairwise order; the class counts' squares are whole numbers,
    exact in any order): the value of ``children.sum()`` in the formula it replaces."""
    table = np.zeros((n_branches, n_classes))
    for i in range(codes.shape[0]):
        b, c = branches[i], codes[i]
        if b < 0 or b >= n_branches or c < 0 or c >= n_classes:
            return np.nan  # the caller names the problem
        table[b, c] += 1.0
    children = np.empty((n_branches, 1))
    m = 0
    for b in range(n_branches):
        size = 0.0
        squares = 0.0
        for c in range(n_classes):
            size += table[b, c]
            squares += table[b, c] * table[b, c]
        if size > 0.0:
            children[m, 0] = size - squares / size
            m += 1
    if m == 0:
        return 0.0
    return numpy_column_sum(children, m, 0)


@njit(cache=True, nogil=True)
def _best_cut(values, codes, n_classes, parent):
    """The threshold of the largest Gini gain on ``values`` (the first of equal gains)
    and that gain, ``parent`` the impurity of ``codes``; ``(nan, 0)`` when every value
    is equal. Class counts are whole numbers, so their sums of squares are exact in any
    order: the gains are :func:`best_threshold`'s arithmetic, value for value."""
    n = values.shape[0]
    order = np.argsort(values, kind="mergesort")
    counts = np.zeros(n_classes)
    for i in range(n):
        counts[codes[i]] += 1.0
    left = np.zeros(n_classes)
    left_squares = 0.0
    right_squares = 0.0
    for c in range(n_classes):
        right_squares += counts[c] * counts[c]
    best_gain, best = -np.inf, -1
    for i in range(n - 1):
        c = codes[order[i]]
        left_squares += 2.0 * left[c] + 1.0
        left[c] += 1.0
        right_squares -= 2.0 * (counts[c] - left[c]) + 1.0
        if values[order[i + 1]] > values[order[i]]:  # a cut after position i
            n_left = i + 1.0
            n_right = n - n_left
            impurity = (n_left - left_squares / n_left) + (n_right - right_squares / n_right)
            gain = parent - impurity / n
            if gain > best_gain:
                best_gain, best = gain, i
    if best < 0:
        return np.nan, 0.0
    return 0.5 * (values[order[best]] + values[order[best + 1]]), best_gain


def best_threshold(
    values: np.ndarray, codes: np.ndarray, n_classes: int, impurity: float | None = None
) -> tuple[float, float]:
    """The threshold of the largest Gini gain on ``values`` (a midpoint between two
    consecutive distinct values; the first of equal gains) and that gain; ``(nan, 0)``
    when the values are all equal. ``impurity``: :func:`gini` of ``codes``, if known."""
    if impurity is None:
        impurity = gini(codes, n_classes)
    threshold, gain = _best_cut(np.ascontiguousarray(values, dtype=np.float64),
                                np.asarray(codes, dtype=np.int64), int(n_classes),
                                float(impurity))  # fmt: skip
    return float(threshold), float(gain)
