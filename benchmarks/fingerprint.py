"""The library's outputs on a fixed set of inputs, to compare two versions bit for bit.

Usage::

    python benchmarks/fingerprint.py --out after.npz           # this checkout
    git worktree add ../before 202adb0 && cp benchmarks/fingerprint.py ../before/benchmarks/
    (cd ../before && python benchmarks/fingerprint.py --out ../main/before.npz)
    python benchmarks/fingerprint.py --compare before.npz after.npz

The script measures the checkout it lies in (it puts its own repository first on the
path), so a copy of it goes into the other checkout.

A refactoring that must not change any result (a module moved, a formula written once
instead of twice) is checked by running this on both versions: every array is compared
byte for byte, and the keys only one side has are listed. The set: DTW distances
(pairwise with and without a band, squared or not, amerced), paths, nearest searches and
tangent velocities on R^1, R^3, S^1, S^2, unit quaternions, SPD(2), SPD(3), SPD(4) and
poses; ``align`` (RTW on each, TTW and NTW on three); and the estimators on aeon's
GunPoint, ItalyPowerDemand and ArrowHead (the default nearest-centroid classifier with
DBA and with a short RTW, the representation choice, the prototype classifier with an
int and with a RandomState seed, the proximity forest with series and with mean
exemplars and the elastic forest alone, k-means: probabilities or scores, predictions,
choices, means, out-of-fold distances) and on generated quaternion and SPD series.
``--quick`` keeps the manifold part only (a minute; the estimators need aeon's bundled
data). Uses the public API only, so the same file runs on any version since the API it
calls existed.
"""

from __future__ import annotations

import argparse
import hashlib
import sys
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository

import sk_rtw
from sk_rtw import (
    RTWKMeans,
    RTWNearestCentroid,
    RTWPrototypeClassifier,
    RTWProximityForest,
    align,
    dtw_nearest_distance,
    dtw_pairwise_distance,
    dtw_path,
    get_manifold,
)
from sk_rtw.datasets import make_warped_signals
from sk_rtw.methods import RTW

#: The elastic forest (Proximity Forest 2.0's recipe alone; the default forest of the
#: versions before shapelet candidates), where the version has splitters.
ELASTIC = {"splitters": (sk_rtw.ElasticSplitter(),)} if hasattr(sk_rtw, "ElasticSplitter") else {}

MANIFOLDS = {
    "euc1": sk_rtw.Euclidean(1), "euc3": sk_rtw.Euclidean(3), "s1": sk_rtw.Sphere(1),
    "s2": sk_rtw.Sphere(2), "quat": sk_rtw.Quaternion(), "spd2": sk_rtw.SPD(2),
    "spd3": sk_rtw.SPD(3), "spd4": sk_rtw.SPD(4), "pose": get_manifold("pose"),
}  # fmt: skip


class Record(dict):
    """Arrays by key; each one's short hash printed as it is added (``verbose``)."""

    def __init__(self, verbose: bool) -> None:
        super().__init__()
        self.verbose = verbose

    def put(self, key: str, value) -> None:
        array = np.asarray(value)
        self[key] = array
        if self.verbose:
            print(key, hashlib.sha1(array.tobytes()).hexdigest()[:12], flush=True)


def _series(manifold, n: int, length: int) -> list[np.ndarray]:
    return [np.asarray(make_warped_signals(manifold, 1, length + i, random_state=i).signals[0])
            for i in range(n)]  # fmt: skip


def manifold_part(out: Record) -> None:
    for name, manifold in MANIFOLDS.items():
        X = _series(manifold, 6, 24)
        for window in (None, 0.1):
            for squared in (False, True):
                out.put(f"pw/{name}/{window}/{squared}",
                        dtw_pairwise_distance(X, manifold=manifold, window=window,
                                              squared=squared))  # fmt: skip
        out.put(f"pw/{name}/adtw",
                dtw_pairwise_distance(X, manifold=manifold, window=0.2, warp_penalty=0.5))
        path, cost = dtw_path(X[0], X[1], manifold=manifold)
        out.put(f"path/{name}", np.r_[np.ravel(path), cost])
        groups = np.array([0, 0, 1, 1, 2, 2])
        out.put(f"nn/{name}",
                dtw_nearest_distance(X[:3], X, groups=groups, manifold=manifold, window=0.1))
        velocity = sk_rtw.tangent_velocity(X[:2], manifold=manifold)
        out.put(f"vel/{name}", np.concatenate([np.ravel(v) for v in velocity]))
        for method in ("rtw", "ttw", "ntw"):
            if method != "rtw" and name not in ("euc1", "s2", "spd2"):
                continue
            data = np.stack([x[:24] for x in X[:4]]) if name == "euc3" else X[:4]
            result = align(data, manifold=manifold, method=method, n_epochs=6, random_state=0)
            out.put(f"align/{name}/{method}/mean", result.mean)
            out.put(f"align/{name}/{method}/warps",
                    np.concatenate([np.ravel(w) for w in result.warps]))


def _scores(estimator, X):
    if hasattr(estimator, "predict_proba"):
        return estimator.predict_proba(X)
    return estimator.decision_function(X)


