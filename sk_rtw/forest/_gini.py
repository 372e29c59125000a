"""Gini impurity and the gain of a split: what every candidate of a node is scored by."""

from __future__ import annotations

import numpy as np


def gini(codes: np.ndarray, n_classes: int) -> float:
    """Gini impurity of class codes: ``1 - sum_c p_c^2``."""
    if len(codes) == 0:
        return 0.0
    p = np.bincount(codes, minlength=n_classes) / len(codes)
    return float(1.0 - p @ p)


def gini_gain(codes: np.ndarray, branches: np.ndarray, n_branches: int, n_classes: int) -> float:
    """The impurity of ``codes`` less the size-weighted impurity of its branches."""
    table = np.zeros((n_branches, n_classes))
    np.add.at(table, (branches, codes), 1.0)
    sizes = table.sum(1)
    filled = sizes > 0
    children = sizes[filled] - (table[filled] ** 2).sum(1) / sizes[filled]
    return gini(codes, n_classes) - float(children.sum()) / len(codes)
