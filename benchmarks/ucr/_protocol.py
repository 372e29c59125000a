"""The per-dataset protocol of the UCR benchmark (paper, section V-A).

For one dataset and each method:

1. the class means from the training series of each class: ``rtw``, ``ttw``, ``ntw``,
   ``dba`` are :class:`sk_rtw.RTWNearestCentroid` with that ``method`` and the paper's
   protocol, one mean per class and no band (``n_centroids=1, dtw_window=None``);
   ``rtw-paper`` is RTW with ``preset="paper"``, ``rtw-equal`` RTW with the paper's
   equal-weight mean (``method=RTW(mean_weights="equal")``), ``rtw-alignment`` RTW with
   ``preset="alignment"`` (align's defaults, means of ``min(N, 4) T``), ``rtw-refined`` the
   one-mean default with ``refine_steps=2`` (soft-DTW refinement of each mean);
   ``rtw-default``, ``dba-default``, ``ttw-default``, ``ntw-default`` are the classifier a
   user gets by default (``RTWNearestCentroid(method=...)``: the band and the centroids
   per class chosen from the training data, every centroid averaged with the method);
   ``rtw-prototype`` and ``dba-prototype`` are :class:`sk_rtw.RTWPrototypeClassifier`
   with that method (the default classifier's centroids, out-of-fold distances to every
   centroid and a linear readout); ``rtw-forest`` is :class:`sk_rtw.RTWProximityForest`
   as shipped (no averaging: a forest of proximity trees with elastic and shapelet
   candidates on the series and their tangent velocity), ``rtw-forest-shapelets`` the
   same with its splitters written out, ``rtw-forest-elastic`` the elastic candidates
   alone (Proximity Forest 2.0's recipe, the default forest before shapelet candidates),
   ``rtw-forest-raw`` that elastic forest without the velocity, ``rtw-forest-mean`` with
   DBA means of random class subsets as exemplars; ``aeon-dba`` is aeon's
   ``elastic_barycenter_average`` with DTW (a reference where the data are Euclidean);
   ``minirocket`` is aeon's ``MiniRocketClassifier`` (the field's default classifier;
   unequal-length series are linearly resampled to the longest training length first,
   which it needs);
2. averaging values, per training series: ``alignment`` = DTW of the *warped* (aligned)
   series to its class mean (the paper's averaging score; not for aeon's DBA) and
   ``barycenter`` = DTW of the unwarped series to its class mean;
3. classification: nearest class mean by DTW for every test series (``1nn-dtw``: aeon's
   1-nearest-neighbour DTW classifier instead, squared point costs and no band;
   ``1nn-dtw-band``: the archive's "DTW, learned window" baseline, 1-NN DTW with squared
   point costs in the Sakoe-Chiba band of the default classifier's candidates, 0, 0.05,
   0.1, 0.2 or none, that classifies the training series best by leave-one-out, ties to
   the narrower band; computed with sk_rtw's exact nearest-neighbour search), keeping
   predictions and distances;
4. paired t-tests (scipy ``ttest_rel``, alpha = 0.05) between every pair of methods: on
   the per-training-series ``alignment`` values (the same series under both methods;
   lower is better) and on the per-test-series classification outcome (1 correct,
   0 wrong; higher is better). A difference is significant when p < alpha; identical
   samples count as no difference.

Every DTW here is sk_rtw's, with the geodesic (absolute) point cost and no normalisation
-- the paper's accumulated ``D_dtw`` --, with no window except in the default
classifiers' predictions (their chosen band).
"""

from __future__ import annotations

import itertools
import json
import os
import sys
import tempfile
import time
import traceback
import warnings
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
from scipy import stats
from scipy.special import softmax

from sk_rtw import (
    Alignment,
    AutoChoice,
    ElasticSplitter,
    GeodesicShapeletClassifier,
    RTWNearestCentroid,
    RTWPrototypeClassifier,
    RTWProximityForest,
    ShapeletSplitter,
    dtw_nearest_distance,
    dtw_pairwise_distance,
)
from sk_rtw.utils import to_aeon

from .._shared import method_object
from ._data import Split, load_split, resample_split, subsample_per_class, take

