"""Manifold time-series classification on R-LASA: leave one demonstration out.

R-LASA's 30 handwriting shapes (``../shared/data/r_lasa``, 4 demonstrations each, 1,000
samples) as unit quaternions (S^3, sign-invariant: ``manifold="quaternion"``) and as
SPD(2) matrices (``manifold="spd"``), every ``--step``-th sample. Fold ``k`` tests on
demonstration ``k`` of every shape and trains on the other three (4 folds, 30 classes of
3 training series). Rows:

* ``prototype``: ``RTWPrototypeClassifier(manifold=...)``, the library's defaults;
* ``nearest-centroid``: ``RTWNearestCentroid(manifold=...)``, the library's defaults;
* ``forest``: ``RTWProximityForest(manifold=...)``, the library's defaults (100 trees,
  elastic and shapelet candidates on the series and their tangent velocity, one thread);
* ``1nn-dtw``: 1-NN by manifold DTW (geodesic point cost, no band);
* ``1nn-dtw-velocity``: 1-NN by DTW of the tangent velocity (``sk_rtw.tangent_velocity``:
  the body angular velocity of the quaternions, the whitened logarithm of the SPD steps;
  Euclidean point cost, no band);
* ``minirocket``: aeon's ``MiniRocketClassifier`` on the coordinates (the 4 quaternion
  components; the 3 distinct entries of a 2 x 2 SPD matrix), which knows no manifold;
* ``minirocket-velocity``: MiniRocket on the tangent velocity
  (``make_pipeline(TangentVelocity(space, output="aeon"), MiniRocketClassifier())``);
* ``shapelets``: ``GeodesicShapeletClassifier(manifold=...)``, the library's defaults;
* ``shapelets-rdst``: the same with RDST's draw (``representation="raw",
  normalised_fraction=0.8``: shapelets from the series only, 80 % normalised);
* ``forest-shapelets``: the same forest with its splitters written out
  (``splitters=[ElasticSplitter(), ShapeletSplitter()]``);
* ``forest-elastic``: the forest with elastic candidates only
  (``splitters=[ElasticSplitter()]``, Proximity Forest 2.0's recipe; the default forest
  before shapelet candidates).

``--frames`` puts every demonstration in a world frame of its own, as a robot's
demonstrations recorded in different frames: a random rotation and sign per
quaternion series (``q -> +-g q``), a congruence by a random rotation per SPD series
(``X -> R X R^T``); the seed of the frames is ``--seed``. ``--spd-velocity-frame world``
gives every SPD row the velocity in the ambient axes (``SPD(2, velocity_frame="world")``,
this library's SPD velocity before the eigenbasis one) instead of the default.

Usage::

    python benchmarks/manifold_classification.py --spaces quaternion --folds 0
    python benchmarks/manifold_classification.py \
        --markdown docs/benchmarks/manifold_classification.md
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation
from sklearn.pipeline import make_pipeline

if __package__ in (None, ""):
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks._shared import check_writable, machine, method_object
from benchmarks.paper._data import data_dir, rlasa_quaternions, rlasa_shapes, rlasa_spd
from sk_rtw import (
    SPD,
    ElasticSplitter,
    GeodesicShapeletClassifier,
    RTWNearestCentroid,
    RTWPrototypeClassifier,
    RTWProximityForest,
    ShapeletSplitter,
    TangentVelocity,
    dtw_pairwise_distance,
    tangent_velocity,
)
from sk_rtw.manifolds import quaternion_product

SPACES = ("quaternion", "spd")
ROWS = ("prototype", "nearest-centroid", "forest", "1nn-dtw", "1nn-dtw-velocity", "minirocket",
        "minirocket-velocity", "shapelets", "shapelets-rdst", "forest-shapelets",
        "forest-elastic")  # fmt: skip


def in_own_frames(demos: np.ndarray, space: str, seed: int) -> np.ndarray:
    """Every demonstration ``demos[shape, demo]`` in a world frame of its own: ``+-g q``
    for a random unit quaternion ``g`` and sign, or ``R X R^T`` for a random rotation."""
    rng = np.random.default_rng(seed)
    out = np.empty_like(demos)
    for index in np.ndindex(*demos.shape[:2]):
        if space == "quaternion":
            g = Rotation.random(random_state=int(rng.integers(2**31))).as_quat()[[3, 0, 1, 2]]
            out[index] = rng.choice([-1.0, 1.0]) * quaternion_product(g, demos[index])
        else:
            angle = rng.uniform(0, 2 * np.pi)
            R = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
            out[index] = R @ demos[index] @ R.T
    return out


def load(space: str, root: Path, step: int) -> tuple[np.ndarray, np.ndarray]:
    """Demonstrations ``(30, 4, T, *point_shape)`` and their shape names."""
    shapes = rlasa_shapes(root)
    loader = rlasa_quaternions if space == "quaternion" else rlasa_spd
    demos = np.stack([loader(root, shape)[:, ::step] for shape in shapes])
    return demos, np.asarray(shapes)


def coordinates(X: np.ndarray, space: str) -> np.ndarray:
    """aeon's layout ``(n, channels, T)`` of the points' coordinates."""
    if space == "spd":
        X = np.stack([X[..., 0, 0], X[..., 0, 1], X[..., 1, 1]], axis=-1)
    return np.moveaxis(X, -1, 1)


def run_fold(space, demos, shapes, fold, rows, method, seed, verbose, manifold=None) -> dict:
    """One fold of every row; ``manifold`` (default: the space's name) is what the
    library's rows are given."""
    name, space = space, space if manifold is None else manifold
    n_demos = demos.shape[1]
    train_demos = [d for d in range(n_demos) if d != fold]
    X_train = demos[:, train_demos].reshape(-1, *demos.shape[2:])
    y_train = np.repeat(shapes, len(train_demos))
    X_test, y_test = demos[:, fold], shapes
    out = {}
    for row in rows:
        start = time.perf_counter()
        if row in ("prototype", "nearest-centroid"):
            cls = RTWPrototypeClassifier if row == "prototype" else RTWNearestCentroid
            model = cls(manifold=space, method=method_object(method), random_state=seed)
            model.fit(X_train, y_train)
            fit = time.perf_counter() - start
            start = time.perf_counter()
            predicted = model.predict(X_test)
            extra = {"decision": model.decision_} if row == "prototype" else {}
        elif row in ("forest", "forest-shapelets", "forest-elastic", "shapelets",
                     "shapelets-rdst"):  # fmt: skip
            if row.startswith("shapelets"):
                rdst = {"representation": "raw", "normalised_fraction": 0.8}
                model = GeodesicShapeletClassifier(manifold=space, random_state=seed, n_jobs=1,
                                                   **(rdst if row == "shapelets-rdst" else {}))
            else:
                splitters = {"forest": None, "forest-elastic": [ElasticSplitter()],
                             "forest-shapelets": [ElasticSplitter(), ShapeletSplitter()]}[row]
                model = RTWProximityForest(manifold=space, random_state=seed, n_jobs=1,
                                           splitters=splitters)  # fmt: skip
            model.fit(X_train, y_train)
            fit = time.perf_counter() - start
            start = time.perf_counter()
            predicted, extra = model.predict(X_test), {}
        elif row == "1nn-dtw":
            fit = 0.0
            D = dtw_pairwise_distance(X_test, X_train, manifold=space)
            predicted, extra = y_train[D.argmin(1)], {}
        elif row == "1nn-dtw-velocity":
            fit = 0.0
            D = dtw_pairwise_distance(tangent_velocity(X_test, space),
                                      tangent_velocity(X_train, space))  # fmt: skip
            predicted, extra = y_train[D.argmin(1)], {}
        elif row == "minirocket-velocity":
            from aeon.classification.convolution_based import MiniRocketClassifier

            model = make_pipeline(TangentVelocity(space, output="aeon"),
                                  MiniRocketClassifier(random_state=seed, n_jobs=1))  # fmt: skip
            model.fit(X_train, y_train)
            fit = time.perf_counter() - start
            start = time.perf_counter()
            predicted, extra = model.predict(X_test), {}
        else:
            from aeon.classification.convolution_based import MiniRocketClassifier

            model = MiniRocketClassifier(random_state=seed, n_jobs=1)
            model.fit(coordinates(X_train, name), y_train)
            fit = time.perf_counter() - start
            start = time.perf_counter()
            predicted, extra = model.predict(coordinates(X_test, name)), {}
        predict = time.perf_counter() - start
        out[row] = {"accuracy": float(np.mean(predicted == y_test)), "fit": fit,
                    "predict": predict, **extra}  # fmt: skip
        if verbose:
            text = (f"{name} fold {fold}: {row} accuracy {out[row]['accuracy']:.3f} "
                    f"(fit {fit:.1f} s, predict {predict:.1f} s)")  # fmt: skip
            print(text, file=sys.stderr, flush=True)
    return out


def warm_up(rows) -> None:
    """Untimed first calls: numba compiles MiniRocket's kernels (univariate and
    multivariate ones: the coordinates have 3 or 4 channels), torch and the DTW kernels
    load (seconds that would land in the first fold's times: 18 s for MiniRocket's
    multivariate kernels)."""
    rng = np.random.default_rng(0)
    X, y = rng.standard_normal((8, 20)).cumsum(1), np.repeat([0, 1], 4)
    if "minirocket" in rows or "minirocket-velocity" in rows:
        from aeon.classification.convolution_based import MiniRocketClassifier

        for channels in (X[:, None], np.stack([X, X[::-1], -X], axis=1)):
            MiniRocketClassifier(random_state=0).fit(channels, y).predict(channels)
    if "prototype" in rows or "nearest-centroid" in rows:
        RTWNearestCentroid(method=method_object("rtw", n_epochs=2)).fit(X, y).predict(X)
    if {"forest", "forest-shapelets", "forest-elastic"} & set(rows):
        RTWProximityForest(n_trees=2, random_state=0).fit(X, y).predict(X)
    if {"shapelets", "shapelets-rdst", "forest-shapelets"} & set(rows):
        GeodesicShapeletClassifier(n_shapelets=20, random_state=0).fit(X, y).predict(X)


def markdown(results: dict, args: argparse.Namespace, command: str) -> str:
    lines = [
        "# Manifold time-series classification: R-LASA, leave one demonstration out",
        "",
        f"Command: `{command}`  ",
        f"Machine: {machine()}; every {args.step}th sample (T = {1000 // args.step}), "
        f"method {args.method}, seed {args.seed}"
        + ("; every demonstration in its own world frame" if args.frames else "")
        + ("" if args.spd_velocity_frame == "eigen" else "; the SPD velocity in world axes")
        + ".",
        "",
        "| space | row | accuracy per fold | mean accuracy | fit s (all folds) | "
        "predict s (all folds) |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for space, folds in results.items():
        for row in args.rows:
            entries = [folds[f][row] for f in sorted(folds)]
            accs = ", ".join(f"{e['accuracy']:.3f}" for e in entries)
            decisions = [e.get("decision") for e in entries if e.get("decision")]
            note = f" (decision: {', '.join(decisions)})" if decisions else ""
            lines.append(
                f"| {space} | {row}{note} | {accs} | "
                f"{np.mean([e['accuracy'] for e in entries]):.3f} | "
                f"{sum(e['fit'] for e in entries):.1f} | "
                f"{sum(e['predict'] for e in entries):.1f} |"
            )
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data-dir", default=None, help="the shared data folder")
    parser.add_argument("--spaces", nargs="+", choices=SPACES, default=list(SPACES))
    parser.add_argument("--rows", nargs="+", choices=ROWS, default=list(ROWS))
    parser.add_argument("--folds", nargs="+", type=int, choices=range(4), default=[0, 1, 2, 3])
    parser.add_argument("--step", type=int, default=5, help="keep every step-th sample")
    parser.add_argument("--method", default="rtw", help="averaging method of the centroids")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--markdown", default=None, help="write the table to this file")
    parser.add_argument("--frames", action="store_true",
                        help="every demonstration in a world frame of its own")  # fmt: skip
    parser.add_argument("--spd-velocity-frame", choices=("eigen", "world"), default="eigen",
                        help="the axes of the SPD tangent velocity")  # fmt: skip
    parser.add_argument("--quiet", action="store_true")
    args = parser.parse_args(argv)
    if args.step < 1:
        parser.error(f"--step must be >= 1, got {args.step}")
    if args.markdown:
        check_writable(args.markdown)
    root = data_dir(args.data_dir)
    warm_up(args.rows)
    results: dict = {}
    for space in args.spaces:
        demos, shapes = load(space, root, args.step)
        if args.frames:
            demos = in_own_frames(demos, space, args.seed)
        results[space] = {}
        manifold = SPD(2, velocity_frame=args.spd_velocity_frame) if space == "spd" else None
        for fold in args.folds:
            results[space][fold] = run_fold(
                space, demos, shapes, fold, args.rows, args.method, args.seed, not args.quiet,
                manifold,
            )
    command = "python benchmarks/manifold_classification.py " + " ".join(
        sys.argv[1:] if argv is None else argv
    )
    text = markdown(results, args, command.strip())
    print(text)
    if args.markdown:
        Path(args.markdown).write_text(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
