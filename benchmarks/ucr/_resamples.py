"""Results over stratified resamples: records of every resample, accuracy per dataset
(mean and spread over the resamples) and paired tests across them.

Resample 0 is the archive's split (``datasets/<name>.json``, the tables of the main
summary); resamples 1 .. K-1 are aeon's and tsml-eval's stratified resamples
(``resamples/<name>/resample<r>.json``). Every method of a resample sees the same
split, so per dataset two methods are compared by a paired t-test over the resamples'
accuracies, and across datasets by a Wilcoxon signed-rank test of the mean accuracies.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from scipy import stats

from ._protocol import ALPHA, record_path


def load_resample_records(out: Path, names: list[str], n_resamples: int) -> list[dict]:
    """Every record of ``names`` and resamples ``0 .. n_resamples-1`` there is."""
    records = []
    for name in names:
        for resample in range(n_resamples):
            path = record_path(out, name, resample)
            if path.is_file():
                records.append(json.loads(path.read_text()))
    return records


def accuracy_table(records: list[dict], methods: list[str], n_resamples: int) -> dict:
    """``{dataset: {method: accuracies by resample (NaN where missing)}}``."""
    table: dict[str, dict[str, np.ndarray]] = {}
    for record in records:
        if record.get("error"):
            continue
        resample = record.get("config", {}).get("resample", 0)
        row = table.setdefault(
            record["dataset"], {m: np.full(n_resamples, np.nan) for m in methods}
        )
        for method in methods:
            entry = record.get("methods", {}).get(method, {})
            if "accuracy" in entry:
                row[method][resample] = entry["accuracy"]
    return dict(sorted(table.items()))


def paired_over_resamples(a: np.ndarray, b: np.ndarray) -> str:
    """ "a" or "b" when one method's accuracy is significantly higher over the resamples
    (paired t-test, alpha 0.05), else "none"."""
    mask = np.isfinite(a) & np.isfinite(b)
    a, b = a[mask], b[mask]
    if len(a) < 2 or np.allclose(a, b):
        return "none"
    p = stats.ttest_rel(a, b).pvalue
    if not np.isfinite(p) or p >= ALPHA:
        return "none"
    return "a" if a.mean() > b.mean() else "b"


def resamples_markdown(records: list[dict], methods: list[str], n_resamples: int) -> list[str]:
    """The resamples section of the summary: mean accuracy, per dataset, paired tests."""
    table = accuracy_table(records, methods, n_resamples)
    complete = {
        d: row for d, row in table.items() if all(np.isfinite(row[m]).all() for m in methods)
    }
    lines = [
        f"## Over {n_resamples} stratified resamples",
        "",
        "Resample 0 is the archive's split (the tables above); resamples 1 .. "
        f"{n_resamples - 1} are aeon's and tsml-eval's stratified resamples, seeded by the "
        f"resample number. {len(complete)} of {len(table)} dataset(s) have every resample "
        "of every method; the means are over those.",
        "",
    ]
    if not complete:
        return lines
    means = np.array([[row[m].mean() for m in methods] for row in complete.values()])
    lines += [
        "| method | mean accuracy | spread over resamples (mean sd) |",
        "| --- | --- | --- |",
    ]
    for i, method in enumerate(methods):
        spread = (
            np.mean([row[method].std(ddof=1) for row in complete.values()])
            if (n_resamples > 1)
            else float("nan")
        )
        lines.append(f"| {method} | {means[:, i].mean():.4f} | {spread:.4f} |")
    lines += [""]
    if len(methods) > 1 and n_resamples > 1:
        lines += [
            "Paired over resamples per dataset (t-test, alpha 0.05): datasets where the row "
            "is significantly more / less accurate than the column; Wilcoxon signed-rank "
            "p across datasets of the mean accuracies.",
            "",
            "| row vs column | " + " | ".join(methods[1:]) + " |",
            "| --- | " + " | ".join("---" for _ in methods[1:]) + " |",
        ]
        for i, a in enumerate(methods[:-1]):
            cells = []
            for j, b in enumerate(methods[1:], start=1):
                if j <= i:
                    cells.append("")
                    continue
                verdicts = [paired_over_resamples(row[a], row[b]) for row in complete.values()]
                diff = means[:, i] - means[:, j]
                p = stats.wilcoxon(diff).pvalue if np.any(diff != 0) else 1.0
                cells.append(f"{verdicts.count('a')} / {verdicts.count('b')} (p = {p:.3g})")
            lines.append(f"| {a} | " + " | ".join(cells) + " |")
        lines += [""]
    lines += [
        "| dataset | " + " | ".join(methods) + " |",
        "| --- | " + " | ".join("---" for _ in methods) + " |",
    ]
    for dataset, row in table.items():
        cells = []
        for m in methods:
            done = row[m][np.isfinite(row[m])]
            if not len(done):
                cells.append("-")
            elif len(done) < n_resamples:
                cells.append(f"{done.mean():.3f} ({len(done)} of {n_resamples})")
            else:
                sd = f" ± {done.std(ddof=1):.3f}" if n_resamples > 1 else ""
                cells.append(f"{done.mean():.3f}{sd}")
        lines.append(f"| {dataset} | " + " | ".join(cells) + " |")
    return [*lines, ""]
