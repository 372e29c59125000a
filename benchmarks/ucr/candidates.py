"""How the default classifier's choice rule was chosen: every candidate, and rules on the halves.

For every dataset, every candidate of the choice (Sakoe-Chiba band x centroids per class)
is fitted as a fixed classifier, ``RTWNearestCentroid(method=M, dtw_window=w,
n_centroids=k)``, and scored on the test split; the same candidates' leave-one-out
nearest-medoid outcomes on the training split (what the choice sees) are computed from one
DTW matrix per band. Rules are then compared per half of the archive by the test accuracy
of the candidate each picks, against 1-NN DTW (squared point costs and no band, as aeon's
``KNeighborsTimeSeriesClassifier`` of the UCR benchmark): fixed candidates,
the best leave-one-out score, and a prior kept unless a candidate is better by ``z``
standard errors (the default's rule, :mod:`sk_rtw.estimators._selection`).

Example::

    python benchmarks/ucr/candidates.py --data-dir ../shared/ucr --all --methods rtw dba

Per-dataset results go to ``--out`` (default ``results/candidates``, one JSON file each,
reused when present); the tables are printed at the end.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository; then _shared

from benchmarks._shared import check_writable, existing_directory
from benchmarks.ucr._data import available_datasets, load_split
from benchmarks.ucr._summary import split_halves
from sk_rtw import RTWNearestCentroid, dtw_pairwise_distance
from sk_rtw.estimators._medoids import loo_class_distances
from sk_rtw.estimators._selection import mcnemar

BANDS = (0.0, 0.05, 0.1, 0.2, None)
CENTROIDS = (1, 2, 4, 8, 16)


def key(window, k) -> str:
    return f"{window}|{k}"


def measure(name: str, data_dir: str, methods, seed: int) -> dict:
    """Test accuracy of every candidate per method, leave-one-out outcomes, 1-NN DTW."""
    train, test = load_split(name, "train", data_dir), load_split(name, "test", data_dir)
    classes, codes = np.unique(train.y, return_inverse=True)
    record: dict = {"dataset": name, "loo": {}, "test": {m: {} for m in methods}}
    for window in BANDS:
        D = dtw_pairwise_distance(train.X, window=window)
        for k in CENTROIDS:
            held_out = loo_class_distances(D, codes, len(classes), k)
            record["loo"][key(window, k)] = (held_out.argmin(1) == codes).astype(int).tolist()
            for method in methods:
                clf = RTWNearestCentroid(method=method, dtw_window=window, n_centroids=k,
                                         random_state=seed).fit(train.X, train.y)  # fmt: skip
                record["test"][method][key(window, k)] = clf.score(test.X, test.y)
    nearest = dtw_pairwise_distance(test.X, train.X, squared=True).argmin(1)  # aeon's 1-NN
    record["1nn"] = float((train.y[nearest] == test.y).mean())
    return record


def prior_rule(loo: dict, prior: str, z: float, grid) -> str:
    """The prior unless a candidate beats it by ``z`` standard errors (fewest centroids,
    then narrowest band, among the best)."""
    base = np.asarray(loo[prior], bool)
    stats = {c: mcnemar(np.asarray(loo[c], bool), base) for c in grid}
    best = max(stats.values())
    if best < z:
        return prior
    return min((c for c in grid if stats[c] >= best - 1e-12), key=order)


def order(candidate: str):
    window, k = candidate.split("|")
    return int(k), 2.0 if window == "None" else float(window)


def report(records: list[dict], method: str) -> list[str]:
    names = sorted(r["dataset"] for r in records)
    by_name = {r["dataset"]: r for r in records}
    halves = dict(zip(("A", "B"), split_halves(names), strict=True))
    grid = [key(w, k) for w in BANDS if w is not None for k in CENTROIDS if k <= 8]
    fixed = [key(w, k) for w, k in ((0.05, 16), (0.05, 8), (0.1, 8), (0.05, 4))]
    rules = {f"fixed w={c.replace('|', ', k=')}": (lambda r, c=c: c) for c in fixed}
    rules["best leave-one-out score"] = lambda r: max(
        grid, key=lambda c: (np.mean(r["loo"][c]), tuple(-x for x in order(c)))
    )
    for prior in (key(0.05, 8), key(0.1, 8)):
        for z in (0.5, 1.0, 1.5):
            rules[f"prior {prior.replace('|', ', k=')}, z={z}"] = lambda r, p=prior, z=z: (
                prior_rule(r["loo"], p, z, grid)
            )
    lines = [f"\n{method}: test accuracy of the candidate each rule picks, minus 1-NN DTW "
             "(points), and datasets at least as accurate as 1-NN DTW",
             "| rule | half A | half B |", "| --- | --- | --- |"]  # fmt: skip
    for label, rule in rules.items():
        cells = []
        for half in ("A", "B"):
            picked = [by_name[n]["test"][method][rule(by_name[n])] for n in halves[half]]
            nearest = [by_name[n]["1nn"] for n in halves[half]]
            diff = 100 * (np.mean(picked) - np.mean(nearest))
            wins = sum(a >= b - 1e-12 for a, b in zip(picked, nearest, strict=True))
            cells.append(f"{diff:+.2f} ({wins}/{len(picked)})")
        lines.append(f"| {label} | {cells[0]} | {cells[1]} |")
    return lines


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(
        description=__doc__.splitlines()[0],
        epilog=__doc__.split("Example::")[1],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--data-dir", type=existing_directory, required=True)
    which = parser.add_mutually_exclusive_group(required=True)
    which.add_argument("--datasets", nargs="+")
    which.add_argument("--all", action="store_true")
    parser.add_argument("--methods", nargs="+", choices=["rtw", "dba"], default=["dba"])
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default="results/candidates")
    args = parser.parse_args(argv)
    out = check_writable(args.out, directory=True)
    names = args.datasets or available_datasets(args.data_dir)
    records = []
    for name in names:
        path = out / f"{name}.json"
        record = json.loads(path.read_text()) if path.is_file() else None
        if record is None or any(m not in record["test"] for m in args.methods):
            record = measure(name, args.data_dir, args.methods, args.seed)
            path.write_text(json.dumps(record))
            print(f"{name}: done", file=sys.stderr, flush=True)
        records.append(record)
    for method in args.methods:
        print("\n".join(report(records, method)))


if __name__ == "__main__":
    main()