ALPHA = 0.05
#: Result files are readable by everyone (rw-r--r--), like any file the user writes.
FILE_MODE = 0o644
#: The paper's protocol (Table II): one mean per class, no band.
ONE_MEAN = {"n_centroids": 1, "dtw_window": None}
#: Rows computed by the product's estimator: the method, its settings, the preset, and
#: other estimator parameters.
ESTIMATOR_METHODS: dict[str, tuple[str, dict, str, dict]] = {
    "rtw": ("rtw", {}, "class-means", ONE_MEAN),
    "rtw-paper": ("rtw", {}, "paper", ONE_MEAN),
    # ablations of the class-means preset: the paper's equal-weight mean, and align's
    # defaults (equal weights on the average time axis, 3 start rounds, Z = min(N, 4) T)
    "rtw-equal": ("rtw", {"mean_weights": "equal"}, "class-means", ONE_MEAN),
    "rtw-alignment": ("rtw", {}, "alignment", ONE_MEAN),
    # the one-mean default followed by the soft-DTW refinement of each mean
    "rtw-refined": ("rtw", {"refine_steps": 2}, "class-means", ONE_MEAN),
    "ttw": ("ttw", {}, "class-means", ONE_MEAN),
    "ntw": ("ntw", {}, "class-means", ONE_MEAN),
    "dba": ("dba", {}, "class-means", ONE_MEAN),
    # the classifier a user gets by default: band and centroids per class chosen from
    # the training data (RTWNearestCentroid(), and with method="dba", "ttw", "ntw")
    "rtw-default": ("rtw", {}, "class-means", {}),
    "dba-default": ("dba", {}, "class-means", {}),
    "ttw-default": ("ttw", {}, "class-means", {}),
    "ntw-default": ("ntw", {}, "class-means", {}),
    # RTWPrototypeClassifier: the default classifier's centroids read out linearly
    "rtw-prototype": ("rtw", {}, "class-means", {}),
    "dba-prototype": ("dba", {}, "class-means", {}),
}
#: Rows of RTWProximityForest: the default forest (elastic and shapelet candidates, 5 of
#: each at every node), the same written out, and the elastic forest with its measured
#: alternatives (no tangent velocity; DBA means of random class subsets as exemplars).
FOREST_METHODS: dict[str, dict] = {
    "rtw-forest": {},
    "rtw-forest-shapelets": {"splitters": (ElasticSplitter(), ShapeletSplitter())},
    "rtw-forest-elastic": {"splitters": (ElasticSplitter(),)},
    "rtw-forest-raw": {"splitters": (ElasticSplitter(),), "representation": "raw"},
    "rtw-forest-mean": {"splitters": (ElasticSplitter(),), "exemplars": "mean"},
}
#: Rows of the classifier a user gets by default.
DEFAULT_CLASSIFIERS = tuple(m for m in ESTIMATOR_METHODS if m.endswith("-default"))
#: Rows of RTWPrototypeClassifier.
PROTOTYPE_CLASSIFIERS = tuple(m for m in ESTIMATOR_METHODS if m.endswith("-prototype"))
REFERENCE_METHODS = ("aeon-dba", "1nn-dtw", "1nn-dtw-band", "minirocket", "rdst")
#: Rows of GeodesicShapeletClassifier (geodesic dilated shapelets, ridge readout).
SHAPELET_METHODS = ("rtw-shapelets",)
#: Rows that do not depend on the seed: ``--resume`` keeps them when only the seed changed.
SEED_FREE = ("1nn-dtw", "1nn-dtw-band")
ALL_METHODS = (*ESTIMATOR_METHODS, *FOREST_METHODS, *SHAPELET_METHODS, *REFERENCE_METHODS)
#: The main job's rows: the paper's one-mean comparison, the default classifier, the
#: prototype classifier, the library's most accurate (the forest, the shapelets) and the
#: references (``rtw-paper`` is slow: means of length N T
#: with the network at every time point; the ablations and the other default and
#: prototype classifiers on demand, with ``--methods``).
DEFAULT_METHODS = (
    "rtw", "ttw", "ntw", "dba", "rtw-default", "rtw-prototype", "rtw-forest",
    "rtw-shapelets", "aeon-dba", "1nn-dtw", "minirocket",
)  # fmt: skip


