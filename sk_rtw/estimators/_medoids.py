"""k-medoids on a precomputed distance matrix, and leave-one-out nearest-medoid scores.

Several centroids per class start from a partition of each class; the ``"auto"`` band and
number of centroids are scored on held-out series. Both work on one DTW matrix per class
and band, computed once (:mod:`sk_rtw.estimators._selection`):

* :func:`kmedoids` -- deterministic k-medoids: the greedy BUILD of Kaufman and Rousseeuw
  (the series with the least total distance, then each next medoid the one that lowers
  the total distance most), then alternating assignment and medoid updates (Park and
  Jun, 2009) until nothing changes. Ties go to the lowest index, so the same matrix
  always gives the same partition.
* :func:`held_out_distances` -- every series' distance to the nearest medoid of its own
  class, itself left out (a medoid is replaced in its cluster).
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
def held_out_distances(D: np.ndarray, medoids: np.ndarray, labels: np.ndarray) -> np.ndarray:
    """Distance of every point of a class to the nearest of its class's medoids, itself
    left out.

    A point that is not a medoid keeps the class's medoids; a medoid is left out of its
    cluster, whose medoid becomes the member that minimises the total distance to the
    cluster's other members (none if the cluster held only the point). With one medoid
    per point this is exact leave-one-out 1-NN; refitting k-medoids without every point
    (``n`` fits of ``O(k n^2)``) would be too costly for the classes of large training
    sets, where the candidates reach every series.

    Parameters
    ----------
    D : ndarray of shape (n, n)
        Distances between the points of one class.
    medoids, labels : ndarray of int
        :func:`kmedoids` of ``D``.

    Returns
    -------
    distances : ndarray of shape (n,)
        ``inf`` for a point alone in its class.
    """
    n, k = D.shape[0], medoids.shape[0]
    is_medoid = np.full(n, -1, dtype=np.int64)
    for m in range(k):
        is_medoid[medoids[m]] = m
    out = np.full(n, np.inf)
    for i in range(n):
        own = is_medoid[i]
        for m in range(k):
            if m != own and D[i, medoids[m]] < out[i]:
                out[i] = D[i, medoids[m]]
        if own < 0:
            continue
        best, best_total = -1, np.inf  # the cluster's medoid without i
        for c in range(n):
            if c == i or labels[c] != own:
                continue
            total = 0.0
            for j in range(n):
                if j != i and labels[j] == own:
                    total += D[c, j]
            if total < best_total:
                best, best_total = c, total
        if best >= 0 and D[i, best] < out[i]:
            out[i] = D[i, best]
    return out
