"""The nearest-centroid classifier's representation: the series, or chosen with the band.

Usage::

    python benchmarks/studies/representation_choice.py --data-dir ../shared/ucr --halves A B \
        --seeds 0 1 2 --out results/representation_choice.jsonl

For every dataset and seed, ``RTWNearestCentroid(representation="auto",
random_state=seed, n_jobs=1)`` is fitted on one thread (the band and the centroids
chosen on the series and on their tangent velocity; the velocity where its choice
classifies the held-out training series better by a standard error) and scored on the
test split; where it chose the velocity, the default ``representation="raw"`` is fitted
too (elsewhere it is the same fit). Kept per dataset (JSON lines, appended as each
finishes; a rerun skips what is there): both accuracies, the choice, its statistic and
the fit seconds. The mean accuracy per half and seed is printed: the rule is adopted
only if it holds where defaults are chosen (halves A and C1) and is confirmed on B and
C2.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository

from benchmarks.studies._halves_cli import (
    halves_parser,
    measure_missing,
    print_half_means,
    read_records,
)
from benchmarks.ucr._data import load_split
from sk_rtw import RTWNearestCentroid


def measure(name: str, seed: int, data_dir: str) -> dict:
    train, test = load_split(name, "train", data_dir), load_split(name, "test", data_dir)
    start = time.perf_counter()
    auto = RTWNearestCentroid(representation="auto", random_state=seed, n_jobs=1)
    auto.fit(train.X, train.y)
    fit = time.perf_counter() - start
    record = {
        "dataset": name, "seed": seed, "chosen": auto.representation_,
        "choice": auto.selection_.get("representation"), "auto_fit": fit,
        "auto": float(np.mean(auto.predict(test.X) == test.y)),
    }  # fmt: skip
    if auto.representation_ == "raw":
        record["raw"] = record["auto"]
    else:
        raw = RTWNearestCentroid(random_state=seed, n_jobs=1).fit(train.X, train.y)
        record["raw"] = float(np.mean(raw.predict(test.X) == test.y))
    print(name, seed, record["chosen"], round(record["raw"], 4), round(record["auto"], 4),
          flush=True)  # fmt: skip
    return record


def main(argv=None) -> None:
    args = halves_parser(__doc__.splitlines()[0], out_required=False).parse_args(argv)
    records = read_records(args.out)
    for _ in measure_missing(args, records, measure):
        pass
    print_half_means(records, args, ["raw", "auto"])


if __name__ == "__main__":
    main()
