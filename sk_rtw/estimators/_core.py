"""The numerical core of the estimators: centres of groups of series, and k-means.

Class means (:class:`RTWAverager`), several centroids per class and clustering
(:class:`RTWKMeans`) all reduce to two functions here, fed one resolved
:class:`CentreSettings`:

* :func:`fit_centres` -- one centre per group of a stacked collection. The engine's
  methods (RTW, TTW, NTW) solve all groups in *one* optimisation
  (:func:`sk_rtw.align._engine.align_collection`); DBA averages group by group.
* :func:`kmeans` -- Lloyd's iterations with manifold DTW for several independent
  clustering problems at once (every class of a training set, or the one problem of
  k-means): each round fits the centres of every cluster of every unfinished problem in
  one :func:`fit_centres` call.

The estimators validate, resolve their settings and store the results; nothing is
averaged or scored by a second implementation.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from joblib import Parallel, delayed

from ..align import METHODS, Alignment, classification_output_length
from ..align._config import AlignmentConfig, resolve_config
from ..align._engine import align_collection
from ..baselines import MultipleAlignment, dba_average
from ..dtw import dtw_pairwise_distance
from ..utils import SeriesCollection, check_series_collection

#: Averaging methods of the estimators: the engine's and DTW barycenter averaging.
ESTIMATOR_METHODS = (*METHODS, "dba")

Centre = Alignment | MultipleAlignment


@dataclass(frozen=True)
class CentreSettings:
    """How the centres of an estimator are computed, resolved once per ``fit``.

    ``engine`` holds the keywords of :func:`sk_rtw.align._config.resolve_config` except
    the output length: ``output_length`` (None: each group's own, see
    :func:`sk_rtw.align.classification_output_length`).
    """

    method: str
    engine: dict[str, Any] = field(default_factory=dict)
    output_length: int | None = None
    dtw_window: float | None = None
    n_jobs: int | None = None
    verbose: int = 0
    owner: str = "RTWAverager"

    def config(self, lengths: np.ndarray, output_length: int) -> AlignmentConfig:
        """The engine configuration for groups of series of these ``lengths``."""
        return resolve_config(self.method, len(lengths), int(np.max(lengths)),
                              output_length=output_length, **self.engine)  # fmt: skip

    def output_length_of(self, lengths: np.ndarray) -> int:
        """Length of the centre of a group of series of these ``lengths``."""
        if self.output_length is not None:
            return int(self.output_length)
        return classification_output_length(lengths, self.engine.get("preset") or "default")


#: Estimator parameters that are :func:`sk_rtw.align` arguments of the same name.
ENGINE_ARGUMENTS = (
    "preset", "n_epochs", "learning_rate", "sinc_window", "loss_window", "loss_step",
    "penalty", "warp_start", "n_iter_no_change", "tol", "device",
)  # fmt: skip
#: Estimator parameters that are engine options; ``"auto"`` leaves the preset's value.
ENGINE_OPTIONS = ("n_components", "hidden_size", "warp_knots", "tangent_refinements",
                  "mean_iterations", "mean_weights")  # fmt: skip


def engine_keywords(params: dict[str, Any], output_length: int | None = None) -> dict[str, Any]:
    """The engine's keywords (``resolve_config``) from an estimator's parameters."""
    keywords = {name: params[name] for name in ENGINE_ARGUMENTS if name in params}
    keywords["output_length"] = output_length
    keywords["own_preset"] = "class-means"
    keywords["method_options"] = {
        name: params[name]
        for name in ENGINE_OPTIONS
        if name in params and not (isinstance(params[name], str) and params[name] == "auto")
    }
    return keywords


def centre_settings(
    method: str,
    *,
    engine: dict[str, Any],
    dtw_window: float | None = None,
    n_jobs: int | None = None,
    verbose: int = 0,
    owner: str = "RTWAverager",
) -> CentreSettings:
    """Resolve an estimator's engine parameters (``engine``: keywords of ``resolve_config``
    plus ``output_length`` and ``method_options``); every value is checked here, before
    any work."""
    engine = dict(engine)
    output_length = engine.pop("output_length", None)
    settings = CentreSettings(method, engine, output_length, dtw_window, n_jobs, verbose, owner)
    if method != "dba":
        settings.config(np.array([2, 2]), 2 if output_length is None else output_length)
    return settings


def _label(name: Any) -> Any:
    return name.item() if isinstance(name, np.generic) else name


def fit_centres(
    collection: SeriesCollection,
    codes: np.ndarray,
    seeds: list[int],
    settings: CentreSettings,
    names: list[Any] | None = None,
    kind: str = "group",
) -> list[Centre]:
    """One centre per group of ``collection`` (``codes``: group of every series).

    Parameters
    ----------
    collection : SeriesCollection
    codes : ndarray of int, shape (N,)
        Group of every series, ``0..n_groups - 1``, none empty.
    seeds : list of int
        One seed per group.
    settings : CentreSettings
    names : list, optional
        A name per group for the ``verbose`` lines (class labels).
    kind : str, default="group"
        What a group is, for the ``verbose`` lines ("class", "cluster").

    Returns
    -------
    list of Alignment or MultipleAlignment
        One per group, in group order.
    """
    codes = np.asarray(codes, dtype=np.int64)
    n_groups = int(codes.max()) + 1
    names = list(range(n_groups)) if names is None else names
    start = time.perf_counter()
    if settings.method == "dba":
        members = [np.flatnonzero(codes == g) for g in range(n_groups)]
        jobs = (
            delayed(dba_average)(collection.subset(idx), window=settings.dtw_window)
            for idx in members
        )
        if settings.n_jobs in (None, 1) or n_groups == 1:
            fitted: list[Centre] = [fn(*args, **kwargs) for fn, args, kwargs in jobs]
        else:
            fitted = Parallel(n_jobs=settings.n_jobs)(jobs)
        details = [f"cost {getattr(result, 'cost', float('nan')):.4g}" for result in fitted]
    else:
        alignments = _fit_engine(collection, codes, seeds, settings)
        details = [f"best epoch {a.best_epoch + 1} of {a.n_iter} run" for a in alignments]
        fitted = list(alignments)
    if settings.verbose:
        seconds = time.perf_counter() - start
        sizes = np.bincount(codes, minlength=n_groups)
        for g in range(n_groups):
            print(
                f"[{settings.owner}] {kind} {_label(names[g])!r}: {sizes[g]} series, "
                f"{settings.method}, {details[g]}",
                file=sys.stderr,
                flush=True,
            )
        plural = "es" if kind.endswith("s") else "s"
        print(
            f"[{settings.owner}] {n_groups} {kind}{plural if n_groups != 1 else ''} "
            f"averaged in {seconds:.1f} s",
            file=sys.stderr,
            flush=True,
        )
    return fitted


def _fit_engine(
    collection: SeriesCollection, codes: np.ndarray, seeds: list[int], settings: CentreSettings
) -> list[Alignment]:
    """The engine's centres: one batched optimisation per distinct output length."""
    n_groups = int(codes.max()) + 1
    lengths = collection.lengths
    z = np.array([settings.output_length_of(lengths[codes == g]) for g in range(n_groups)])
    fitted: list[Alignment | None] = [None] * n_groups
    for length in np.unique(z):
        groups = np.flatnonzero(z == length)
        members = np.flatnonzero(np.isin(codes, groups))
        local = np.searchsorted(groups, codes[members])
        config = settings.config(lengths[members], int(length))
        results = align_collection(
            collection.subset(members), local, [seeds[g] for g in groups], config,
            n_jobs=settings.n_jobs, verbose=settings.verbose >= 2,
        )  # fmt: skip
        for g, result in zip(groups, results, strict=True):
            fitted[g] = result
    return [f for f in fitted if f is not None]


