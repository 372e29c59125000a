"""The prototype classifier's decision rule: leave-one-out against refits on folds, one fit.

Usage::

    python benchmarks/ucr/prototype_decision.py --data-dir ../shared/ucr --halves A B \\
        --seeds 0 1 2 --out results/decision_dev.jsonl
    python benchmarks/ucr/prototype_decision.py --data-dir ../shared/ucr_large \\
        --halves C1 C2 --seeds 0 --out results/decision_large.jsonl

For every dataset and seed, on one thread (BLAS included): ``RTWNearestCentroid()`` and
``RTWPrototypeClassifier()`` fitted and timed (fit, prediction of the test set), then,
from the prototype fit's own out-of-fold distances, the decision of ``decision="auto"``
by both rules: the default readout's closed-form leave-one-out predictions (the
classifier's rule) and the rule it replaced, five readouts refitted on the folds of the
out-of-fold distances. Test accuracy under each rule (the readout's and the nearest
centroid's predictions are both computed). Each dataset's record is appended to
``--out`` as it finishes (JSON lines; a rerun skips what is there), then the summary per
half and seed is printed: mean accuracy of the nearest centroid and of both rules, the
datasets where the rules decide differently, and the fit and prediction of the
prototype classifier against the nearest centroid's.
"""

from __future__ import annotations

import functools
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np
from sklearn.utils import check_random_state
from threadpoolctl import threadpool_limits

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository; then _shared

from benchmarks._shared import machine
from benchmarks.ucr._data import load_split
from benchmarks.ucr._halves_cli import halves_parser, measure_missing, read_records
from benchmarks.ucr._summary import FIXED_HALVES
from sk_rtw import RTWNearestCentroid, RTWPrototypeClassifier
from sk_rtw.estimators._out_of_fold import split_folds
from sk_rtw.estimators._prototypes import default_readout
from sk_rtw.estimators._readout_cv import fit_readout
from sk_rtw.estimators._selection import Z_THRESHOLD, mcnemar


def refitted_on_folds(clf: RTWPrototypeClassifier, features, codes, seed: int) -> np.ndarray:
    """The former rule's predictions: the default readout refitted on the folds."""
    predicted = np.empty_like(codes)
    fold_seed = check_random_state(seed).randint(2**31 - 1)
    for train, test in split_folds(clf.cv, codes, fold_seed):
        if len(np.unique(codes[train])) < 2:
            predicted[test] = codes[train][0]
            continue
        readout = fit_readout(default_readout(), features[train], codes[train])
        predicted[test] = readout.predict(features[test])
    return predicted


def fit_and_predict(estimator, train, test):
    """The fitted estimator, its test predictions, and the seconds of each."""
    start = time.perf_counter()
    estimator.fit(train.X, train.y)
    middle = time.perf_counter()
    predicted = estimator.predict(test.X)
    return estimator, predicted, middle - start, time.perf_counter() - middle


def warm_up() -> None:
    """Both classifiers once on a small generated set, untimed: compilation and cache
    loading stay out of the first dataset's times."""
    from sk_rtw.datasets import make_warped_signals

    X = np.concatenate([make_warped_signals("euclidean", 12, 40, random_state=s).signals
                        for s in (0, 1)])  # fmt: skip
    y = np.repeat([0, 1], 12)
    X[12:] = X[12:, ::-1]
    RTWNearestCentroid(random_state=0, n_jobs=1).fit(X, y).predict(X)
    RTWPrototypeClassifier(random_state=0, n_jobs=1).fit(X, y).predict(X)