@dataclass(frozen=True)
class RunConfig:
    methods: tuple[str, ...] = DEFAULT_METHODS
    data_dir: str | None = None
    epochs: int = 256
    max_series_per_class: int | None = None
    output_length: int | None = None
    device: str = "cpu"
    seed: int = 0
    time_budget: float | None = None
    out: str = "results/ucr"
    verbose: int = 1
    resume: bool = False
    resample: int = 0


def record_path(out: str | Path, name: str, resample: int = 0) -> Path:
    """Where a dataset's result file lives: ``datasets/<name>.json`` for the archive's
    split (resample 0), ``resamples/<name>/resample<r>.json`` for resample ``r``."""
    if resample == 0:
        return Path(out) / "datasets" / f"{name}.json"
    return Path(out) / "resamples" / name / f"resample{resample}.json"


def one_hot(predictions, classes) -> np.ndarray:
    """Probabilities of a classifier without a graded score: 1 for the predicted class
    (what aeon's ``predict_proba`` gives for 1-NN and for MiniRocket's ridge readout)."""
    classes = np.asarray(classes)
    return (np.asarray(predictions)[:, None] == classes[None, :]).astype(float)


def atomic_write_json(path: Path, payload: dict) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    with os.fdopen(fd, "w") as handle:
        json.dump(payload, handle, indent=1, default=_jsonable)
    os.chmod(tmp, FILE_MODE)  # mkstemp creates 0600
    os.replace(tmp, path)


def _jsonable(value):
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    return str(value)


def _class_members(y, classes):
    return [np.flatnonzero(y == c) for c in classes]


def make_estimator(row: str, config: RunConfig) -> RTWNearestCentroid | RTWPrototypeClassifier:
    """The estimator of one row, with the run's epochs, output length, seed and device."""
    name, settings, preset, params = ESTIMATOR_METHODS[row]
    lengths = {} if config.output_length is None else {"output_length": config.output_length}
    method = method_object(name, **settings, n_epochs=config.epochs, **lengths)
    estimator = RTWPrototypeClassifier if row in PROTOTYPE_CLASSIFIERS else RTWNearestCentroid
    return estimator(
        method=method,
        preset=preset,
        random_state=config.seed,
        device=config.device,
        verbose=max(0, config.verbose - 1),  # 2: a line per class, 3: epoch progress
        **params,
    )


def _fit_estimator(method, train, test, config):
    """Fit one estimator row; its scores, predictions and times."""
    estimator = make_estimator(method, config)
    start = time.perf_counter()
    estimator.fit(train.X, train.y)
    fit_seconds = time.perf_counter() - start
    prototype = isinstance(estimator, RTWPrototypeClassifier)
    readout = estimator
    if prototype:  # the centroids are its nearest-centroid fit's
        estimator = estimator.centroids_
    alignment = np.full(len(train.y), np.nan)
    barycenter = np.full(len(train.y), np.nan)
    for k, fitted in enumerate(estimator.alignments_):  # every centroid and its series
        members = np.flatnonzero(estimator.assignments_ == k)
        mean = np.asarray(estimator.means_[k])[None]
        alignment[members] = dtw_pairwise_distance(fitted.aligned, mean)[:, 0]
        series = (
            train.X[members] if isinstance(train.X, np.ndarray) else [train.X[i] for i in members]
        )
        barycenter[members] = dtw_pairwise_distance(series, mean)[:, 0]
    start = time.perf_counter()
    if prototype:
        predictions, distances = readout.predict(test.X), None
    else:
        distances = estimator.class_distances(test.X)
        predictions = estimator.classes_[distances.argmin(1)]
    predict_seconds = time.perf_counter() - start
    extra = {}
    if prototype:
        nearest = estimator.predict(test.X)  # untimed: the nearest-centroid decision
        extra = {
            "decision": readout.decision_,
            "cv_accuracy": readout.cv_accuracy_,
            "nearest_accuracy": float(np.mean(nearest == test.y)),
        }
    # untimed, as predict_proba would give them: the softmax of the distances already
    # computed, or the readout's probabilities where it has them
    if not prototype:
        probabilities = softmax(-distances / estimator.temperature_, axis=1)
    elif hasattr(readout, "predict_proba"):
        probabilities = readout.predict_proba(test.X)
    else:
        probabilities = one_hot(predictions, estimator.classes_)
    return {
        "fit_seconds": fit_seconds,
        "predict_seconds": predict_seconds,
        "alignment": alignment,
        "barycenter": barycenter,
        "predictions": predictions,
        "probabilities": probabilities,
        "test_distances": distances,
        "classes": estimator.classes_,
        "parameters": repr(readout),
        "best_epochs": [
            a.best_epoch if isinstance(a, Alignment) else -1 for a in estimator.alignments_
        ],
        "dtw_window": estimator.dtw_window_,
        "n_centroids": estimator.n_centroids_,
        "selection": estimator.selection_,
        "iterations": [a.n_iter for a in estimator.alignments_],
        "output_length": [len(m) for m in estimator.means_],
        **extra,
    }


