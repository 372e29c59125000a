"""A readout over the distances to every training series, beside the nearest centroid.

Usage::

    python benchmarks/ucr/series_features.py --data-dir ../shared/ucr --halves A B --seeds 0

The prototype classifier reads out distances to centroids. This script measures the
richest readout of that kind a small training set allows: the DTW distances of a series
to *every* training series as its features (Kate, "Using dynamic time warping distances
as features for improved time series classification", 2016), ``log1p``, standardised,
``RidgeClassifierCV`` (the prototype classifier's default readout). Per dataset, on one
thread: ``RTWNearestCentroid(random_state=seed)`` fitted (its accuracy and its chosen
band, which every other row uses), 1-NN DTW at that band, and the readout twice: with
the training rows as they are (a series' distance to itself is 0, a value no test series
shows) and with that entry replaced by the series' distance to its nearest other
training series. Mean accuracy per half and seed is printed; ``--out`` keeps every
dataset's row (JSON lines, appended as each finishes; a rerun skips what is there).
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
from sk_rtw import RTWNearestCentroid, dtw_pairwise_distance
from sk_rtw.estimators._prototypes import default_readout

ROWS = ("nearest_centroid", "one_nn", "series_readout", "series_readout_nearest_other")


def readout_accuracy(train_features, train_y, test_features, test_y) -> float:
    readout = default_readout().fit(np.log1p(train_features), train_y)
    return float(np.mean(readout.predict(np.log1p(test_features)) == test_y))


def measure(name: str, seed: int, data_dir: str) -> dict:
    train, test = load_split(name, "train", data_dir), load_split(name, "test", data_dir)
    centroids = RTWNearestCentroid(random_state=seed, n_jobs=1).fit(train.X, train.y)
    window = centroids.dtw_window_
    among = dtw_pairwise_distance(train.X, window=window)
    across = dtw_pairwise_distance(test.X, train.X, window=window)
    others = among.copy()
    np.fill_diagonal(others, np.inf)
    nearest_other = others.copy()
    np.fill_diagonal(nearest_other, others.min(1))
    return {
        "dataset": name, "seed": seed, "window": window, "n_train": len(train.y),
        "nearest_centroid": float(np.mean(centroids.predict(test.X) == test.y)),
        "one_nn": float(np.mean(train.y[across.argmin(1)] == test.y)),
        "series_readout": readout_accuracy(among, train.y, across, test.y),
        "series_readout_nearest_other": readout_accuracy(nearest_other, train.y, across,
                                                         test.y),
    }  # fmt: skip


def main(argv=None) -> None:
    args = halves_parser(__doc__.splitlines()[0], out_required=False).parse_args(argv)
    print(f"machine: {machine()}; one thread", flush=True)
    records = read_records(args.out)
    with threadpool_limits(1):
        for record in measure_missing(args, records, measure):
            shown = ", ".join(f"{row} {record[row]:.3f}" for row in ROWS)
            print(f"{record['dataset']} seed {record['seed']}: {shown}", flush=True)
    print_half_means(records, args, list(ROWS))


if __name__ == "__main__":
    main()
