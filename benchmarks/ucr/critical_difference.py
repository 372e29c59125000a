"""A critical-difference diagram from tsml-format accuracy summaries, offline.

Reads ``<root>/classification/accuracy/<Classifier>_accuracy.csv`` (a row per dataset, a
column per resample: what ``benchmarks/ucr/run.py`` writes under ``<out>/tsml``, and
the layout of the published reference results that aeon's ``get_estimator_results``
reads), averages every classifier's accuracy over the resamples, keeps the datasets
every classifier has, and draws aeon's ``plot_critical_difference`` (Wilcoxon signed-rank
tests with Holm's correction, alpha 0.1).

Examples::

    python benchmarks/ucr/critical_difference.py results/ucr/tsml --out cd.png
    # beside published results kept in a local folder of the same layout
    python benchmarks/ucr/critical_difference.py results/ucr/tsml ~/published --out cd.png \\
        --classifiers RTWNearestCentroid MiniROCKET 1NN-DTW HC2
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository

from benchmarks._shared import positive_int


def read_accuracies(roots: list[Path], classifiers: list[str] | None, resamples: int | None):
    """``(datasets, classifiers, accuracy (n_datasets, n_classifiers))``: the mean over the
    first ``resamples`` columns (all of them for None) of every summary found."""
    import pandas as pd

    tables = {}
    for root in roots:
        folder = root / "classification" / "accuracy"
        if not root.is_dir():
            raise SystemExit(f"error: {root} is not an existing folder")
        if not any(folder.glob("*_accuracy.csv")):
            raise SystemExit(
                f"error: {root} holds no accuracy summary: expected "
                f"{folder}/<Classifier>_accuracy.csv (what run.py writes under <out>/tsml)"
            )
        for path in sorted(folder.glob("*_accuracy.csv")):
            name = path.name[: -len("_accuracy.csv")]
            if classifiers and name not in classifiers:
                continue
            frame = pd.read_csv(path, index_col=0)
            values = frame.to_numpy(dtype=float)[:, :resamples]
            if resamples is not None and values.shape[1] < resamples:
                raise SystemExit(f"{path}: {values.shape[1]} resamples, {resamples} asked")
            tables[name] = dict(zip(frame.index, values.mean(axis=1), strict=True))
    missing = sorted(set(classifiers or []) - set(tables))
    if missing:
        raise SystemExit(f"no accuracy summary for {', '.join(missing)} under {roots}")
    names = list(classifiers) if classifiers else sorted(tables)
    datasets = sorted(set.intersection(*(set(tables[n]) for n in names))) if names else []
    accuracy = np.array([[tables[n][d] for n in names] for d in datasets])
    return datasets, names, accuracy


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(
        description=__doc__.splitlines()[0],
        epilog=__doc__.split("Examples::")[1],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("roots", nargs="+", type=Path, help="folders in the tsml layout")
    parser.add_argument("--classifiers", nargs="+", help="which (default: every one found)")
    parser.add_argument("--resamples", type=positive_int, default=None,
                        help="first K (default all)")  # fmt: skip
    parser.add_argument("--out", type=Path, default=Path("critical_difference.png"))
    args = parser.parse_args(argv)
    datasets, names, accuracy = read_accuracies(args.roots, args.classifiers, args.resamples)
    if len(names) < 3 or len(datasets) < 3:
        print(
            f"error: aeon's Friedman test needs 3 classifiers on 3 datasets; got "
            f"{len(names)} on {len(datasets)}",
            file=sys.stderr,
        )
        return 1
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from aeon.visualisation import plot_critical_difference

    fig, _ = plot_critical_difference(accuracy, names)
    fig.savefig(args.out, dpi=120, bbox_inches="tight")
    plt.close(fig)
    for i, name in enumerate(names):
        print(f"{name}: mean accuracy {accuracy[:, i].mean():.4f}")
    print(f"{len(datasets)} datasets; written: {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
