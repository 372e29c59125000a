"""What shapelet candidates cost the forest: fit and predict CPU seconds of the elastic
forest and of the forest with shapelet candidates (the default) on the same datasets,
one thread.

Usage::

    python benchmarks/forest_shapelet_cost.py --data-dir ../shared/ucr_large \
        --datasets Crop ElectricDevices

For every dataset (after two small untimed forests of each kind, so that compiling is
not timed): ``RTWProximityForest(random_state=seed, n_jobs=1,
splitters=[ElasticSplitter()])`` and the same with ``splitters=[ElasticSplitter(),
ShapeletSplitter()]`` (the default forest), fitted on the training split and
asked to predict the test split; CPU seconds (``time.process_time``) and accuracy of
each, and the ratios of the second's seconds to the first's (the local-patterns
issue's bound: 1.3x).
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository

from benchmarks.ucr._data import load_split, take  # missing values filled as in the UCR run
from sk_rtw import ElasticSplitter, RTWProximityForest, ShapeletSplitter

#: The splitters of each forest.
KINDS = {"elastic": lambda: [ElasticSplitter()],
         "shapelets": lambda: [ElasticSplitter(), ShapeletSplitter()]}  # fmt: skip


def measure(name: str, data_dir: str | None, seed: int) -> dict:
    """Fit and predict CPU seconds and accuracy of both forests on one dataset."""
    train, test = load_split(name, "train", data_dir), load_split(name, "test", data_dir)
    X, y, X_test, y_test = train.X, train.y, test.X, test.y
    rows = np.concatenate([np.flatnonzero(y == c)[:3] for c in np.unique(y)])
    few = take(train, rows)
    out = {}
    for splitters in KINDS.values():
        RTWProximityForest(n_trees=2, random_state=0, splitters=splitters()).fit(
            few.X, few.y).predict(X_test[:5])  # fmt: skip
    for kind, splitters in KINDS.items():
        forest = RTWProximityForest(random_state=seed, n_jobs=1, splitters=splitters())
        start = time.process_time()
        forest.fit(X, y)
        fit = time.process_time() - start
        start = time.process_time()
        accuracy = float(np.mean(forest.predict(X_test) == y_test))
        out[kind] = (fit, time.process_time() - start, accuracy)
        print(f"{name} {kind}: fit {fit:.1f} s, predict {out[kind][1]:.1f} s CPU, "
              f"accuracy {accuracy:.4f}", flush=True)  # fmt: skip
    return out


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--datasets", nargs="+", default=["GunPoint", "ItalyPowerDemand"])
    parser.add_argument("--data-dir", default=None)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    warnings.filterwarnings("ignore")
    totals = np.zeros((2, 2))
    for name in args.datasets:
        result = measure(name, args.data_dir, args.seed)
        (ef, ep, _), (sf, sp, _) = result["elastic"], result["shapelets"]
        totals += [[ef, ep], [sf, sp]]
        print(f"{name}: shapelet candidates cost {sf / ef:.2f}x the fit, {sp / ep:.2f}x the "
              f"prediction, {(sf + sp) / (ef + ep):.2f}x both", flush=True)  # fmt: skip
    (ef, ep), (sf, sp) = totals
    print(f"all: {sf / ef:.2f}x the fit, {sp / ep:.2f}x the prediction, "
          f"{(sf + sp) / (ef + ep):.2f}x both")


if __name__ == "__main__":
    main()