def estimator_part(out: Record) -> None:
    from aeon.datasets import load_classification

    for dataset in ("GunPoint", "ItalyPowerDemand", "ArrowHead"):
        X, y = load_classification(dataset, split="train")
        X_test, _ = load_classification(dataset, split="test")
        X, X_test = X[:, 0], X_test[:, 0]
        estimators = {
            "nc-dba": RTWNearestCentroid(method="dba", random_state=0),
            "nc-rtw8": RTWNearestCentroid(method=RTW(n_epochs=8), random_state=0),
            "nc-dba-auto": RTWNearestCentroid(
                method="dba", representation="auto", random_state=0
            ),
            "nc-dba-1": RTWNearestCentroid(
                method="dba", n_centroids=1, dtw_window=0.1, random_state=1
            ),
            "proto-dba": RTWPrototypeClassifier(method="dba", random_state=0),
            "proto-dba-rs": RTWPrototypeClassifier(method="dba",
                                                   random_state=np.random.RandomState(3)),
            "forest": RTWProximityForest(n_trees=6, random_state=0),
            "forest-mean": RTWProximityForest(n_trees=3, exemplars="mean", random_state=1),
            "forest-elastic": RTWProximityForest(n_trees=6, random_state=0, **ELASTIC),
        }
        for label, estimator in estimators.items():
            if dataset == "ArrowHead" and label == "nc-rtw8":
                continue
            estimator.fit(X, y)
            key = f"{dataset}/{label}"
            out.put(f"{key}/proba", _scores(estimator, X_test))
            out.put(f"{key}/pred", estimator.predict(X_test).astype(str).astype("S"))
            if hasattr(estimator, "oof_distances_"):
                out.put(f"{key}/oof", estimator.oof_distances_)
            for attribute in ("dtw_window_", "n_centroids_", "temperature_", "decision_",
                              "cv_accuracy_", "representation_"):  # fmt: skip
                if hasattr(estimator, attribute):
                    value = np.asarray(getattr(estimator, attribute), dtype=object)
                    out.put(f"{key}/{attribute}", value.astype(str).astype("S"))
            if hasattr(estimator, "means_"):
                out.put(f"{key}/means", np.concatenate([np.ravel(m) for m in estimator.means_]))
            if hasattr(estimator, "transform"):
                out.put(f"{key}/transform", estimator.transform(X_test[:20]))
        kmeans = RTWKMeans(n_clusters=3, method="dba", random_state=0).fit(X)
        out.put(f"{dataset}/kmeans", kmeans.labels_)
    for name, n, length, estimators in (
        ("quat", 8, 30, {
            "nc": RTWNearestCentroid("quaternion", method=RTW(n_epochs=5), random_state=0),
            "forest": RTWProximityForest("quaternion", n_trees=4, random_state=0),
            "forest-elastic": RTWProximityForest("quaternion", n_trees=4, random_state=0,
                                                 **ELASTIC),
            "proto": RTWPrototypeClassifier("quaternion", method="dba", cv=3, random_state=0),
        }),
        ("spd", 6, 25, {
            "nc": RTWNearestCentroid("spd", method="dba", random_state=0),
            "forest": RTWProximityForest("spd", n_trees=3, random_state=0),
            "forest-elastic": RTWProximityForest("spd", n_trees=3, random_state=0, **ELASTIC),
        }),
    ):  # fmt: skip
        manifold = "quaternion" if name == "quat" else "spd"
        offset = 10 if name == "quat" else 20
        series = np.concatenate([
            np.asarray(make_warped_signals(manifold, n, length, random_state=offset + c).signals)
            for c in range(2)
        ])  # fmt: skip
        labels = np.repeat([0, 1], n)
        for label, estimator in estimators.items():
            estimator.fit(series, labels)
            out.put(f"{name}/{label}", _scores(estimator, series))


def compare(first: str, second: str) -> int:
    """Print the keys that differ or that one side lacks; the number of differences."""
    a, b = np.load(first, allow_pickle=False), np.load(second, allow_pickle=False)
    same, different = 0, []
    for key in sorted(set(a) & set(b)):
        x, y = a[key], b[key]
        if x.shape == y.shape and x.dtype == y.dtype and x.tobytes() == y.tobytes():
            same += 1
        else:
            different.append(key)
    for key in different:
        print(f"different: {key}")
    for key in sorted(set(a) - set(b)):
        print(f"only in {first}: {key}")
    for key in sorted(set(b) - set(a)):
        print(f"only in {second}: {key}")
    print(f"{same} arrays identical, {len(different)} different")
    return len(different)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(
        description=__doc__.splitlines()[0],
        epilog=__doc__.split("Usage::")[1].split("The script measures")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--out", help="write the arrays to this .npz file")
    parser.add_argument("--quick", action="store_true", help="the manifold part only")
    parser.add_argument("--compare", nargs=2, metavar=("FIRST", "SECOND"),
                        help="compare two files written by --out")  # fmt: skip
    parser.add_argument("--quiet", action="store_true", help="no line per array")
    args = parser.parse_args(argv)
    if args.compare:
        return int(compare(*args.compare) > 0)
    if not args.out:
        parser.error("give --out FILE (or --compare FIRST SECOND)")
    warnings.filterwarnings("ignore")
    out = Record(verbose=not args.quiet)
    manifold_part(out)
    if not args.quick:
        estimator_part(out)
    np.savez(args.out, **out)
    print(f"{len(out)} arrays written to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
