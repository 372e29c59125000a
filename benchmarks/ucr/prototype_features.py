"""The prototype classifier's features: one column per centroid, against order-free ones.

Usage::

    python benchmarks/ucr/prototype_features.py --data-dir ../shared/ucr --halves A B \\
        --seeds 0 --out results/features_dev.jsonl
    python benchmarks/ucr/prototype_features.py --data-dir ../shared/ucr_large \\
        --halves C1 C2 --seeds 0 --out results/features_large.jsonl

``RTWPrototypeClassifier`` reads out one feature per centroid: column ``m`` is "the
distance to centroid ``m``", so ``readout_weights_`` can name the centroids that weigh for
and against a class. A readout can also be given features that do not depend on which
centroid of a class is which: every class's distances sorted (``ranked``), its three
nearest (``ranked3``), or its nearest only (``class_min``). Per dataset and seed, on one
thread, ``RTWPrototypeClassifier(random_state=seed)`` is fitted once; from its out-of-fold
training distances and its test distances each feature set gets the default readout
(``log1p`` of the distances over the fit's scale, standardised, ``RidgeClassifierCV``)
and the classifier's decision rule (the readout where its exact leave-one-out
predictions beat the nearest out-of-fold centroid by a standard error). Test accuracy of
the readout alone and under the rule; mean per half printed, every dataset's record
appended to ``--out`` as it finishes (JSON lines; a rerun skips what is there).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository

from benchmarks._shared import machine
from benchmarks.ucr._data import load_split
from benchmarks.ucr._halves_cli import (
    halves_parser,
    measure_missing,
    print_half_means,
    read_records,
)
from sk_rtw import RTWPrototypeClassifier
from sk_rtw.estimators._prototypes import default_readout
from sk_rtw.estimators._readout_cv import fit_readout, ridge_loo_predictions
from sk_rtw.estimators._selection import Z_THRESHOLD, mcnemar

FEATURES = ("centroids", "ranked", "ranked3", "class_min")


def feature_sets(distances: np.ndarray, centroid_classes: np.ndarray) -> dict:
    """Every feature set of the distances (n_series, n_means) to the centroids."""
    by_class = [np.sort(distances[:, centroid_classes == c], axis=1)
                for c in range(int(centroid_classes.max()) + 1)]  # fmt: skip
    return {
        "centroids": distances,
        "ranked": np.concatenate(by_class, axis=1),
        "ranked3": np.concatenate([d[:, :3] for d in by_class], axis=1),
        "class_min": np.stack([d[:, 0] for d in by_class], axis=1),
    }


def measure(name: str, seed: int, data_dir: str) -> dict:
    train, test = load_split(name, "train", data_dir), load_split(name, "test", data_dir)
    clf = RTWPrototypeClassifier(random_state=seed, n_jobs=1).fit(train.X, train.y)
    codes = np.searchsorted(clf.classes_, train.y)
    test_codes = np.searchsorted(clf.classes_, test.y)
    train_sets = feature_sets(clf.oof_distances_, clf.centroid_classes_)
    test_sets = feature_sets(clf.transform(test.X), clf.centroid_classes_)
    nearest_train = train_sets["class_min"].argmin(1)
    nearest_test = test_sets["class_min"].argmin(1)
    record = {"dataset": name, "seed": seed,
              "nearest": float(np.mean(nearest_test == test_codes))}  # fmt: skip
    for features in FEATURES:
        train_features = np.log1p(train_sets[features] / clf.distance_scale_)
        readout = fit_readout(default_readout(), train_features, codes)
        predicted = readout.predict(np.log1p(test_sets[features] / clf.distance_scale_))
        left_out = ridge_loo_predictions(readout, train_features, codes)
        z = float(mcnemar(left_out == codes, nearest_train == codes))
        decided = predicted if z >= Z_THRESHOLD else nearest_test
        record[f"{features}_readout"] = float(np.mean(predicted == test_codes))
        record[f"{features}_rule"] = float(np.mean(decided == test_codes))
        record[f"{features}_z"] = z
    return record


def main(argv=None) -> None:
    args = halves_parser(__doc__.splitlines()[0]).parse_args(argv)
    print(f"machine: {machine()}; one thread", flush=True)
    records = read_records(args.out)
    with threadpool_limits(1):
        for record in measure_missing(args, records, measure):
            rules = ", ".join(f"{f} {record[f + '_rule']:.3f}" for f in FEATURES)
            print(f"{record['dataset']} seed {record['seed']}: {rules}", flush=True)
    columns = ["nearest"] + [f"{f}_{kind}" for f in FEATURES for kind in ("readout", "rule")]
    print_half_means(records, args, columns)


if __name__ == "__main__":
    main()