def dtw_to_centres(
    collection: SeriesCollection, centres: list[np.ndarray], settings: CentreSettings
) -> np.ndarray:
    """k-means distances: ``sqrt`` of the squared-cost DTW of every series to every centre."""
    means = check_series_collection(list(centres), collection.manifold, name="centres")
    squared = dtw_pairwise_distance(
        collection, means, window=settings.dtw_window, squared=True, n_jobs=settings.n_jobs
    )
    return np.sqrt(squared)


@dataclass
class Clustering:
    """The outcome of :func:`kmeans` for one problem."""

    centres: list[np.ndarray]
    labels: np.ndarray
    inertia: float
    n_iter: int
    fits: list[Centre] = field(default_factory=list)


def _inertia(distances: np.ndarray, labels: np.ndarray) -> float:
    return float((distances[np.arange(len(labels)), labels] ** 2).sum())


def fill_empty(
    labels: np.ndarray, distances: np.ndarray, n_clusters: int
) -> tuple[np.ndarray, int]:
    """Give every empty cluster the series farthest from its own centre (scikit-learn's
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
    settings: CentreSettings,
) -> list[np.ndarray]:  # fmt: skip
    """k-means++ with DTW: each new centre drawn with probability ~ squared distance."""
    n = collection.n_series
    chosen = [int(rng.randint(n))]
    nearest = dtw_to_centres(collection, [collection.series(chosen[0])], settings)[:, 0]
    for _ in range(1, n_clusters):
        weights = nearest**2
        total = weights.sum()
        if total > 0 and np.isfinite(total):
            pick = int(rng.choice(n, p=weights / total))
        else:  # every series sits on a chosen one: take any other
            pick = int(rng.choice(np.setdiff1d(np.arange(n), chosen)))
        chosen.append(pick)
        new = dtw_to_centres(collection, [collection.series(pick)], settings)[:, 0]
        nearest = np.minimum(nearest, new)
    return [collection.series(i) for i in chosen]


@dataclass
class _Run:
    """The state of one problem's Lloyd iterations."""

    collection: SeriesCollection
    index: np.ndarray
    n_clusters: int
    rng: np.random.RandomState
    centres: list[np.ndarray]
    distances: np.ndarray
    labels: np.ndarray
    inertia: float
    fits: list[Centre] = field(default_factory=list)
    best: Clustering | None = None
    n_iter: int = 0
    done: bool = False


