"""The shapelet rows of the UCR benchmark beside the published figures, per half.

Usage::

    python benchmarks/ucr/run.py --data-dir ../shared/ucr --half A --seed 0 --jobs 1 \
        --methods rtw-forest rtw-forest-elastic rtw-shapelets rdst --out results/s0_A
    python benchmarks/studies/shapelet_rows.py results/s0_A results/s0_B ...

For every results folder (one half and seed): the mean accuracy of every row over the
datasets the published table covers, beside PF 2.0, TS-CHIEF, RDST, MiniRocket and HC2
(split 0, ``../shared/ucr/published_results.csv``), and the fit and prediction seconds
of every row in total, with the ratio of the forest with shapelet candidates (the
default ``rtw-forest``, or ``rtw-forest-shapelets`` written out) to the elastic forest
(``rtw-forest-elastic``; the same run, one thread).
"""

from __future__ import annotations

import argparse
import csv
import json
from pathlib import Path

import numpy as np

PUBLISHED = ("PF2", "TS-CHIEF", "RDST", "MiniRocket", "HC2")
ROWS = ("rtw-forest", "rtw-forest-shapelets", "rtw-forest-elastic", "rtw-shapelets", "rdst")


def published(path: Path) -> dict[str, dict[str, float]]:
    with open(path, newline="") as handle:
        return {
            row["dataset"]: {k: float(row[f"{k}_split0"]) for k in PUBLISHED
                             if row.get(f"{k}_split0")}
            for row in csv.DictReader(handle)
        }


def summary(folder: Path, table: dict) -> str:
    records = [json.loads(p.read_text()) for p in sorted((folder / "datasets").glob("*.json"))]
    rows = [r for r in ROWS if all(r in rec["methods"] and "accuracy" in rec["methods"][r]
                                   for rec in records)]  # fmt: skip
    covered = [rec for rec in records if len(table.get(rec["dataset"], {})) == len(PUBLISHED)]
    lines = [f"{folder}: {len(records)} datasets, {len(covered)} with published figures"]
    for row in rows:
        acc_all = np.mean([rec["methods"][row]["accuracy"] for rec in records])
        acc = np.mean([rec["methods"][row]["accuracy"] for rec in covered])
        fit = sum(rec["methods"][row]["fit_seconds"] for rec in records)
        predict = sum(rec["methods"][row]["predict_seconds"] for rec in records)
        lines.append(f"  {row:22s} covered {acc:.4f}  all {acc_all:.4f}  fit {fit:8.1f} s  "
                     f"predict {predict:7.1f} s")  # fmt: skip
    for name in PUBLISHED:
        mean = np.mean([table[r["dataset"]][name] for r in covered])
        lines.append(f"  {name:22s} covered {mean:.4f}")
    with_shapelets = [r for r in ("rtw-forest-shapelets", "rtw-forest") if r in rows]
    if with_shapelets and "rtw-forest-elastic" in rows:
        fit = [sum(rec["methods"][r]["fit_seconds"] for rec in records)
               for r in (with_shapelets[0], "rtw-forest-elastic")]  # fmt: skip
        lines.append(f"  forest with shapelets / elastic forest: fit {fit[0] / fit[1]:.2f}x")
    return "\n".join(lines)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folders", nargs="+", type=Path)
    parser.add_argument("--published", type=Path,
                        default=Path(__file__).resolve().parents[3] / "shared" / "ucr"
                        / "published_results.csv")  # fmt: skip
    args = parser.parse_args(argv)
    table = published(args.published)
    for folder in args.folders:
        print(summary(folder, table))


if __name__ == "__main__":
    main()
