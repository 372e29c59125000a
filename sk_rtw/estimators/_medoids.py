"""k-medoids on a precomputed distance matrix, and leave-one-out nearest-medoid scores.

Several centroids per class start from a partition of each class; the ``"auto"`` band and
number of centroids are scored on held-out series. Both work on one DTW matrix per band,
computed once (:mod:`sk_rtw.estimators._selection`), so that no candidate needs a new DTW:

* :func:`kmedoids` -- deterministic k-medoids: the greedy BUILD of Kaufman and Rousseeuw
  (the series with the least total distance, then each next medoid the one that lowers
  the total distance most), then alternating assignment and medoid updates (Park and
  Jun, 2009) until nothing changes. Ties go to the lowest index, so the same matrix
  always gives the same partition.
* :func:`loo_class_distances` -- every series' distance to the nearest medoid of every
  class, its own class's medoids chosen without it (leave-one-out).
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Rounds of the alternating phase (it stops earlier as soon as no medoid moves).
MAX_ROUNDS = 100


@njit(cache=True, nogil=True)
def _build(D, k):
    n = D.shape[0]
    medoids = np.empty(k, dtype=np.int64)
    totals = D.sum(axis=1)
    medoids[0] = np.argmin(totals)
    nearest = D[medoids[0]].copy()
    chosen = np.zeros(n, dtype=np.bool_)
    chosen[medoids[0]] = True
    for m in range(1, k):
        best, best_gain = -1, -1.0
        for c in range(n):
            if chosen[c]:
                continue
            gain = 0.0
            for j in range(n):
                drop = nearest[j] - D[c, j]
                if drop > 0.0:
                    gain += drop
            if gain > best_gain:
                best, best_gain = c, gain
        medoids[m] = best
        chosen[best] = True
        for j in range(n):
            if D[best, j] < nearest[j]:
                nearest[j] = D[best, j]
    return medoids


@njit(cache=True, nogil=True)
def _assign(D, medoids):
    n, k = D.shape[0], medoids.shape[0]
    labels = np.empty(n, dtype=np.int64)
    for j in range(n):
        best = 0
        for m in range(1, k):
            if D[j, medoids[m]] < D[j, medoids[best]]:
                best = m
        labels[j] = best
    for m in range(k):  # a medoid belongs to its own cluster (duplicates tie)
        labels[medoids[m]] = m
    return labels


@njit(cache=True, nogil=True)
def kmedoids(D: np.ndarray, k: int):
    """Deterministic k-medoids of the points of a distance matrix (module docstring).

    Parameters
    ----------
    D : ndarray of shape (n, n)
        Symmetric distances, zero diagonal.
    k : int
        Clusters, at most ``n``.

    Returns
    -------
    medoids : ndarray of int, shape (k,)
        Row of every cluster's medoid.
    labels : ndarray of int, shape (n,)
        Cluster of every point (its nearest medoid).
    """
    medoids = _build(D, k)
    labels = _assign(D, medoids)
    for _ in range(MAX_ROUNDS):
        moved = False
        for m in range(k):
            best, best_total = medoids[m], np.inf
            for c in range(D.shape[0]):
                if labels[c] != m:
                    continue
                total = 0.0
                for j in range(D.shape[0]):
                    if labels[j] == m:
                        total += D[c, j]
                if total < best_total:
                    best, best_total = c, total
            if best != medoids[m]:
                medoids[m] = best
                moved = True
        if not moved:
            break
        labels = _assign(D, medoids)
    return medoids, labels


@njit(cache=True, nogil=True)
def _submatrix(D, index):
    n = index.shape[0]
    out = np.empty((n, n))
    for a in range(n):
        for b in range(n):
            out[a, b] = D[index[a], index[b]]
    return out


@njit(cache=True, nogil=True)
def loo_class_distances(D: np.ndarray, codes: np.ndarray, n_classes: int, k: int) -> np.ndarray:
    """Distance of every series to the nearest of ``k`` medoids of every class.

    The medoids of a series' own class are chosen without it (leave-one-out); those of
    the other classes from the whole class.

    Parameters
    ----------
    D : ndarray of shape (n, n)
        Distances between the series.
    codes : ndarray of int, shape (n,)
        Class of every series, ``0..n_classes - 1``.
    n_classes : int
    k : int
        Medoids per class (at most the class size; one fewer when a series is left out).

    Returns
    -------
    distances : ndarray of shape (n, n_classes)
        ``inf`` where a class has no medoid (a series alone in its class, left out).
    """
    n = D.shape[0]
    out = np.full((n, n_classes), np.inf)
    for c in range(n_classes):
        members = np.flatnonzero(codes == c)
        size = members.shape[0]
        if size == 0:
            continue
        medoids, _ = kmedoids(_submatrix(D, members), min(k, size))
        chosen = members[medoids]
        for i in range(n):
            if codes[i] == c:
                continue
            for m in chosen:
                if D[i, m] < out[i, c]:
                    out[i, c] = D[i, m]
        if size == 1:
            continue
        rest = np.empty(size - 1, dtype=np.int64)
        for a in range(size):  # leave member a out, choose its class's medoids again
            rest[:a] = members[:a]
            rest[a:] = members[a + 1 :]
            medoids, _ = kmedoids(_submatrix(D, rest), min(k, size - 1))
            i = members[a]
            for m in rest[medoids]:
                if D[i, m] < out[i, c]:
                    out[i, c] = D[i, m]
    return out