def kmeans(
    collection: SeriesCollection,
    problems: np.ndarray,
    n_clusters: list[int],
    settings: CentreSettings,
    rngs: list[np.random.RandomState],
    *,
    max_iter: int = 10,
    tol: float = 1e-4,
    init_label: str = "",
) -> list[Clustering]:
    """One k-means++ seeding and Lloyd's iterations for every problem, in lockstep.

    Parameters
    ----------
    collection : SeriesCollection
    problems : ndarray of int, shape (N,)
        The problem (class) of every series, ``0..n_problems - 1``.
    n_clusters : list of int
        Clusters of every problem (at most its number of series).
    settings : CentreSettings
    rngs : list of numpy.random.RandomState
        One per problem: seeding and the seeds of the centre fits.
    max_iter : int, default=10
    tol : float, default=1e-4
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
        centres = kmeans_seeds(sub, k, rng, settings)
        distances = dtw_to_centres(sub, centres, settings)
        labels = distances.argmin(1)
        runs.append(_Run(sub, index, k, rng, centres, distances, labels,
                         _inertia(distances, labels)))  # fmt: skip
    for iteration in range(1, max_iter + 1):
        active = [run for run in runs if not run.done]
        if not active:
            break
        start = time.perf_counter()
        refilled = []
        for run in active:
            run.labels, filled = fill_empty(run.labels, run.distances, run.n_clusters)
            refilled.append(filled)
        # every cluster of every active problem is one group of one batched fit
        offsets = np.cumsum([0] + [run.n_clusters for run in active])
        stacked = np.concatenate([run.index for run in active])
        codes = np.concatenate([run.labels + offsets[i] for i, run in enumerate(active)])
        seeds = [int(run.rng.randint(2**31 - 1)) for run in active for _ in range(run.n_clusters)]
        fitted = fit_centres(collection.subset(stacked), codes, seeds, settings, kind="cluster")
        for i, (run, filled) in enumerate(zip(active, refilled, strict=True)):
            run.fits = fitted[offsets[i] : offsets[i + 1]]
            run.centres = [fit.mean for fit in run.fits]
            run.distances = dtw_to_centres(run.collection, run.centres, settings)
            new_labels = run.distances.argmin(1)
            new_inertia = _inertia(run.distances, new_labels)
            changed = int((new_labels != run.labels).sum())
            improved = run.inertia - new_inertia
            run.labels, run.inertia, run.n_iter = new_labels, new_inertia, iteration
            if settings.verbose:
                print(
                    f"[{settings.owner}] {init_label}problem {i + 1}/{len(active)} iteration "
                    f"{iteration}: inertia {new_inertia:.6g}, {changed} series changed cluster"
                    + (f", {filled} empty cluster(s) re-seeded" if filled else "")
                    + f", {time.perf_counter() - start:.1f} s",
                    file=sys.stderr,
                    flush=True,
                )
            full = np.all(np.bincount(run.labels, minlength=run.n_clusters) > 0)
            if full and (run.best is None or run.inertia < run.best.inertia):
                run.best = Clustering(list(run.centres), run.labels.copy(), run.inertia,
                                      iteration, list(run.fits))  # fmt: skip
            if changed == 0 or (filled == 0 and improved <= tol * abs(run.inertia)):
                run.done = True
    out = []
    for run in runs:
        if run.best is None:  # every iterate left a cluster empty: keep the last, filled
            labels, _ = fill_empty(run.labels, run.distances, run.n_clusters)
            run.best = Clustering(list(run.centres), labels, _inertia(run.distances, labels),
                                  run.n_iter, list(run.fits))  # fmt: skip
        run.best.n_iter = run.n_iter
        out.append(run.best)
    return out