def _fit_forest(method, train, test, config):
    """Fit one forest row (one thread); its predictions, probabilities and times."""
    forest = RTWProximityForest(
        random_state=config.seed, n_jobs=1, verbose=max(0, config.verbose - 1),
        **FOREST_METHODS[method],
    )  # fmt: skip
    start = time.perf_counter()
    forest.fit(train.X, train.y)
    fit_seconds = time.perf_counter() - start
    start = time.perf_counter()
    probabilities = forest.predict_proba(test.X)  # predict is its argmax
    predict_seconds = time.perf_counter() - start
    return {
        "fit_seconds": fit_seconds,
        "predict_seconds": predict_seconds,
        "predictions": forest.classes_[np.argmax(probabilities, axis=1)],
        "probabilities": probabilities,
        "classes": forest.classes_,
        "parameters": repr(forest),
        "n_nodes": [tree.n_nodes_ for tree in forest.trees_],
        "depth": [tree.depth_ for tree in forest.trees_],
    }


def _fit_aeon_dba(train, test, config):
    from aeon.clustering.averaging import elastic_barycenter_average

    if not isinstance(train.X, np.ndarray):
        raise ValueError("aeon's DBA needs equal-length series")
    classes = np.unique(train.y)
    start = time.perf_counter()
    means = np.stack(
        [
            elastic_barycenter_average(
                to_aeon(train.X[members]), distance="dtw", random_state=config.seed
            )[0]
            for members in _class_members(train.y, classes)
        ]
    )
    fit_seconds = time.perf_counter() - start
    barycenter = np.full(len(train.y), np.nan)
    for k, members in enumerate(_class_members(train.y, classes)):
        barycenter[members] = dtw_pairwise_distance(train.X[members], means[k][None])[:, 0]
    start = time.perf_counter()
    distances = dtw_pairwise_distance(test.X, means)
    return {
        "fit_seconds": fit_seconds,
        "predict_seconds": time.perf_counter() - start,
        "barycenter": barycenter,  # no warped series: the averaging score is undefined
        "predictions": classes[distances.argmin(1)],
        "test_distances": distances,
        "classes": classes,
    }


def _fit_1nn(train, test, config):
    from aeon.classification.distance_based import KNeighborsTimeSeriesClassifier

    classifier = KNeighborsTimeSeriesClassifier(distance="dtw", n_neighbors=1)
    start = time.perf_counter()
    classifier.fit(to_aeon(train.X), train.y)
    fit_seconds = time.perf_counter() - start
    start = time.perf_counter()
    predictions = classifier.predict(to_aeon(test.X))
    return {
        "fit_seconds": fit_seconds,
        "predict_seconds": time.perf_counter() - start,
        "predictions": predictions,
        "classes": classifier.classes_,
        "parameters": repr(classifier),
    }


def equal_length(X, length: int) -> np.ndarray:
    """Series linearly resampled to ``length`` samples (a stack as they are if equal)."""
    if isinstance(X, np.ndarray) and X.shape[1] == length:
        return X
    out = []
    for series in X:
        series = np.asarray(series, dtype=float).reshape(len(series), -1)
        old, new = np.linspace(0.0, 1.0, len(series)), np.linspace(0.0, 1.0, length)
        out.append(np.stack([np.interp(new, old, c) for c in series.T], axis=1))
    return np.stack(out)


