"""The proximity forest's cost against Proximity Forest 2.0's C++ and aeon's 1-NN DTW.

Usage::

    python benchmarks/forest_speed.py --data-dir ../shared/ucr --halves A B \
        --out results/forest_speed.jsonl
    python benchmarks/forest_speed.py --data-dir ../shared/ucr_large --halves C1 C2 \
        --out results/forest_speed_c.jsonl

For every dataset of the halves and every seed (after a warm-up forest of two trees on a
few series, so that compiling is not timed), :class:`sk_rtw.RTWProximityForest`
(``random_state=seed``, ``n_jobs=1``, everything else default; ``--elastic``: the elastic
forest, ``splitters=[ElasticSplitter()]``, with an ``--out`` of its own) is fitted and
asked to predict the test split on one thread; the CPU seconds of each (``time.process_time``:
wall time depends on what else the machine runs) are kept with the test accuracy, and
so are the CPU seconds per test series of aeon's 1-NN DTW (full window, one thread) on at
most ``--dtw-series`` test series. Records are JSON lines appended one dataset at a time
(a rerun skips what is there), with the fitted forest's pickle size beside the training
series' size and the growth of the process's peak resident memory during the fit (0
where the peak came before it, as while loading the data). ``--parallel`` also times
the fit with ``n_jobs=2`` against ``n_jobs=1`` in wall seconds (the speed-up of two
threads).

The summary gives, per half, the forest's total fit and prediction CPU seconds against
Proximity Forest 2.0's C++ on the same machine kind, taken as ``--pf2-factor`` (0.6)
times its published one-CPU seconds (``PF2_train_s``, ``PF2_test_s`` of
``published_results.csv``; the factor is what ``../shared/tools/pf2_cpp`` measured when
it built and ran that C++ on this machine kind: 0.59 for training, 0.67 for testing,
median of six datasets), and the median over datasets of the forest's prediction time
per series over 1-NN DTW's.
"""

from __future__ import annotations

import argparse
import os
import pickle
import resource
import sys
import time
from pathlib import Path

import numpy as np
from sklearn.base import clone

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository

from benchmarks.studies._halves_cli import (
    halves_parser,
    measure_missing,
    read_records,
)
from benchmarks.ucr._data import load_split
from benchmarks.ucr._published import PF2_TIMES, default_published, read_published
from benchmarks.ucr._summary import FIXED_HALVES
from sk_rtw import ElasticSplitter, RTWProximityForest

#: Proximity Forest 2.0's C++ seconds on this machine kind over its published seconds.
PF2_FACTOR = 0.6


def _cpu(call):
    start = time.process_time()
    value = call()
    return value, time.process_time() - start


def _wall(call) -> float:
    start = time.perf_counter()
    call()
    return time.perf_counter() - start


