"""The default classifier over several seeds: each target per half and seed, from run folders.

Reads the result folders of ``benchmarks/ucr/run.py`` runs that differ only in
``--seed`` (each with the rows ``rtw-default``, ``rtw``, ``1nn-dtw`` and
``1nn-dtw-band``; ``dba-default`` where present) and prints, per half (A, B of the
development archive; C1, C2 of the large training sets; ``--combine`` adds unions such as
``C=C1+C2``) and seed: mean accuracy of the default and of 1-NN DTW (full window, and
with a learned band), the datasets where the default is at least as accurate, the fit
against one RTW mean per class, the median prediction speed-up over full-window 1-NN
DTW, and the datasets whose choice is the same on every seed. Cells list the seeds in
the order given, separated by semicolons (one value when all agree).

Example::

    python benchmarks/ucr/seeds.py results/dev_s0 results/dev_s1 results/dev_s2 \\
        results/large_s0 results/large_s1 results/large_s2 --combine C=C1+C2
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository; then _shared

from benchmarks.ucr._summary import halves, load_records

DEFAULT, ONE_MEAN, NEAREST, LEARNED = "rtw-default", "rtw", "1nn-dtw", "1nn-dtw-band"


def by_seed(folders: list[str]) -> dict[int, dict[str, dict]]:
    """Records by seed and dataset (folders of the same seed are merged).

    Records without the default row (a dataset that only a baseline ran on) are left out.
    """
    out: dict[int, dict[str, dict]] = {}
    for folder in folders:
        for record in load_records(Path(folder)):
            if record.get("error") is None and DEFAULT in record.get("methods", {}):
                out.setdefault(record["config"]["seed"], {})[record["dataset"]] = record
    return out


def _accuracy(record: dict, method: str) -> float:
    return record["methods"][method]["accuracy"]


def cell(values: list[str]) -> str:
    return values[0] if len(set(values)) == 1 else "; ".join(values)


def rows(records: dict[int, dict[str, dict]], names: list[str]) -> list[tuple[str, str]]:
    """The targets of one half: a label and a cell (seeds in order) per row."""
    seeds = sorted(records)
    per_seed = [[records[s][n] for n in names if n in records[s]] for s in seeds]
    out = []

    def mean(method: str) -> list[str]:
        return [f"{np.mean([_accuracy(r, method) for r in rs]):.4f}" for rs in per_seed]

    out.append(("mean accuracy, default", cell(mean(DEFAULT))))
    for reference, label in ((NEAREST, "1-NN DTW"), (LEARNED, "1-NN DTW, learned band")):
        out.append((f"mean accuracy, {label}", cell(mean(reference))))
        gap = [
            f"{100 * np.mean([_accuracy(r, DEFAULT) - _accuracy(r, reference) for r in rs]):+.2f}"
            for rs in per_seed
        ]
        out.append((f"default minus {label} (points)", cell(gap)))
        wins = [
            f"{sum(_accuracy(r, DEFAULT) >= _accuracy(r, reference) - 1e-12 for r in rs)}"
            f" of {len(rs)}"
            for rs in per_seed
        ]
        out.append((f"default at least as accurate as {label}", cell(wins)))
    fits = []
    for rs in per_seed:
        ratios = [
            r["methods"][DEFAULT]["fit_seconds"] / r["methods"][ONE_MEAN]["fit_seconds"]
            for r in rs
        ]
        total = sum(r["methods"][DEFAULT]["fit_seconds"] for r in rs)
        one = sum(r["methods"][ONE_MEAN]["fit_seconds"] for r in rs)
        fits.append(f"{total:.0f} s / {one:.0f} s, max {max(ratios):.1f}x")
    out.append(("fit: default / one RTW mean per class (total; worst dataset)", cell(fits)))
    speed = [
        f"{np.median([_predict_ratio(r) for r in rs]):.1f}x" for rs in per_seed
    ]  # fmt: skip
    out.append(("prediction speed-up over 1-NN DTW (median per dataset)", cell(speed)))
    choices = {
        n: {
            (records[s][n]["methods"][DEFAULT]["dtw_window"],
             repr(records[s][n]["methods"][DEFAULT]["n_centroids"]))
            for s in seeds if n in records[s]
        }
        for n in names
    }  # fmt: skip
    same = sum(len(c) == 1 for c in choices.values())
    out.append(("the same choice on every seed (datasets)", f"{same} of {len(names)}"))
    return out


def _predict_ratio(record: dict) -> float:
    methods = record["methods"]
    return methods[NEAREST]["predict_seconds"] / max(methods[DEFAULT]["predict_seconds"], 1e-9)


def choices_table(records: dict[int, dict[str, dict]], names: list[str]) -> list[str]:
    """Per dataset: the choice (band, centroids, centroids per class) on every seed."""
    seeds = sorted(records)
    lines = [
        "| dataset | training series | choice (band, centroids) | centroids | fit, default / "
        "one mean (s) | predict, default / 1-NN DTW (s) | accuracy, default / 1-NN / "
        "learned band |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    for name in names:
        entries = [records[s][name] for s in seeds if name in records[s]]
        if not entries:
            continue
        picks = [
            f"({e['methods'][DEFAULT]['dtw_window']}, {e['methods'][DEFAULT]['n_centroids']!r})"
            for e in entries
        ]
        counts = [str(sum(e["methods"][DEFAULT]["selection"]["class_centroids"])) for e in entries]
        fits = [
            f"{e['methods'][DEFAULT]['fit_seconds']:.1f} / "
            f"{e['methods'][ONE_MEAN]['fit_seconds']:.1f}"
            for e in entries
        ]
        predicts = [
            f"{e['methods'][DEFAULT]['predict_seconds']:.1f} / "
            f"{e['methods'][NEAREST]['predict_seconds']:.1f}"
            for e in entries
        ]
        accuracies = [
            f"{_accuracy(e, DEFAULT):.3f} / {_accuracy(e, NEAREST):.3f} / "
            f"{_accuracy(e, LEARNED):.3f}"
            for e in entries
        ]
        lines.append(
            f"| {name} | {entries[0]['n_train']} | {cell(picks)} | {cell(counts)} | "
            f"{cell(fits)} | {cell(predicts)} | {cell(accuracies)} |"
        )
    return lines


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(
        description=__doc__.splitlines()[0],
        epilog=__doc__.split("Example::")[1],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("folders", nargs="+", help="result folders of run.py (--out)")
    parser.add_argument(
        "--combine",
        nargs="*",
        default=[],
        metavar="NAME=H1+H2",
        help="unions of halves to report too, e.g. C=C1+C2 all=A+B+C1+C2",
    )
    args = parser.parse_args(argv)
    records = by_seed(args.folders)
    if not records:
        parser.error("no result files in the given folders")
    names = sorted({n for rs in records.values() for n in rs})
    parts = halves(names)
    for spec in args.combine:
        label, _, members = spec.partition("=")
        halves_named = members.split("+")
        unknown = [half for half in halves_named if half not in parts]
        if not label or not members or unknown:
            parser.error(
                f"argument --combine: {spec!r} must be NAME=H1+H2 with halves the results "
                f"hold ({', '.join(parts)})"
                + (f"; not there: {', '.join(unknown)}" if label and members else "")
            )
        parts[label] = [n for half in halves_named for n in parts[half]]
    seeds = ", ".join(str(s) for s in sorted(records))
    table = {label: dict(rows(records, found)) for label, found in parts.items() if found}
    labels = list(next(iter(table.values())))
    print(
        f"Seeds {seeds} (cells list them in this order, separated by semicolons; "
        "one value when all agree)\n"
    )
    print("| target | " + " | ".join(f"half {h} ({len(parts[h])})" for h in table) + " |")
    print("| --- | " + " | ".join("---" for _ in table) + " |")
    for label in labels:
        print(f"| {label} | " + " | ".join(table[h][label] for h in table) + " |")
    for half, found in parts.items():
        if half.startswith("C") and len(half) == 2:
            print(f"\nHalf {half}, per dataset (seeds {seeds}):\n")
            print("\n".join(choices_table(records, found)))


if __name__ == "__main__":
    main()
