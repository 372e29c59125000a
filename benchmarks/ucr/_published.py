"""Published split-0 accuracies beside this run's, on the datasets they cover.

``published_results.csv`` (``../shared/ucr``, read ``PUBLISHED.md`` there) holds, per
dataset, accuracies on the archive's own split (resample 0) from the bake-off redux
(Middlehurst, Schäfer and Bagnall 2024: Proximity Forest 1.0, MiniRocket, 1-NN DTW) and
Proximity Forest 2.0's fold 0 with its single-CPU train and test seconds (Herrmann et al.
2023, the authors' machine). They are figures to compare against, never to choose a
default by. :func:`published_markdown` prints them beside the run's rows, with means per
half over the datasets every published column covers, and the run's fit and prediction
seconds against Proximity Forest 2.0's (another machine: a ratio, not a race).
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from ._summary import halves

#: The published columns shown, and their labels.
PUBLISHED_COLUMNS = {
    "PF_split0": "Proximity Forest 1.0",
    "PF2_split0": "Proximity Forest 2.0",
    "MiniRocket_split0": "MiniRocket",
    "1NN-DTW_split0": "1-NN DTW",
}
#: Proximity Forest 2.0's single-CPU seconds (its authors' machine).
PF2_TIMES = ("PF2_train_s", "PF2_test_s")
#: The file's name in a data directory.
PUBLISHED_FILE = "published_results.csv"


def default_published(data_dir: str | None) -> Path | None:
    """``<data_dir>/published_results.csv`` when it exists, else None."""
    if data_dir is None:
        return None
    path = Path(data_dir) / PUBLISHED_FILE
    return path if path.is_file() else None


def read_published(path: Path) -> dict[str, dict[str, float]]:
    """Per dataset, every numeric column of the file (empty cells left out)."""
    out: dict[str, dict[str, float]] = {}
    with Path(path).open(newline="") as handle:
        for row in csv.DictReader(handle):
            values = {}
            for key, value in row.items():
                if key in ("dataset", "half") or not value:
                    continue
                values[key] = float(value)
            out[row["dataset"]] = values
    return out


def published_markdown(
    records: list[dict], methods: list[str], published: dict[str, dict[str, float]]
) -> list[str]:
    """The run's accuracies beside the published split-0 ones (module docstring)."""
    done = [
        r for r in records
        if not r.get("error") and r.get("resample", 0) == 0
        and all(c in published.get(r["dataset"], {}) for c in PUBLISHED_COLUMNS)
    ]  # fmt: skip
    if not done:
        return []
    ours = [m for m in methods if any("accuracy" in r["methods"].get(m, {}) for r in done)]
    labels = list(PUBLISHED_COLUMNS.values())
    lines = [
        "## Beside the published figures (split 0)",
        "",
        "Published accuracies on the archive's own split, on the datasets every published "
        "column covers (bake-off redux: Proximity Forest 1.0, MiniRocket, 1-NN DTW; "
        "Proximity Forest 2.0's fold 0). Figures to compare against, not to tune to.",
        "",
        "| dataset | " + " | ".join([*ours, *labels]) + " |",
        "| --- | " + " | ".join("---" for _ in [*ours, *labels]) + " |",
    ]
    for r in done:
        cells = [_accuracy(r, m) for m in ours]
        cells += [f"{published[r['dataset']][c]:.3f}" for c in PUBLISHED_COLUMNS]
        lines.append(f"| {r['dataset']} | " + " | ".join(cells) + " |")
    parts = {f"half {k}": v for k, v in halves([r["dataset"] for r in done]).items()}
    parts["all"] = [r["dataset"] for r in done]
    lines += [
        "",
        "Means over the covered datasets (a method's mean over the datasets where it ran):",
        "",
        "| part | sets | " + " | ".join([*ours, *labels]) + " |",
        "| --- | --- | " + " | ".join("---" for _ in [*ours, *labels]) + " |",
    ]
    for part, names in parts.items():
        chosen = [r for r in done if r["dataset"] in names]
        cells = []
        for m in ours:
            values = [r["methods"][m]["accuracy"] for r in chosen
                      if "accuracy" in r["methods"].get(m, {})]  # fmt: skip
            cells.append(f"{np.mean(values):.4f} (n={len(values)})" if values else "-")
        cells += [f"{np.mean([published[r['dataset']][c] for r in chosen]):.4f}"
                  for c in PUBLISHED_COLUMNS]  # fmt: skip
        lines.append(f"| {part} | {len(chosen)} | " + " | ".join(cells) + " |")
    lines += _times(done, ours, published, parts)
    return [*lines, ""]


def _accuracy(record: dict, method: str) -> str:
    entry = record["methods"].get(method, {})
    return f"{entry['accuracy']:.3f}" if "accuracy" in entry else "-"


def _times(done, ours, published, parts) -> list[str]:
    """Fit and prediction seconds against Proximity Forest 2.0's, per part."""
    timed = [m for m in ours if all(
        "fit_seconds" in r["methods"].get(m, {}) or "accuracy" not in r["methods"].get(m, {})
        for r in done
    )]  # fmt: skip
    with_times = [r for r in done if all(c in published[r["dataset"]] for c in PF2_TIMES)]
    if not timed or not with_times:
        return []
    lines = [
        "",
        "Seconds in total over the covered datasets, fit / prediction, and their ratio to "
        "Proximity Forest 2.0's published single-CPU seconds (its authors' machine, C++; "
        "only the ratio compares):",
        "",
        "| part | " + " | ".join(timed) + " | Proximity Forest 2.0 |",
        "| --- | " + " | ".join("---" for _ in timed) + " | --- |",
    ]
    for part, names in parts.items():
        chosen = [r for r in with_times if r["dataset"] in names]
        pf2_fit = sum(published[r["dataset"]]["PF2_train_s"] for r in chosen)
        pf2_test = sum(published[r["dataset"]]["PF2_test_s"] for r in chosen)
        cells = []
        for m in timed:
            entries = [r["methods"][m] for r in chosen if "accuracy" in r["methods"].get(m, {})]
            if len(entries) != len(chosen):
                cells.append("-")
                continue
            fit = sum(e["fit_seconds"] for e in entries)
            test = sum(e["predict_seconds"] for e in entries)
            ratios = f"{fit / pf2_fit:.2f}x / {test / pf2_test:.2f}x"
            cells.append(f"{fit:.0f} / {test:.0f} s ({ratios})")
        lines.append(f"| {part} | " + " | ".join(cells) + f" | {pf2_fit:.0f} / {pf2_test:.0f} s |")
    return lines
