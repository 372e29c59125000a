"""The numerical core of the estimators: centroids of groups of series, and k-means.

Class means (:class:`RTWAverager`), several centroids per class and clustering
(:class:`RTWKMeans`) all reduce to two functions here, fed one checked method object
(:mod:`sk_rtw.methods`) and one :class:`~sk_rtw.methods.FitContext`:

* :func:`fit_centroids` -- one centroid per group of a stacked collection, by the
  method's :meth:`~sk_rtw.methods.AveragingMethod.fit_groups` (the engine's methods
  solve all groups in one optimisation; DBA averages group by group). The groups are
  the classes, or the parts of every class (:func:`~sk_rtw.estimators._partition.partition`);
* :func:`kmeans` -- Lloyd's iterations with manifold DTW for independent clustering
  problems in lockstep (:class:`RTWKMeans`): each round fits the centroids of every
  cluster of every unfinished problem in one :func:`fit_centroids` call.

The estimators validate, resolve their settings and store the results; nothing is
averaged or scored by a second implementation. A group of one series is its own centroid
(:class:`SeriesCentroid`) where the method's average of one series is that series
(:meth:`~sk_rtw.methods.AveragingMethod.keeps_single_series`).
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..dtw import dtw_pairwise_distance
from ..methods import AveragingMethod, FitContext
from ..utils import SeriesCollection, check_series_collection


def _label(name: Any) -> Any:
    return name.item() if isinstance(name, np.generic) else name


@dataclass(frozen=True, eq=False)
class SeriesCentroid:
    """The centroid of a group of one series: the series itself, nothing averaged.

    The fields of :class:`~sk_rtw.methods.AveragingResult`: ``aligned`` is the series,
    ``warps`` the identity, ``cost`` 0, ``n_iter`` 0; ``config`` is the method's
    configuration (:meth:`~sk_rtw.methods.AveragingMethod.configure`), which did not run.
    """

    mean: np.ndarray
    aligned: np.ndarray
    warps: np.ndarray
    config: Any
    manifold: Any
    cost: float = 0.0
    n_iter: int = 0
    fit_time: float = 0.0

    @classmethod
    def of(cls, series: np.ndarray, config: Any, manifold: Any) -> SeriesCentroid:
        return cls(series, series[None], np.linspace(0.0, 1.0, len(series))[None], config,
                   manifold)  # fmt: skip


def fit_centroids(
    method: AveragingMethod,
    config: Any,
    collection: SeriesCollection,
    codes: np.ndarray,
    seeds: list[int],
    context: FitContext,
    *,
    names: list[Any] | None = None,
    kind: str = "group",
    owner: str = "RTWAverager",
    starts: list[np.ndarray] | None = None,
) -> list[Any]:
    """One centroid per group of ``collection`` (``codes``: group of every series).

    Parameters
    ----------
    method : AveragingMethod
    config
        ``method.configure(context)``: its settings, checked and resolved once per fit.
    collection : SeriesCollection
    codes : ndarray of int, shape (N,)
        Group of every series, ``0..n_groups - 1``, none empty.
    seeds : list of int
        One seed per group.
    context : FitContext
    names : list, optional
        A name per group for the ``verbose`` lines (class labels).
    kind : str, default="group"
        What a group is, for the ``verbose`` lines ("class", "cluster").
    owner : str, default="RTWAverager"
        The estimator's name, for the ``verbose`` lines.
    starts : list of ndarray, optional
        A current average of every group (k-means' previous centroids).

    Returns
    -------
    list
        One result per group (:class:`~sk_rtw.methods.AveragingResult`), in group order.
    """
    codes = np.asarray(codes, dtype=np.int64)
    n_groups = int(codes.max()) + 1
    names = list(range(n_groups)) if names is None else names
    start = time.perf_counter()
    sizes = np.bincount(codes, minlength=n_groups)
    fitted: list[Any] = [None] * n_groups
    single = sizes == 1 if method.keeps_single_series(config) else np.zeros(n_groups, bool)
    member = np.empty(n_groups, dtype=np.int64)
    member[codes] = np.arange(len(codes))  # a group's only series, where it has one
    for g in np.flatnonzero(single):
        fitted[g] = SeriesCentroid.of(collection.series(member[g]), config, collection.manifold)
    averaged = np.flatnonzero(~single)
    if len(averaged):
        rows = np.flatnonzero(~single[codes])
        whole = len(rows) == len(codes)
        results = method.fit_groups(
            collection if whole else collection.subset(rows),
            codes if whole else np.searchsorted(averaged, codes[rows]),
            [seeds[g] for g in averaged], config, context,
            None if starts is None else [starts[g] for g in averaged],
        )  # fmt: skip
        for g, result in zip(averaged, results, strict=True):
            fitted[g] = result
    if context.verbose:
        seconds = time.perf_counter() - start
        # a line per class or cluster; a line per centroid only at verbose >= 2
        for g in range(n_groups if kind != "centroid" or context.verbose >= 2 else 0):
            what = ("the series itself" if single[g]
                    else method.describe(fitted[g]))  # fmt: skip
            print(
                f"[{owner}] {kind} {_label(names[g])!r}: {sizes[g]} series, {method.label}, "
                f"{what}",
                file=sys.stderr,
                flush=True,
            )
        plural = "es" if kind.endswith("s") else "s"
        print(
            f"[{owner}] {n_groups} {kind}{plural if n_groups != 1 else ''} "
            f"averaged in {seconds:.1f} s",
            file=sys.stderr,
            flush=True,
        )
    return fitted


def dtw_to_centroids(
    collection: SeriesCollection, centroids: list[np.ndarray], context: FitContext
) -> np.ndarray:
    """k-means distances: ``sqrt`` of the squared-cost DTW of every series to every centroid."""
    means = check_series_collection(list(centroids), collection.manifold, name="centroids")
    squared = dtw_pairwise_distance(
        collection, means, window=context.dtw_window, squared=True, n_jobs=context.n_jobs
    )
    return np.sqrt(squared)


@dataclass
class Clustering:
    """The outcome of :func:`kmeans` for one problem.

    ``labels`` assign every series to its nearest centroid; ``members`` are the labels the
    centroids were averaged from (``fits[k].aligned`` holds the series with ``members ==
    k``). They differ where the last round moved series to another centroid.
    """

    centroids: list[np.ndarray]
    labels: np.ndarray
    inertia: float
    n_iter: int
    fits: list[Any] = field(default_factory=list)
    members: np.ndarray | None = None


def _inertia(distances: np.ndarray, labels: np.ndarray) -> float:
    return float((distances[np.arange(len(labels)), labels] ** 2).sum())


def fill_empty(
    labels: np.ndarray, distances: np.ndarray, n_clusters: int
) -> tuple[np.ndarray, int]:
    """Give every empty cluster the series farthest from its own centroid (scikit-learn's
    rule), never emptying another cluster; returns the labels and how many were filled."""
    labels = labels.copy()
    filled = 0
    for k in range(n_clusters):
        if np.any(labels == k):
            continue
        own = distances[np.arange(len(labels)), labels].copy()
        sizes = np.bincount(labels, minlength=n_clusters)
        own[sizes[labels] < 2] = -np.inf  # a series alone in its cluster stays there
        labels[int(np.argmax(own))] = k
        filled += 1
    return labels, filled


def kmeans_seeds(
    collection: SeriesCollection, n_clusters: int, rng: np.random.RandomState,
    context: FitContext,
) -> list[np.ndarray]:  # fmt: skip
    """k-means++ with DTW: each new centroid drawn with probability ~ squared distance."""
    n = collection.n_series
    chosen = [int(rng.randint(n))]
    nearest = dtw_to_centroids(collection, [collection.series(chosen[0])], context)[:, 0]
    for _ in range(1, n_clusters):
        weights = nearest**2
        total = weights.sum()
        if total > 0 and np.isfinite(total):
            pick = int(rng.choice(n, p=weights / total))
        else:  # every series sits on a chosen one: take any other
            pick = int(rng.choice(np.setdiff1d(np.arange(n), chosen)))
        chosen.append(pick)
        new = dtw_to_centroids(collection, [collection.series(pick)], context)[:, 0]
        nearest = np.minimum(nearest, new)
    return [collection.series(i) for i in chosen]


@dataclass
class _Run:
    """The state of one problem's Lloyd iterations."""

    collection: SeriesCollection
    index: np.ndarray
    n_clusters: int
    rng: np.random.RandomState
    centroids: list[np.ndarray]
    distances: np.ndarray
    labels: np.ndarray
    inertia: float
    fits: list[Any] = field(default_factory=list)
    members: np.ndarray | None = None
    best: Clustering | None = None
    n_iter: int = 0
    done: bool = False


def kmeans(
    collection: SeriesCollection,
    problems: np.ndarray,
    n_clusters: list[int],
    method: AveragingMethod,
    config: Any,
    context: FitContext,
    rngs: list[np.random.RandomState],
    *,
    max_iter: int,
    tol: float,
    init_label: str = "",
    owner: str = "RTWAverager",
) -> list[Clustering]:
    """One k-means++ seeding and Lloyd's iterations for every problem, in lockstep.

    Parameters
    ----------
    collection : SeriesCollection
    problems : ndarray of int, shape (N,)
        The problem (class) of every series, ``0..n_problems - 1``.
    n_clusters : list of int
        Clusters of every problem (at most its number of series).
    method : AveragingMethod
        How every cluster is averaged.
    config
        ``method.configure(context)``.
    context : FitContext
    rngs : list of numpy.random.RandomState
        One per problem: seeding and the seeds of the centroid fits.
    max_iter : int
    tol : float
        A problem stops when no series changes cluster, or when its inertia improves by
        less than this fraction with no cluster re-seeded.

    Returns
    -------
    list of Clustering
        Per problem, the best iterate (lowest inertia with no empty cluster).
    """
    runs = []
    for p, (k, rng) in enumerate(zip(n_clusters, rngs, strict=True)):
        index = np.flatnonzero(problems == p)
        sub = collection.subset(index)
        centroids = kmeans_seeds(sub, k, rng, context)
        distances = dtw_to_centroids(sub, centroids, context)
        labels = distances.argmin(1)
        runs.append(_Run(sub, index, k, rng, centroids, distances, labels,
                         _inertia(distances, labels)))  # fmt: skip
    for iteration in range(1, max_iter + 1):
        active = [run for run in runs if not run.done]
        if not active:
            break
        start = time.perf_counter()
        refilled = []
        for run in active:
            run.labels, filled = fill_empty(run.labels, run.distances, run.n_clusters)
            run.members = run.labels
            refilled.append(filled)
        # every cluster of every active problem is one group of one batched fit
        offsets = np.cumsum([0] + [run.n_clusters for run in active])
        stacked = np.concatenate([run.index for run in active])
        codes = np.concatenate([run.labels + offsets[i] for i, run in enumerate(active)])
        seeds = [int(run.rng.randint(2**31 - 1)) for run in active for _ in range(run.n_clusters)]
        starts = [c for run in active for c in run.centroids]  # warm starts (DBA)
        fitted = fit_centroids(method, config, collection.subset(stacked), codes, seeds,
                               context, kind="cluster", owner=owner, starts=starts)  # fmt: skip
        for i, (run, filled) in enumerate(zip(active, refilled, strict=True)):
            run.fits = fitted[offsets[i] : offsets[i + 1]]
            run.centroids = [fit.mean for fit in run.fits]
            run.distances = dtw_to_centroids(run.collection, run.centroids, context)
            new_labels = run.distances.argmin(1)
            new_inertia = _inertia(run.distances, new_labels)
            changed = int((new_labels != run.labels).sum())
            improved = run.inertia - new_inertia
            run.labels, run.inertia, run.n_iter = new_labels, new_inertia, iteration
            if context.verbose:
                print(
                    f"[{owner}] {init_label}problem {i + 1}/{len(active)} iteration "
                    f"{iteration}: inertia {new_inertia:.6g}, {changed} series changed cluster"
                    + (f", {filled} empty cluster(s) re-seeded" if filled else "")
                    + f", {time.perf_counter() - start:.1f} s",
                    file=sys.stderr,
                    flush=True,
                )
            full = np.all(np.bincount(run.labels, minlength=run.n_clusters) > 0)
            if full and (run.best is None or run.inertia < run.best.inertia):
                run.best = Clustering(list(run.centroids), run.labels.copy(), run.inertia,
                                      iteration, list(run.fits), run.members)  # fmt: skip
            if changed == 0 or (filled == 0 and improved <= tol * abs(run.inertia)):
                run.done = True
    out = []
    for run in runs:
        if run.best is None:  # every iterate left a cluster empty: keep the last, filled
            labels, _ = fill_empty(run.labels, run.distances, run.n_clusters)
            run.best = Clustering(list(run.centroids), labels, _inertia(run.distances, labels),
                                  run.n_iter, list(run.fits), run.members)  # fmt: skip
        run.best.n_iter = run.n_iter
        out.append(run.best)
    return out