def _fit_minirocket(train, test, config):
    """aeon's MiniRocketClassifier (ridge readout over 10,000 random convolution features)."""
    try:
        from aeon.classification.convolution_based import MiniRocketClassifier
    except ImportError as exc:  # pragma: no cover - the benchmark needs aeon for its data
        raise ImportError(
            "the minirocket row needs aeon (pip install 'sk-rtw[benchmarks]')"
        ) from exc
    length = int(train.lengths.max())
    classifier = MiniRocketClassifier(random_state=config.seed, n_jobs=1)
    return _fit_timed(classifier, to_aeon(equal_length(train.X, length)), train.y,
                      to_aeon(equal_length(test.X, length)))  # fmt: skip


def _fit_timed(classifier, X_train, y_train, X_test) -> dict:
    """Fit and predict one classifier; its predictions, classes and seconds."""
    start = time.perf_counter()
    classifier.fit(X_train, y_train)
    fit_seconds = time.perf_counter() - start
    start = time.perf_counter()
    predictions = classifier.predict(X_test)
    return {
        "fit_seconds": fit_seconds,
        "predict_seconds": time.perf_counter() - start,
        "predictions": predictions,
        "classes": classifier.classes_,
        "parameters": repr(classifier),
    }


def _fit_shapelets(train, test, config):
    """GeodesicShapeletClassifier() on one thread."""
    classifier = GeodesicShapeletClassifier(random_state=config.seed, n_jobs=1)
    return _fit_timed(classifier, train.X, train.y, test.X)


def _fit_rdst(train, test, config):
    """aeon's RDSTClassifier (random dilated shapelets, ridge readout), one thread."""
    try:
        from aeon.classification.shapelet_based import RDSTClassifier
    except ImportError as exc:  # pragma: no cover - the benchmark needs aeon for its data
        raise ImportError("the rdst row needs aeon (pip install 'sk-rtw[benchmarks]')") from exc
    classifier = RDSTClassifier(random_state=config.seed, n_jobs=1)
    return _fit_timed(classifier, to_aeon(train.X), train.y, to_aeon(test.X))


def _fit_1nn_band(train, test, config):
    """1-NN DTW (squared point costs) in the band with the best leave-one-out accuracy."""
    classes, codes = np.unique(train.y, return_inverse=True)
    start = time.perf_counter()
    scores = {}
    windows = AutoChoice().windows  # the default classifier's candidate bands
    for window in windows:
        held_out = dtw_nearest_distance(
            train.X, train.X, codes, window=window, squared=True,
            exclude=np.arange(len(codes)), nearest_only=True,
        )  # fmt: skip
        scores[window] = float((held_out.argmin(1) == codes).mean())
    best = max(scores.values())
    window = next(w for w in windows if scores[w] == best)  # the narrowest of the best
    fit_seconds = time.perf_counter() - start
    start = time.perf_counter()
    nearest = dtw_nearest_distance(test.X, train.X, codes, window=window, squared=True,
                                   nearest_only=True)  # fmt: skip
    return {
        "fit_seconds": fit_seconds,
        "predict_seconds": time.perf_counter() - start,
        "predictions": classes[nearest.argmin(1)],
        "classes": classes,
        "dtw_window": window,
        "selection": {"leave-one-out accuracy": {str(w): a for w, a in scores.items()}},
    }


def paired_test(a: np.ndarray, b: np.ndarray, lower_is_better: bool) -> dict:
    """Paired t-test of per-item values of methods A and B; which one is better."""
    mask = np.isfinite(a) & np.isfinite(b)
    a, b = a[mask], b[mask]
    if len(a) < 2 or np.allclose(a, b):
        return {"n": len(a), "p": None, "better": "none"}
    p = float(stats.ttest_rel(a, b).pvalue)
    if not np.isfinite(p) or p >= ALPHA:
        return {"n": len(a), "p": p if np.isfinite(p) else None, "better": "none"}
    a_better = (a.mean() < b.mean()) if lower_is_better else (a.mean() > b.mean())
    return {"n": len(a), "p": p, "better": "a" if a_better else "b"}


