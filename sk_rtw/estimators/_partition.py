"""Every class split into its count of centroids' parts by k-medoids on DTW.

After the choice (:mod:`sk_rtw.estimators._selection`) a class of ``k`` centroids is
split into ``k`` parts, and the averaging method fits every part once. A class the choice
scored whole reuses its k-medoids; a larger one is split in random chunks of at most
:data:`PART_SERIES` series, each with its share of the parts, and the DTW pairs the
choice computed are not computed again.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._random import check_random_state
from ..dtw import dtw_pairwise_distance
from ..utils import SeriesCollection
from ._selection import Selection, candidate_key, class_counts, class_medoids

#: Largest class split into centroids by one k-medoids; larger ones are split in chunks.
PART_SERIES = 500


def partition(
    collection: SeriesCollection,
    codes: np.ndarray,
    n_centroids: int | float,
    window: float | None,
    *,
    selection: Selection | None = None,
    random_state: Any = None,
    n_jobs: int | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Split every class into its count of parts (:func:`class_counts`) by k-medoids on DTW.

    A class of one part needs no DTW, nor does one whose every series is a part. A class
    the selection scored whole reuses its k-medoids; another is split on the DTW matrix
    (band ``window``) of its series, in random chunks of at most :data:`PART_SERIES`
    series (each with its share of the parts) when it is larger; the pairs the selection
    computed (a sampled class in the selection's band) are not computed again.

    Returns
    -------
    groups : ndarray of int, shape (n_series,)
        Part of every series, numbered class by class.
    owners : ndarray of int, shape (n_groups,)
        Class of every part.
    """
    rng = check_random_state(random_state)
    n_classes = int(codes.max()) + 1
    sizes = np.bincount(codes, minlength=n_classes)
    counts = class_counts(n_centroids, sizes)
    key = candidate_key(window, n_centroids)
    reused = None if selection is None else selection.medoids.get(key)
    groups = np.empty(collection.n_series, dtype=np.int64)
    owners: list[int] = []
    for c in range(n_classes):
        members = np.flatnonzero(codes == c)
        k = int(counts[c])
        if k == 1:
            part = np.zeros(len(members), dtype=np.int64)
        elif k == len(members):
            part = np.arange(len(members))
        elif reused is not None and len(reused[c]) == len(members):
            part = reused[c]  # the selection's sample holds the whole class, in order
        else:
            known = None
            if selection is not None and selection.matrices and selection.dtw_window == window:
                seen = np.flatnonzero(np.isin(members, selection.sample))
                known = (seen, selection.matrices[c])
            part = _split(collection, members, k, window, rng, n_jobs, known)
        groups[members] = len(owners) + part
        owners += [c] * k
    return groups, np.asarray(owners, dtype=np.int64)


def _split(
    collection: SeriesCollection,
    members: np.ndarray,
    k: int,
    window: float | None,
    rng: np.random.RandomState,
    n_jobs: int | None,
    known: tuple[np.ndarray, np.ndarray] | None = None,
) -> np.ndarray:
    """k-medoids labels of one class, in chunks of at most :data:`PART_SERIES` series;
    ``known``: positions among ``members`` and their DTW matrix, reused for one chunk."""
    n_chunks = math.ceil(len(members) / PART_SERIES)
    if n_chunks == 1 and known is not None:
        _, labels = class_medoids(_complete(collection, members, known, window, n_jobs), k)
        return labels
    order = np.arange(len(members)) if n_chunks == 1 else rng.permutation(len(members))
    chunks = np.array_split(order, n_chunks)
    shares = _apportion(k, np.array([len(chunk) for chunk in chunks]))
    part = np.empty(len(members), dtype=np.int64)
    offset = 0
    for chunk, share in zip(chunks, shares, strict=True):
        D = dtw_pairwise_distance(collection.subset(members[np.sort(chunk)]), window=window,
                                  n_jobs=n_jobs)  # fmt: skip
        _, labels = class_medoids(D, int(share))
        part[np.sort(chunk)] = offset + labels
        offset += int(share)
    return part


def _complete(
    collection: SeriesCollection,
    members: np.ndarray,
    known: tuple[np.ndarray, np.ndarray],
    window: float | None,
    n_jobs: int | None,
) -> np.ndarray:
    """The DTW matrix of ``members`` from the block ``known`` holds: only the pairs with
    a series outside it are computed."""
    seen, block = known
    rest = np.setdiff1d(np.arange(len(members)), seen)
    D = np.empty((len(members), len(members)))
    D[np.ix_(seen, seen)] = block
    if len(rest):
        outside = collection.subset(members[rest])
        cross = dtw_pairwise_distance(outside, collection.subset(members[seen]),
                                      window=window, n_jobs=n_jobs)  # fmt: skip
        D[np.ix_(rest, seen)] = cross
        D[np.ix_(seen, rest)] = cross.T
        D[np.ix_(rest, rest)] = dtw_pairwise_distance(outside, window=window, n_jobs=n_jobs)
    return D


def _apportion(k: int, sizes: np.ndarray) -> np.ndarray:
    """``k`` parts shared among chunks in proportion to their sizes (largest remainders),
    at least one each."""
    exact = k * sizes / sizes.sum()
    shares = np.maximum(1, np.floor(exact).astype(np.int64))
    for i in np.argsort(-(exact - np.floor(exact)), kind="stable"):
        if shares.sum() >= k:
            break
        shares[i] += 1
    return np.minimum(shares, sizes)