def _rss_bytes() -> int:
    """This process's resident memory now (Linux), 0 where unknown."""
    try:
        with open("/proc/self/statm") as handle:
            return int(handle.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0


def _peak_rss_bytes() -> int:
    """The largest resident memory this process has had (Linux reports kilobytes)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def _series_bytes(X) -> int:
    return sum(np.asarray(s).nbytes for s in X) if isinstance(X, list) else np.asarray(X).nbytes


def _aeon(X) -> np.ndarray | list[np.ndarray]:
    """Series in aeon's channels-first layout."""
    if isinstance(X, list):
        return [np.asarray(s, dtype=float).reshape(len(s), -1).T for s in X]
    return np.asarray(X, dtype=float)[:, None, :]


def _warm_up(train) -> None:
    """Two trees on a few series of every class: the kernels compiled (or loaded from
    numba's cache) for these series before anything is timed or its memory read."""
    rows = np.concatenate([np.flatnonzero(train.y == c)[:3] for c in np.unique(train.y)])
    X = [train.X[i] for i in rows] if isinstance(train.X, list) else train.X[rows]
    forest = RTWProximityForest(n_trees=2, random_state=0, n_jobs=1).fit(X, train.y[rows])
    forest.predict(X)


def measure(name: str, seed: int, data_dir: str, args: argparse.Namespace) -> dict:
    """One dataset and seed: the forest's CPU seconds and accuracy, 1-NN DTW's seconds
    per test series (and the two-thread fit if asked)."""
    from aeon.classification.distance_based import KNeighborsTimeSeriesClassifier

    train, test = load_split(name, "train", data_dir), load_split(name, "test", data_dir)
    _warm_up(train)
    splitters = [ElasticSplitter()] if args.elastic else None
    forest = RTWProximityForest(random_state=seed, n_jobs=1, splitters=splitters)
    before = _rss_bytes()
    _, fit = _cpu(lambda: forest.fit(train.X, train.y))
    peak = max(0, _peak_rss_bytes() - before)  # 0 where the peak came before the fit
    predicted, predict = _cpu(lambda: forest.predict(test.X))
    record = {
        "dataset": name, "seed": seed, "n_train": len(train.y), "n_test": len(test.y),
        "accuracy": float(np.mean(predicted == test.y)), "fit_cpu": fit,
        "predict_cpu": predict, "predict_per_series": predict / len(test.y),
        "train_bytes": _series_bytes(train.X), "pickle_bytes": len(pickle.dumps(forest)),
        "fit_peak_rss_increase": peak,
    }  # fmt: skip
    if args.dtw_series > 0:
        rows = np.random.default_rng(seed).permutation(len(test.y))[: args.dtw_series]
        queries = [test.X[i] for i in rows] if isinstance(test.X, list) else test.X[rows]
        knn = KNeighborsTimeSeriesClassifier(distance="dtw", n_neighbors=1, n_jobs=1)
        knn.fit(_aeon(train.X), train.y)
        knn.predict(_aeon(queries[:1]))  # compiled before it is timed
        _, dtw = _cpu(lambda: knn.predict(_aeon(queries)))
        record["dtw_per_series"] = dtw / len(rows)
    if args.parallel:
        one = _wall(lambda: clone(forest).set_params(n_jobs=1).fit(train.X, train.y))
        two = _wall(lambda: clone(forest).set_params(n_jobs=2).fit(train.X, train.y))
        record["fit_wall_1"], record["fit_wall_2"] = one, two
    return record


def summary(records: list[dict], args: argparse.Namespace) -> list[str]:
    """Per half and seed: totals against Proximity Forest 2.0's C++, the median ratio to
    1-NN DTW's prediction, the mean accuracy against PF 2.0's published split 0."""
    path = args.published or default_published(args.data_dir) or default_published(
        str(Path(args.data_dir).parent / "ucr")
    )
    if path is None:
        return ["(no published_results.csv beside the data: pass --published)"]
    published = read_published(path)
    lines = [
        "| half | seed | sets | fit CPU s | PF2 C++ fit s | ratio | predict CPU s | "
        "PF2 C++ predict s | ratio | predict / 1-NN DTW (median) | accuracy | PF2 split 0 |",
        "|" + " --- |" * 12,
    ]
    for seed in args.seeds:
        for half in args.halves:
            rows = [
                r for r in records
                if r["dataset"] in FIXED_HALVES[half] and r["seed"] == seed
                and all(published.get(r["dataset"], {}).get(c) for c in PF2_TIMES)
            ]  # fmt: skip
            if not rows:
                continue
            fit = sum(r["fit_cpu"] for r in rows)
            predict = sum(r["predict_cpu"] for r in rows)
            pf2_fit = args.pf2_factor * sum(published[r["dataset"]]["PF2_train_s"] for r in rows)
            pf2_predict = args.pf2_factor * sum(
                published[r["dataset"]]["PF2_test_s"] for r in rows
            )
            dtw = [r["predict_per_series"] / r["dtw_per_series"] for r in rows
                   if r.get("dtw_per_series")]  # fmt: skip
            accuracy = np.mean([r["accuracy"] for r in rows])
            pf2_accuracy = np.mean([published[r["dataset"]]["PF2_split0"] for r in rows])
            lines.append(
                f"| {half} | {seed} | {len(rows)} | {fit:.1f} | {pf2_fit:.1f} | "
                f"{fit / pf2_fit:.2f}x | {predict:.1f} | {pf2_predict:.1f} | "
                f"{predict / pf2_predict:.2f}x | "
                f"{f'{np.median(dtw):.2f}x' if dtw else '-'} | {accuracy:.4f} | "
                f"{pf2_accuracy:.4f} |"
            )
    parallel = [r for r in records if "fit_wall_2" in r]
    if parallel:
        one = sum(r["fit_wall_1"] for r in parallel)
        two = sum(r["fit_wall_2"] for r in parallel)
        lines += [
            "",
            f"n_jobs=2 against n_jobs=1, fit wall seconds over {len(parallel)} dataset runs: "
            f"{one:.1f} / {two:.1f} s, {one / two:.2f}x faster",
        ]
    return lines


def main(argv: list[str] | None = None) -> None:
    parser = halves_parser(__doc__.splitlines()[0], out_required=False)
    add = parser.add_argument
    add("--dtw-series", type=int, default=300,
        help="test series 1-NN DTW predicts per dataset (0: none)")  # fmt: skip
    add("--parallel", action="store_true",
        help="also time the fit with n_jobs=2 against n_jobs=1 (wall seconds)")  # fmt: skip
    add("--elastic", action="store_true",
        help="the elastic forest (splitters=[ElasticSplitter()]) instead of the default "
        "(records of its own: give it another --out)")  # fmt: skip
    add("--pf2-factor", type=float, default=PF2_FACTOR,
        help="PF 2.0's C++ seconds on this machine kind over its published seconds")  # fmt: skip
    add("--published", type=Path, default=None,
        help="published_results.csv (default: in --data-dir, or in ../ucr beside it)")  # fmt: skip
    args = parser.parse_args(argv)
    records = read_records(args.out)
    def one(name: str, seed: int, data_dir: str) -> dict:
        return measure(name, seed, data_dir, args)

    for record in measure_missing(args, records, one):
        memory = (f", pickle {record['pickle_bytes'] / 1e6:.2f} MB (training series "
                  f"{record['train_bytes'] / 1e6:.2f} MB), fit peak +"
                  f"{record['fit_peak_rss_increase'] / 1e6:.0f} MB")  # fmt: skip
        ratio = (f", 1-NN DTW {record['predict_per_series'] / record['dtw_per_series']:.2f}x"
                 if record.get("dtw_per_series") else "")  # fmt: skip
        print(f"{record['dataset']} seed {record['seed']}: fit {record['fit_cpu']:.1f} s, "
              f"predict {record['predict_cpu']:.1f} s{ratio}, accuracy "
              f"{record['accuracy']:.4f}{memory}", flush=True)  # fmt: skip
    print("\n".join(["", *summary(records, args)]))


if __name__ == "__main__":
    main()