def pairwise_tests(results: dict) -> dict:
    tests = {}
    done = [m for m in results if "error" not in results[m] and "skipped" not in results[m]]
    for a, b in itertools.combinations(done, 2):
        entry = {}
        ra, rb = results[a], results[b]
        a_values = np.asarray(ra.get("alignment", []), float)
        b_values = np.asarray(rb.get("alignment", []), float)
        if np.isfinite(a_values).any() and np.isfinite(b_values).any():
            entry["averaging"] = paired_test(a_values, b_values, True)
        entry["classification"] = paired_test(
            np.asarray(ra["correct"], float), np.asarray(rb["correct"], float), False
        )
        tests[f"{a}|{b}"] = entry
    return tests


def process_dataset(
    name: str,
    config: RunConfig,
    position: str = "",
    on_method_done: Callable[[str], None] | None = None,
) -> dict:
    """Run every method on one dataset and write ``<out>/datasets/<name>.json``.

    ``on_method_done(method)`` is called after each method (progress bars).
    """
    with warnings.catch_warnings():
        _quiet_third_party_warnings()
        return _process_dataset(name, config, position, on_method_done or (lambda m: None))


def _quiet_third_party_warnings() -> None:
    """aeon's numba kernels warn about reflected lists on every call: not ours to act on."""
    try:
        from numba.core.errors import NumbaPendingDeprecationWarning, NumbaTypeSafetyWarning
    except ImportError:  # pragma: no cover
        return
    warnings.simplefilter("ignore", NumbaTypeSafetyWarning)
    warnings.simplefilter("ignore", NumbaPendingDeprecationWarning)


_WARM: set[str] = set()


def warm_up(methods) -> None:
    """Fit every estimator method once on a tiny problem, untimed, in this process.

    The first fit in a process loads numba's cached kernels and torch's first calls (about a
    second); without this the first dataset of each worker would carry it in its fit time.
    """
    rng = np.random.default_rng(0)
    X, y = rng.standard_normal((8, 20)).cumsum(1), [0] * 4 + [1] * 4
    for method in methods:
        if method in ESTIMATOR_METHODS and method not in _WARM:
            make_estimator(method, RunConfig(epochs=2, verbose=0)).fit(X, y).predict(X)
            _WARM.add(method)
        if method in FOREST_METHODS and method not in _WARM:
            RTWProximityForest(n_trees=2, random_state=0, **FOREST_METHODS[method]).fit(
                X, y
            ).predict(X)
            _WARM.add(method)
        if method in ("rtw-shapelets", "rdst") and method not in _WARM:
            split = Split(X=X, y=np.asarray(y), lengths=np.full(len(X), X.shape[1]))
            fitter = _fit_shapelets if method == "rtw-shapelets" else _fit_rdst
            fitter(split, split, RunConfig(verbose=0))
            _WARM.add(method)
        if method == "minirocket" and method not in _WARM:  # numba compiles its kernels
            split = Split(X=X, y=np.asarray(y), lengths=np.full(len(X), X.shape[1]))
            _fit_minirocket(split, split, RunConfig(verbose=0))
            _WARM.add(method)


#: The run settings an estimator row's result depends on (a seed-free row: only the
#: subsampling, and the seed when there is one).
RESULT_SETTINGS = (
    "epochs", "max_series_per_class", "output_length", "device", "seed", "resample",
)  # fmt: skip
#: Settings added after results were first written: an older record ran with this value.
SETTING_DEFAULTS = {"resample": 0}


def reusable(record: dict | None, config: RunConfig) -> dict:
    """The finished method entries of a dataset's earlier ``record`` that this run would
    compute the same way (``--resume``): every row when the run settings are the same,
    the seed-free rows (:data:`SEED_FREE`) also across seeds when nothing is subsampled."""
    if not record or record.get("error") is not None:
        return {}
    before, now = record.get("config", {}), asdict(config)
    same = all(before.get(k, SETTING_DEFAULTS.get(k)) == now[k] for k in RESULT_SETTINGS)
    same_split = (
        before.get("max_series_per_class") == now["max_series_per_class"]
        and before.get("resample", 0) == now["resample"]
        and (now["max_series_per_class"] is None or before.get("seed") == now["seed"])
    )
    return {
        method: entry
        for method, entry in record.get("methods", {}).items()
        if method in config.methods
        and "accuracy" in entry
        and (same or (method in SEED_FREE and same_split))
    }


