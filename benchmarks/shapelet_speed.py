"""The shapelet classifier against aeon's RDSTClassifier on R^1, one thread, same run.

Usage::

    python benchmarks/shapelet_speed.py --datasets GunPoint ItalyPowerDemand ArrowHead \
        --seeds 0 1

For every dataset (aeon's bundled ones, or ``--data-dir``) and seed: test accuracy, fit
and prediction CPU seconds of ``RDSTClassifier(n_jobs=1)`` and of
``GeodesicShapeletClassifier(n_jobs=1)`` with shapelets from the series alone
(``representation="raw"``) and from the series and their velocity (the default), and
the ratios of their seconds to RDST's. Both compile their kernels first, untimed.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository

from sk_rtw import GeodesicShapeletClassifier
from sk_rtw.utils import from_aeon


def main(argv=None) -> None:
    from aeon.classification.shapelet_based import RDSTClassifier
    from aeon.datasets import load_classification

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--datasets", nargs="+",
                        default=["GunPoint", "ItalyPowerDemand", "ArrowHead"])  # fmt: skip
    parser.add_argument("--seeds", nargs="+", type=int, default=[0, 1])
    parser.add_argument("--data-dir", default=None)
    args = parser.parse_args(argv)
    warnings.filterwarnings("ignore")
    X, y = load_classification("GunPoint", split="train")
    RDSTClassifier(max_shapelets=20, n_jobs=1).fit(X, y).predict(X)
    GeodesicShapeletClassifier(n_shapelets=20).fit(from_aeon(X), y).predict(from_aeon(X))
    rows = {
        "rdst": lambda s: RDSTClassifier(random_state=s, n_jobs=1),
        "shapelets-raw": lambda s: GeodesicShapeletClassifier(representation="raw",
                                                               random_state=s, n_jobs=1),
        "shapelets": lambda s: GeodesicShapeletClassifier(random_state=s, n_jobs=1),
    }
    for name in args.datasets:
        kw = {"extract_path": args.data_dir} if args.data_dir else {}
        X_train, y_train = load_classification(name, split="train", **kw)
        X_test, y_test = load_classification(name, split="test", **kw)
        for seed in args.seeds:
            seconds = {}
            for row, make in rows.items():
                train, test = (X_train, X_test) if row == "rdst" else (
                    from_aeon(X_train), from_aeon(X_test))  # fmt: skip
                model = make(seed)
                start = time.process_time()
                model.fit(train, y_train)
                fit = time.process_time() - start
                start = time.process_time()
                accuracy = float(np.mean(model.predict(test) == y_test))
                predict = time.process_time() - start
                seconds[row] = (fit, predict)
                base_fit, base_predict = seconds["rdst"]
                ratio = "" if row == "rdst" else (
                    f"  ({fit / base_fit:.2f}x / {predict / base_predict:.2f}x RDST)")
                print(f"{name:18s} seed {seed} {row:14s} accuracy {accuracy:.3f} "
                      f"fit {fit:6.2f} s predict {predict:6.2f} s{ratio}", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
