"""How the default classifier's choice rule was chosen: every candidate, and rules on the halves.

For every dataset, every candidate of the choice (Sakoe-Chiba band x centroids of every
class: one, or a fraction of the class up to every series) is fitted as a fixed
classifier, ``RTWNearestCentroid(method=M, dtw_window=w, n_centroids=k)``, and scored on
the test split; the candidates' leave-one-out nearest-medoid outcomes on the training
split (what the choice sees, on the same stratified sample of a large training set) come
from :func:`sk_rtw.estimators._selection.held_out_scores`. Rules are then compared per
half (A and B of the development archive, C1 and C2 of the large training sets) by the
test accuracy of the candidate each picks, against 1-NN DTW with squared point costs and
no band (the predictions of aeon's ``KNeighborsTimeSeriesClassifier``, computed here with
sk_rtw's exact nearest-neighbour search): fixed candidates, the best leave-one-out score,
and priors kept unless a candidate is better by ``z`` standard errors (the default's
rule, :class:`sk_rtw.AutoChoice`).

Example::

    python benchmarks/studies/candidates.py --data-dir ../shared/ucr --all --methods rtw dba
    python benchmarks/studies/candidates.py --data-dir ../shared/ucr_large \\
        --datasets Crop Computers AllGestureWiimoteX --methods dba

Per-dataset results go to ``--out`` (default ``results/candidates``, one JSON file each,
reused when present, so runs over several data directories share one report); the tables
are printed at the end for every dataset in ``--out``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository; then _shared

from benchmarks._shared import check_writable, existing_directory
from benchmarks.ucr._data import available_datasets, load_split
from benchmarks.ucr._summary import halves
from sk_rtw import AutoChoice, RTWNearestCentroid, dtw_nearest_distance, dtw_pairwise_distance
from sk_rtw.estimators._selection import (  # the choice's own steps, one by one
    class_partitions,
    held_out_scores,
    mcnemar,
    selection_sample,
)
from sk_rtw.utils import check_series_collection

#: The default candidates (the grid a rule picks from).
WINDOWS, CENTROIDS = AutoChoice().windows, AutoChoice().centroids


def key(window, k) -> str:
    return f"{window}|{k!r}"


def parse(candidate: str):
    window, k = candidate.split("|")
    return (None if window == "None" else float(window)), (float(k) if "." in k else int(k))


def measure(name: str, data_dir: str, methods, seed: int) -> dict:
    """Test accuracy of every candidate per method, leave-one-out outcomes, 1-NN DTW."""
    train, test = load_split(name, "train", data_dir), load_split(name, "test", data_dir)
    classes, codes = np.unique(train.y, return_inverse=True)
    collection = check_series_collection(train.X)
    sample = selection_sample(collection, codes, WINDOWS, np.random.RandomState(seed))
    subset, sampled = collection.subset(sample), codes[sample]
    members = [np.flatnonzero(sampled == c) for c in range(len(classes))]
    record: dict = {"dataset": name, "n_train": len(codes), "n_sample": len(sample),
                    "loo": {}, "test": {m: {} for m in methods},
                    "seconds": {m: {} for m in methods}}  # fmt: skip
    for window in WINDOWS:
        matrices = [dtw_pairwise_distance(subset.subset(m), window=window) for m in members]
        for k in CENTROIDS:
            partition = class_partitions(matrices, members, k)
            held_out = held_out_scores(subset, sampled, partition, window, every_class=False)
            record["loo"][key(window, k)] = (held_out.argmin(1) == sampled).astype(int).tolist()
            for method in methods:
                start = time.perf_counter()
                clf = RTWNearestCentroid(method=method, dtw_window=window, n_centroids=k,
                                         random_state=seed).fit(train.X, train.y)  # fmt: skip
                fit = time.perf_counter() - start
                record["test"][method][key(window, k)] = clf.score(test.X, test.y)
                predict = time.perf_counter() - start - fit
                record["seconds"][method][key(window, k)] = [fit, predict]
            print(f"{name}: {key(window, k)} done", file=sys.stderr, flush=True)
    by_class = dtw_nearest_distance(test.X, train.X, codes, squared=True)
    record["1nn"] = float((classes[by_class.argmin(1)] == test.y).mean())
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
    window, k = parse(candidate)
    count = k - 1e6 if isinstance(k, int) else k
    return count, 2.0 if window is None else window


def report(records: list[dict], method: str) -> list[str]:
    by_name = {r["dataset"]: r for r in records if method in r["test"]}
    parts = halves(sorted(by_name))
    grid = [key(w, k) for w in WINDOWS for k in CENTROIDS]
    rules = {f"fixed w={c.replace('|', ', k=')}": (lambda r, c=c: c) for c in grid}
    rules["best leave-one-out score"] = lambda r: max(
        grid, key=lambda c: (np.mean(r["loo"][c]), tuple(-x for x in order(c)))
    )
    for prior in grid:
        for z in (1.0, 2.0):
            rules[f"prior {prior.replace('|', ', k=')}, z={z}"] = lambda r, p=prior, z=z: (
                prior_rule(r["loo"], p, z, grid)
            )
    lines = [f"\n{method}: test accuracy of the candidate each rule picks, minus 1-NN DTW "
             "(points), and datasets at least as accurate as 1-NN DTW",
             "| rule | " + " | ".join(f"half {h}" for h in parts) + " |",
             "| --- | " + " | ".join("---" for _ in parts) + " |"]  # fmt: skip
    for label, rule in rules.items():
        cells = []
        for names in parts.values():
            picked = [by_name[n]["test"][method][rule(by_name[n])] for n in names]
            nearest = [by_name[n]["1nn"] for n in names]
            diff = 100 * (np.mean(picked) - np.mean(nearest))
            wins = sum(a >= b - 1e-12 for a, b in zip(picked, nearest, strict=True))
            cells.append(f"{diff:+.2f} ({wins}/{len(picked)})")
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
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
    for name in names:
        path = out / f"{name}.json"
        record = json.loads(path.read_text()) if path.is_file() else None
        if record is None or any(m not in record["test"] for m in args.methods):
            record = measure(name, args.data_dir, args.methods, args.seed)
            path.write_text(json.dumps(record))
            print(f"{name}: done", file=sys.stderr, flush=True)
    records = [json.loads(p.read_text()) for p in sorted(out.glob("*.json"))]
    for method in args.methods:
        print("\n".join(report(records, method)))


if __name__ == "__main__":
    main()