def read_record(path: Path) -> dict | None:
    """A dataset's result file, or None if there is none (or it cannot be read)."""
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError):
        return None


def _process_dataset(name, config, position, on_method_done) -> dict:
    warm_up(config.methods)
    start = time.perf_counter()
    record = {"dataset": name, "config": asdict(config), "methods": {}, "error": None}
    record["resample"] = config.resample
    path = record_path(config.out, name, config.resample)
    done = reusable(read_record(path), config) if config.resume else {}
    try:
        train = load_split(name, "train", config.data_dir)
        test = load_split(name, "test", config.data_dir)
        train, test = resample_split(train, test, config.resample)
        kept = subsample_per_class(train, config.max_series_per_class, config.seed)
        record.update(
            n_train_total=len(train.y),
            n_train=len(kept),
            n_test=len(test.y),
            lengths=[int(train.lengths.min()), int(train.lengths.max())],
            n_classes=len(np.unique(train.y)),
            notes=train.notes + test.notes,
            train_index=kept,
        )
        train = take(train, kept)
        for method in config.methods:
            if method in done:  # finished by an earlier run with the same settings
                record["methods"][method] = done[method]
                on_method_done(method)
                continue
            elapsed = time.perf_counter() - start
            if config.time_budget and elapsed > config.time_budget:
                record["methods"][method] = {
                    "skipped": f"time budget of {config.time_budget:.0f} s used up"
                }
                on_method_done(method)
                continue
            _log(config, f"{position} {name}: {method} ...")
            try:
                if method in ESTIMATOR_METHODS:
                    out = _fit_estimator(method, train, test, config)
                elif method in FOREST_METHODS:
                    out = _fit_forest(method, train, test, config)
                elif method == "aeon-dba":
                    out = _fit_aeon_dba(train, test, config)
                elif method == "1nn-dtw":
                    out = _fit_1nn(train, test, config)
                elif method == "1nn-dtw-band":
                    out = _fit_1nn_band(train, test, config)
                elif method == "minirocket":
                    out = _fit_minirocket(train, test, config)
                elif method == "rtw-shapelets":
                    out = _fit_shapelets(train, test, config)
                elif method == "rdst":
                    out = _fit_rdst(train, test, config)
                else:
                    raise ValueError(f"unknown method {method!r}")
            except Exception as exc:  # one method failing must not lose the others
                record["methods"][method] = {
                    "error": f"{type(exc).__name__}: {exc}",
                    "traceback": traceback.format_exc(),
                }
                _log(config, f"{position} {name}: {method} failed: {exc}")
                atomic_write_json(path, record)
                on_method_done(method)
                continue
            if "probabilities" not in out:  # the reference rows: aeon's predict_proba
                out["probabilities"] = one_hot(out["predictions"], out["classes"])
            correct = (np.asarray(out["predictions"]) == test.y).astype(int)
            out["correct"] = correct
            out["accuracy"] = float(correct.mean())
            record["methods"][method] = out
            atomic_write_json(path, record)  # a long dataset keeps its finished methods
            _log(
                config,
                f"{position} {name}: {method} accuracy {out['accuracy']:.3f} "
                f"({out['fit_seconds']:.1f} s)",
            )
            on_method_done(method)
        record["tests"] = pairwise_tests(record["methods"])
        record["test_labels"] = test.y
    except Exception as exc:
        record["error"] = f"{type(exc).__name__}: {exc}"
        record["traceback"] = traceback.format_exc()
        _log(config, f"{position} {name}: failed: {record['error']}")
    record["seconds"] = time.perf_counter() - start
    atomic_write_json(path, record)
    return record


def _log(config: RunConfig, text: str) -> None:
    if config.verbose:
        try:  # above an active progress bar, not through it
            from tqdm import tqdm

            tqdm.write(text, file=sys.stderr)
        except ImportError:
            print(text, file=sys.stderr, flush=True)