def measure(name: str, seed: int, data_dir: str, cv: int = 5) -> dict:
    train, test = load_split(name, "train", data_dir), load_split(name, "test", data_dir)
    _, nc_predicted, nc_fit, nc_predict = fit_and_predict(
        RTWNearestCentroid(random_state=seed, n_jobs=1), train, test
    )
    clf, predicted, fit, predict = fit_and_predict(
        RTWPrototypeClassifier(random_state=seed, n_jobs=1, cv=cv), train, test
    )

    codes = np.searchsorted(clf.classes_, train.y)
    features = clf._features(clf.oof_distances_)
    by_class = np.stack(
        [clf.oof_distances_[:, clf.centroid_classes_ == c].min(1)
         for c in range(len(clf.classes_))], axis=1,
    )  # fmt: skip
    z_folds = float(mcnemar(refitted_on_folds(clf, features, codes, seed) == codes,
                            by_class.argmin(1) == codes))  # fmt: skip
    folds_decision = "readout" if z_folds >= Z_THRESHOLD else "nearest"
    test_features = clf._features(clf.transform(test.X))
    by_readout = clf.classes_[np.asarray(clf.readout_.predict(test_features), dtype=np.int64)]
    by_nearest = clf.centroids_.predict(test.X)

    def accuracy(labels) -> float:
        return float(np.mean(labels == test.y))

    half = next((h for h, members in FIXED_HALVES.items() if name in members), "-")
    return {
        "dataset": name, "seed": seed, "half": half, "cv": cv,
        "n_means": len(clf.centroid_classes_),
        "nearest_centroid": accuracy(nc_predicted), "prototype": accuracy(predicted),
        "decision": clf.decision_, "z": clf.cv_accuracy_["z"],
        "folds_decision": folds_decision, "folds_z": z_folds,
        "folds_rule": accuracy(by_readout if folds_decision == "readout" else by_nearest),
        "readout": accuracy(by_readout), "nearest": accuracy(by_nearest),
        "nc_fit": nc_fit, "nc_predict": nc_predict, "fit": fit, "predict": predict,
    }  # fmt: skip


def summary(records: list[dict]) -> None:
    groups: dict[tuple[str, int], list[dict]] = defaultdict(list)
    for record in records:
        groups[(record["half"], record["seed"])].append(record)
    print("| half | seed | sets | nearest centroid | leave-one-out rule | folds rule | "
          "fit / NC fit | predict / NC predict |")  # fmt: skip
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for (half, seed), rows in sorted(groups.items()):

        def mean(key: str, rows=rows) -> float:
            return float(np.mean([r[key] for r in rows]))

        def ratio(key: str, base: str, rows=rows) -> float:
            return sum(r[key] for r in rows) / sum(r[base] for r in rows)

        print(
            f"| {half} | {seed} | {len(rows)} | {mean('nearest_centroid'):.4f} | "
            f"{mean('prototype'):.4f} | {mean('folds_rule'):.4f} | "
            f"{ratio('fit', 'nc_fit'):.2f} ({sum(r['fit'] for r in rows):.1f} s) | "
            f"{ratio('predict', 'nc_predict'):.2f} |"
        )
    print("\nWhere the rules differ or the readout decides:")
    for r in records:
        if r["decision"] != r["folds_decision"] or r["decision"] == "readout":
            print(
                f"- {r['dataset']} seed {r['seed']}: leave-one-out {r['decision']} "
                f"(z = {r['z']:.2f}, {r['prototype']:.4f}), folds {r['folds_decision']} "
                f"(z = {r['folds_z']:.2f}, {r['folds_rule']:.4f}); fit {r['fit']:.1f} s "
                f"against {r['nc_fit']:.1f} s"
            )


def main(argv=None) -> None:
    parser = halves_parser(__doc__.splitlines()[0])
    parser.add_argument("--cv", type=int, default=5, help="the classifier's folds (cv)")
    args = parser.parse_args(argv)
    print(f"machine: {machine()}; one thread", flush=True)
    # records of other folds in the same file are left out (and not counted as done)
    records = [r for r in read_records(args.out) if r.get("cv", 5) == args.cv]
    with threadpool_limits(1):
        warm_up()
        measured = functools.partial(measure, cv=args.cv)
        for record in measure_missing(args, records, measured):
            print(
                f"{record['dataset']} seed {record['seed']}: {record['decision']} "
                f"({record['prototype']:.4f}), fit {record['fit']:.1f} s",
                flush=True,
            )
    summary([r for r in records if r["seed"] in args.seeds])


if __name__ == "__main__":
    main()
