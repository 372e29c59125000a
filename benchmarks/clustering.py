"""Clustering and several centroids per class: RTWKMeans against tslearn and 1-NN DTW.

Usage::

    python benchmarks/clustering.py                                 # aeon's bundled data
    python benchmarks/clustering.py --data-dir ../shared/ucr --all  # the development archive
    python benchmarks/clustering.py --sections manifolds --demo-dir ../shared/data

Prints
1. ``tslearn``: RTWKMeans (DBA and RTW centres) beside tslearn's
   ``TimeSeriesKMeans(metric="dtw")`` on Euclidean UCR training sets, ``k`` = number of
   classes, ``n_init`` 2, ``max_iter`` 10: inertia (the same measure for both: sum of
   squared-cost DTW of each series to its centre, recomputed with sk_rtw's DTW), adjusted
   Rand index against the labels, seconds. Needs ``pip install tslearn`` (skipped
   otherwise).
2. ``manifolds``: RTWKMeans where no peer runs: RCFS letters on S^2 and S^3, R-LASA shapes
   on S^3 and SPD(2) (demonstrations from ``--demo-dir``), ARI against the shape labels.
3. ``centroids``: nearest centroid with ``n_centroids`` = 1, 2, 4, 8 DBA (or, with
   ``--centroid-method rtw``, RTW) centroids per class, and with ``k`` chosen by 3-fold
   cross-validation on the training split
   (``GridSearchCV``), against 1-NN DTW (both with sk_rtw's DTW, absolute point cost):
   test accuracy and prediction seconds per dataset, and the count of datasets where
   the cross-validated ``k`` is at least as accurate as 1-NN DTW.
4. ``classify``: the default nearest-centroid classifier (``RTWNearestCentroid()``:
   band and centroids per class chosen from the training data; RTW and DBA centroids)
   beside one RTW mean per class (``n_centroids=1, dtw_window=None``) and 1-NN DTW on
   labelled demonstrations on curved manifolds (the letters and shapes of section 2, and
   the two pose tasks in R^3 x S^3), every other demonstration of a class for training:
   test accuracy, chosen window and centroids, fit seconds.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np
from sklearn.metrics import adjusted_rand_score

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository; then _shared

from benchmarks._shared import method_object
from benchmarks.ucr._data import AEON_BUNDLED, available_datasets, load_split
from sk_rtw import RTWKMeans, RTWNearestCentroid, dtw_pairwise_distance
from sk_rtw.manifolds import Sphere

CENTROIDS = (1, 2, 4, 8)
SECTIONS = ("tslearn", "manifolds", "centroids", "classify")


def inertia(X, centres, labels) -> float:
    """Sum of squared-cost DTW of every series to its own centre (sk_rtw's DTW)."""
    d = dtw_pairwise_distance(X, np.asarray(centres), squared=True)
    return float(d[np.arange(len(labels)), labels].sum())


def section_tslearn(names, data_dir, epochs: int) -> None:
    try:
        from tslearn.clustering import TimeSeriesKMeans
    except ImportError:
        print("\n1. tslearn not installed (pip install tslearn): section skipped")
        return
    print(f"\n1. RTWKMeans vs tslearn TimeSeriesKMeans(metric='dtw'), k = classes, "
          f"n_init 2, max_iter 10 (RTW: {epochs} epochs)")  # fmt: skip
    head = f"{'dataset':>26} {'n':>5} {'k':>3} | {'inertia':>30} | {'ARI':>20} | {'seconds':>20}"
    print(
        head
        + "\n"
        + " " * 37
        + "| tslearn      dba      rtw | tslearn  dba   rtw | tslearn  dba  rtw"
    )
    for name in names:
        split = load_split(name, "train", data_dir)
        if not isinstance(split.X, np.ndarray) or split.X.ndim != 2:
            continue
        X, y = split.X, split.y
        k = len(np.unique(y))
        rows = {}
        start = time.perf_counter()
        tk = TimeSeriesKMeans(k, metric="dtw", n_init=2, max_iter=10, random_state=0).fit(
            X[..., None]
        )
        seconds = time.perf_counter() - start
        score = inertia(X, tk.cluster_centers_[..., 0], tk.labels_)
        rows["tslearn"] = (score, adjusted_rand_score(y, tk.labels_), seconds)
        for method in ("dba", "rtw"):
            start = time.perf_counter()
            km = RTWKMeans(k, method=method_object(method, n_epochs=epochs), n_init=2,
                           max_iter=10, random_state=0).fit(X)  # fmt: skip
            rows[method] = (km.inertia_, adjusted_rand_score(y, km.labels_),
                            time.perf_counter() - start)  # fmt: skip
        cells = [
            " ".join(f"{rows[m][i]:>8.4g}" for m in ("tslearn", "dba", "rtw")) for i in range(3)
        ]
        print(f"{name:>26} {len(X):>5} {k:>3} | {cells[0]} | {cells[1]} | {cells[2]}", flush=True)


def manifold_datasets(demo_dir: Path):
    """(name, manifold, series, labels) of labelled demonstrations on curved manifolds."""
    from benchmarks.paper._data import (
        letters_on_s3,
        rcfs_letter,
        rlasa_quaternions,
        rlasa_spd,
    )

    letters = ("A", "C", "G", "L", "S", "W")
    positions = [rcfs_letter(demo_dir, L)[:, ::4] for L in letters]  # (n, 50, 2) each
    labels = np.concatenate([[i] * len(p) for i, p in enumerate(positions)])
    stacked = np.concatenate(positions)
    scale = 0.5 / np.abs(stacked).max()
    tangent = np.concatenate([scale * stacked, np.zeros((*stacked.shape[:2], 1))], axis=-1)
    north = np.broadcast_to(np.array([0.0, 0.0, 1.0]), tangent.shape)
    on_s2 = Sphere(2).exp(north, tangent)
    yield "RCFS letters on S^2", "sphere", on_s2, labels
    yield "RCFS letters on S^3", "quaternion", letters_on_s3(stacked, 2 * scale), labels
    shapes = ("BendedLine", "CShape", "GShape", "Khamesh", "Sshape", "Worm")
    quats = [rlasa_quaternions(demo_dir, s)[:, ::10] for s in shapes]
    spds = [rlasa_spd(demo_dir, s)[:, ::10] for s in shapes]
    shape_labels = np.concatenate([[i] * len(q) for i, q in enumerate(quats)])
    yield "R-LASA shapes on S^3", "quaternion", np.concatenate(quats), shape_labels
    yield "R-LASA shapes on SPD(2)", "spd", np.concatenate(spds), shape_labels


def demo_root(demo_dir: str | None, section: str) -> Path | None:
    """The demonstration folder, or None after saying that ``section`` is skipped."""
    from benchmarks.paper._data import data_dir

    try:
        return data_dir(demo_dir)
    except FileNotFoundError as exc:
        print(f"\n{section}. {exc} (this script: --demo-dir): section skipped")
        return None


def section_manifolds(demo_dir: str | None, epochs: int) -> None:
    root = demo_root(demo_dir, "2")
    if root is None:
        return
    print(f"\n2. RTWKMeans on curved manifolds (no peer runs here), k = shapes, n_init 2 "
          f"(RTW: {epochs} epochs)")  # fmt: skip
    print(f"{'data':>24} {'n':>4} {'T':>4} {'k':>3} | {'ARI dba':>8} {'ARI rtw':>8} | "
          f"{'s dba':>6} {'s rtw':>6}")  # fmt: skip
    for name, manifold, X, y in manifold_datasets(root):
        k = len(np.unique(y))
        out = {}
        for method in ("dba", "rtw"):
            start = time.perf_counter()
            km = RTWKMeans(k, method=method_object(method, n_epochs=epochs), manifold=manifold,
                           n_init=2, random_state=0).fit(X)  # fmt: skip
            out[method] = (adjusted_rand_score(y, km.labels_), time.perf_counter() - start)
        print(f"{name:>24} {len(X):>4} {X.shape[1]:>4} {k:>3} | {out['dba'][0]:>8.3f} "
              f"{out['rtw'][0]:>8.3f} | {out['dba'][1]:>6.1f} {out['rtw'][1]:>6.1f}",
              flush=True)  # fmt: skip


def labelled_demonstrations(root):
    """(name, manifold, series, labels): section 2's data and the two pose tasks."""
    from benchmarks.paper._data import icsc_carrot_grating, icsc_wiping

    yield from manifold_datasets(root)
    grating = [s[::20] for s in icsc_carrot_grating(root)]
    wiping = [s[::10] for s in icsc_wiping(root)]
    yield "poses: grating or wiping", "pose", grating + wiping, np.repeat([0, 1], [12, 4])


def section_classify(demo_dir: str | None, epochs: int) -> None:
    root = demo_root(demo_dir, "4")
    if root is None:
        return
    rows = {
        "one rtw mean": ("rtw", {"n_centroids": 1, "dtw_window": None}),
        "default rtw": ("rtw", {}),
        "default dba": ("dba", {}),
    }
    print(f"\n4. The default nearest centroid on curved manifolds (RTW: {epochs} epochs), "
          "every other demonstration of a class for training")  # fmt: skip
    print(f"{'data':>26} {'n':>4} | " + " ".join(f"{r:>22}" for r in rows)
          + f" {'1-NN DTW':>9}")  # fmt: skip
    for name, manifold, X, y in labelled_demonstrations(root):
        X = list(X)
        train = np.concatenate([np.flatnonzero(y == c)[0::2] for c in np.unique(y)])
        test = np.setdiff1d(np.arange(len(y)), train)
        cells = []
        for method, params in rows.values():
            settings = method_object(method, n_epochs=epochs)
            clf = RTWNearestCentroid(manifold=manifold, method=settings, random_state=0, **params)
            start = time.perf_counter()
            clf.fit([X[i] for i in train], y[train])
            fit = time.perf_counter() - start
            accuracy = clf.score([X[i] for i in test], y[test])
            choice = "" if params else f"w={clf.dtw_window_},k={clf.n_centroids_}"
            cells.append(f"{accuracy:.3f} {choice} {fit:.1f}s")
        nearest = dtw_pairwise_distance([X[i] for i in test], [X[i] for i in train],
                                        manifold=clf.manifold_).argmin(1)  # fmt: skip
        one_nn = float((y[train][nearest] == y[test]).mean())
        print(f"{name:>26} {len(y):>4} | " + " ".join(f"{c:>22}" for c in cells)
              + f" {one_nn:>9.3f}", flush=True)  # fmt: skip


def section_centroids(names, data_dir, method="dba") -> None:
    print(f"\n3. Nearest centroid with k {method.upper()} centroids per class vs 1-NN DTW "
          "(accuracy; prediction seconds)")  # fmt: skip
    from sklearn.model_selection import GridSearchCV, StratifiedKFold

    ks = " ".join(f"{'k=' + str(k):>7}" for k in CENTROIDS)
    print(f"{'dataset':>26} | {ks} {'CV k':>9} {'1-NN':>7} | {'pred CV':>9} {'pred 1-NN':>9} "
          f"{'x':>6}")  # fmt: skip
    wins_any = wins_4 = wins_cv = speedups = n = 0
    ratios = []
    for name in names:
        train, test = load_split(name, "train", data_dir), load_split(name, "test", data_dir)
        accuracy, predict_seconds = {}, {}
        for k in CENTROIDS:
            clf = RTWNearestCentroid(method=method, n_centroids=k, dtw_window=None,
                                     random_state=0, n_jobs=-1)  # fmt: skip
            clf.fit(train.X, train.y)
            start = time.perf_counter()
            accuracy[k] = float((clf.predict(test.X) == test.y).mean())
            predict_seconds[k] = time.perf_counter() - start
        folds = int(min(3, np.bincount(np.unique(train.y, return_inverse=True)[1]).min()))
        if folds >= 2:
            search = GridSearchCV(
                RTWNearestCentroid(method=method, dtw_window=None, random_state=0, n_jobs=-1),
                {"n_centroids": list(CENTROIDS)},
                cv=StratifiedKFold(folds, shuffle=True, random_state=0),
            ).fit(train.X, train.y)
            best_k = search.best_params_["n_centroids"]
        else:  # a class with one series: nothing to cross-validate
            best_k = 1
        cv_accuracy = accuracy[best_k]
        start = time.perf_counter()
        nearest = dtw_pairwise_distance(test.X, train.X, n_jobs=-1).argmin(1)
        one_nn_seconds = time.perf_counter() - start
        one_nn = float((train.y[nearest] == test.y).mean())
        ratio = one_nn_seconds / max(predict_seconds[best_k], 1e-9)
        ratios.append(ratio)
        n += 1
        wins_any += max(accuracy.values()) >= one_nn
        wins_4 += accuracy[4] >= one_nn
        wins_cv += cv_accuracy >= one_nn
        speedups += ratio >= 10
        cells = " ".join(f"{accuracy[k]:>7.3f}" for k in CENTROIDS)
        cv_cell = f"{cv_accuracy:.3f} ({best_k})"
        print(f"{name:>26} | {cells} {cv_cell:>9} {one_nn:>7.3f} | "
              f"{predict_seconds[best_k]:>9.3f} {one_nn_seconds:>9.3f} {ratio:>6.1f}",
              flush=True)  # fmt: skip
    if n:
        print(f"\nAt least as accurate as 1-NN DTW: k chosen by cross-validation on {wins_cv}/{n} "
              f"datasets (k = 4 on {wins_4}/{n}; the best k in hindsight on {wins_any}/{n}). "
              f"Prediction with the cross-validated k at least 10x faster than 1-NN DTW on "
              f"{speedups}/{n} (median {np.median(ratios):.1f}x); the speed-up cannot exceed "
              "n_train / (k n_classes), small on these training sets.")  # fmt: skip


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(
        description=__doc__.splitlines()[0],
        epilog=__doc__.split("Usage::")[1].split("Prints")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--data-dir", help="UCR archive in aeon's local layout")
    parser.add_argument("--all", action="store_true", help="every dataset in --data-dir")
    parser.add_argument("--datasets", nargs="+", help=f"default: {', '.join(AEON_BUNDLED)}")
    parser.add_argument("--demo-dir", help="demonstration data (default ../shared/data)")
    parser.add_argument("--sections", nargs="+", choices=SECTIONS, default=list(SECTIONS))
    parser.add_argument("--epochs", type=int, default=64, help="RTW epochs per centre fit")
    parser.add_argument(
        "--centroid-method", default="dba", choices=["dba", "rtw"],
        help="averaging of the centroids per class (section 3; default dba)",
    )  # fmt: skip
    args = parser.parse_args(argv)
    warnings.filterwarnings("ignore", module="tslearn")
    if args.datasets:
        names = args.datasets
    elif args.all:
        names = available_datasets(args.data_dir)
    else:
        names = list(AEON_BUNDLED)
    if "tslearn" in args.sections:
        section_tslearn(names, args.data_dir, args.epochs)
    if "manifolds" in args.sections:
        section_manifolds(args.demo_dir, args.epochs)
    if "centroids" in args.sections:
        section_centroids(names, args.data_dir, args.centroid_method)
    if "classify" in args.sections:
        section_classify(args.demo_dir, args.epochs)


if __name__ == "__main__":
    main()
