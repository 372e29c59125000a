"""Summary across datasets: verdict, mean accuracy and rank, Table II of the paper, per-dataset
accuracy, a scatter plot and a critical-difference diagram."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from scipy.stats import rankdata

from ._protocol import DEFAULT_CLASSIFIERS, PROTOTYPE_CLASSIFIERS, pairwise_tests

PAIRS = (
    ("ttw", "rtw"),
    ("ntw", "rtw"),
    ("dba", "rtw"),
    ("rtw-paper", "rtw"),
    ("1nn-dtw", "rtw"),
    ("ttw", "ntw"),
    ("aeon-dba", "dba"),
)
PAPER_TABLE_II = {  # averaging, classification (% of 128 datasets)
    ("ttw", "rtw"): {"a": (7.34, 5.47), "b": (39.84, 54.69), "none": (52.82, 39.84)},
    ("ntw", "rtw"): {"a": (7.81, 6.25), "b": (8.59, 35.16), "none": (83.60, 58.59)},
}


def load_records(out: Path) -> list[dict]:
    return [json.loads(p.read_text()) for p in sorted((out / "datasets").glob("*.json"))]


def _test(record, a, b, kind):
    # recomputed from the stored per-series values, so every record is judged alike
    tests = pairwise_tests(record.get("methods", {}))
    if f"{a}|{b}" in tests:
        entry = tests[f"{a}|{b}"].get(kind)
        return entry and entry["better"]
    if f"{b}|{a}" in tests:
        entry = tests[f"{b}|{a}"].get(kind)
        flip = {"a": "b", "b": "a", "none": "none"}
        return entry and flip[entry["better"]]
    return None


def table_ii(records: list[dict]) -> list[dict]:
    rows = []
    for a, b in PAIRS:
        row = {"pair": (a, b)}
        for kind in ("averaging", "classification"):
            outcomes = [o for o in (_test(r, a, b, kind) for r in records) if o]
            n = len(outcomes)
            row[kind] = {
                k: (100.0 * outcomes.count(k) / n if n else float("nan"))
                for k in ("a", "b", "none")
            }
            row[kind]["n"] = n
        rows.append(row)
    return rows


def accuracy_matrix(records, methods):
    names, rows = [], []
    for r in records:
        accs = [r["methods"].get(m, {}).get("accuracy") for m in methods]
        if r.get("error") is None and all(a is not None for a in accs):
            names.append(r["dataset"])
            rows.append(accs)
    return names, np.array(rows, dtype=float).reshape(len(rows), len(methods))


def wins_ties_losses(records: list[dict], a: str, b: str) -> dict:
    """Datasets where method ``a`` is more / equally / less accurate than ``b``."""
    _, acc = accuracy_matrix(records, [a, b])
    if not len(acc):
        return {"wins": 0, "ties": 0, "losses": 0, "n": 0, "mean_a": np.nan, "mean_b": np.nan}
    diff = acc[:, 0] - acc[:, 1]
    tie = np.abs(diff) <= 1e-12
    return {
        "wins": int(((diff > 0) & ~tie).sum()),
        "ties": int(tie.sum()),
        "losses": int(((diff < 0) & ~tie).sum()),
        "n": len(acc),
        "mean_a": float(acc[:, 0].mean()),
        "mean_b": float(acc[:, 1].mean()),
    }


def verdict(records: list[dict], methods: list[str]) -> list[str]:
    """Who won, where RTW ranks, on how many datasets: a few plain sentences."""
    names, acc = accuracy_matrix(records, methods)
    if not len(names):
        return ["No dataset where every method ran: no verdict."]
    ranks = np.mean([rankdata(-row) for row in acc], axis=0)
    means = acc.mean(0)
    order = np.argsort(ranks, kind="stable")
    best, most_accurate = methods[order[0]], methods[int(np.argmax(means))]
    lines = [
        f"Verdict over {len(names)} dataset(s) where all {len(methods)} methods ran: "
        f"{best} has the best mean rank ({ranks[order[0]]:.2f}, mean accuracy "
        f"{means[order[0]]:.4f})"
        + (
            "."
            if most_accurate == best
            else f"; the highest mean accuracy is {most_accurate}'s ({means.max():.4f})."
        )
    ]
    if "rtw" in methods:
        i = methods.index("rtw")
        place = int(np.flatnonzero(order == i)[0]) + 1
        lines.append(
            f"RTW (one mean per class) ranks {place} of {len(methods)} (mean rank "
            f"{ranks[i]:.2f}, mean accuracy "
            f"{means[i]:.4f})."
        )
        for other in ("dba", "ttw", "ntw"):
            if other in methods:
                row = wins_ties_losses(records, "rtw", other)
                lines.append(
                    f"RTW against {other}: {row['wins']} wins, {row['ties']} ties, "
                    f"{row['losses']} losses on {row['n']} dataset(s)."
                )
    lines += best_classifiers_verdict(records, methods)
    lines += default_classifier_verdict(records, methods)
    lines += prototype_verdict(records, methods)
    if len(names) < 30:
        lines.append(
            f"Few datasets ({len(names)}): one dataset moves a share by "
            f"{100 / len(names):.1f} points; read the tables as anecdotes, not rankings."
        )
    return lines


#: The library's most accurate classifiers, and the references they are read beside.
BEST_ROWS = ("rtw-forest", "rtw-forest-shapelets", "rtw-forest-elastic", "rtw-shapelets")
BEST_REFERENCES = ("minirocket", "rdst", "1nn-dtw")


def best_classifiers_verdict(records: list[dict], methods: list[str]) -> list[str]:
    """The library's best classifiers (the forest, the shapelets) beside MiniRocket and
    1-NN DTW on the datasets where all of them ran: mean accuracy, fit and prediction
    seconds."""
    rows = [m for m in (*BEST_ROWS, *BEST_REFERENCES) if m in methods]
    if not any(m in methods for m in BEST_ROWS) or len(rows) < 2:
        return []
    names, acc = accuracy_matrix(records, rows)
    if not len(names):
        return []
    chosen = [r for r in records if r["dataset"] in names]
    parts = []
    for i, row in enumerate(rows):
        fit = sum(r["methods"][row]["fit_seconds"] for r in chosen)
        predict = sum(r["methods"][row]["predict_seconds"] for r in chosen)
        parts.append(f"{row} {acc[:, i].mean():.4f} (fit {fit:.1f} s, predict {predict:.1f} s)")
    return [
        f"The library's best beside the references, on {len(names)} dataset(s), mean "
        f"accuracy (seconds in total): " + "; ".join(parts) + "."
    ]


def prototype_verdict(records: list[dict], methods: list[str]) -> list[str]:
    """RTWPrototypeClassifier against the default nearest centroid, 1-NN DTW and MiniRocket,
    on the datasets where all of them ran."""
    row = "rtw-prototype"
    others = [m for m in ("rtw-default", "1nn-dtw", "minirocket") if m in methods]
    if row not in methods or not others:
        return []
    names, acc = accuracy_matrix(records, [row, *others])
    if not len(names):
        return []
    chosen = [r for r in records if r["dataset"] in names]
    against = "; ".join(
        f"{other} {acc[:, i + 1].mean():.4f} (gap {acc[:, 0].mean() - acc[:, i + 1].mean():+.4f}"
        f", at least as accurate on {int(np.sum(acc[:, 0] >= acc[:, i + 1] - 1e-12))})"
        for i, other in enumerate(others)
    )
    decisions = [r["methods"][row].get("decision") for r in chosen]
    line = (
        f"The prototype classifier, RTWPrototypeClassifier(): mean accuracy "
        f"{acc[:, 0].mean():.4f} on {len(names)} dataset(s), against {against}; the readout "
        f"decided on {decisions.count('readout')} of them, the nearest centroid on the rest"
    )
    if "rtw-default" in others:
        fit = sum(r["methods"][row]["fit_seconds"] for r in chosen)
        base = sum(r["methods"]["rtw-default"]["fit_seconds"] for r in chosen)
        predict = sum(r["methods"][row]["predict_seconds"] for r in chosen)
        base_predict = sum(r["methods"]["rtw-default"]["predict_seconds"] for r in chosen)
        line += (
            f"; fit {fit:.1f} s against the nearest centroid's {base:.1f} s "
            f"({fit / max(base, 1e-9):.2f}x), prediction {predict:.2f} s against "
            f"{base_predict:.2f} s ({predict / max(base_predict, 1e-9):.2f}x)"
        )
    if "minirocket" not in methods:
        line += " (MiniRocket not run: add --methods minirocket, which needs aeon)"
    return [line + "."]


def timing(records: list[dict], method: str, reference: str = "1nn-dtw") -> dict:
    """Total fit and prediction seconds of ``method`` over the datasets where it and
    ``reference`` ran, and the median per dataset of the reference's prediction time over
    the method's."""
    pairs = [
        (r["methods"][method], r["methods"][reference])
        for r in records
        if not r.get("error")
        and "accuracy" in r["methods"].get(method, {})
        and "accuracy" in r["methods"].get(reference, {})
    ]
    if not pairs:
        return {}
    return {
        "n": len(pairs),
        "fit": sum(m["fit_seconds"] for m, _ in pairs),
        "predict": sum(m["predict_seconds"] for m, _ in pairs),
        "reference_fit": sum(r["fit_seconds"] for _, r in pairs),
        "reference_predict": sum(r["predict_seconds"] for _, r in pairs),
        "speedup": float(
            np.median([r["predict_seconds"] / max(m["predict_seconds"], 1e-9) for m, r in pairs])
        ),
    }


def default_classifier_verdict(records: list[dict], methods: list[str]) -> list[str]:
    """The classifier a user gets by default against 1-NN DTW: accuracy and times."""
    if "rtw-default" not in methods or "1nn-dtw" not in methods:
        return []
    row = wins_ties_losses(records, "rtw-default", "1nn-dtw")
    if not row["n"]:
        return []
    times = timing(records, "rtw-default")
    line = (
        f"The default classifier, RTWNearestCentroid() (band and centroids per class chosen "
        f"from the training data): mean accuracy {row['mean_a']:.4f} against 1-NN DTW's "
        f"{row['mean_b']:.4f}, at least as accurate on {row['wins'] + row['ties']} of "
        f"{row['n']} dataset(s); fit {times['fit']:.1f} s in total"
    )
    one_mean = timing(records, "rtw")
    if one_mean and one_mean["n"] == times["n"]:
        line += f" (one mean per class: {one_mean['fit']:.1f} s)"
    line += (
        f", prediction {times['predict']:.2f} s against 1-NN DTW's "
        f"{times['reference_predict']:.2f} s (median speed-up {times['speedup']:.1f}x)."
    )
    learned = wins_ties_losses(records, "rtw-default", "1nn-dtw-band")
    if "1nn-dtw-band" in methods and learned["n"]:
        line += (
            f" Against 1-NN DTW with a learned band: {learned['mean_a']:.4f} against "
            f"{learned['mean_b']:.4f}, at least as accurate on "
            f"{learned['wins'] + learned['ties']} of {learned['n']}."
        )
    return [line]


#: The development archive (``../shared/ucr``, 30 datasets) in its two fixed halves:
#: alphabetical positions 1, 3, 5, ... (A, where defaults are chosen) and 2, 4, 6, ...
#: (B, where they are confirmed).
HALF_A = (
    "ArrowHead", "Beef", "BirdChicken", "Car", "Coffee", "DodgerLoopGame", "ECGFiveDays",
    "Fish", "Fungi", "GunPoint", "InsectEPGSmallTrain", "Lightning2", "Meat", "OliveOil",
    "Plane",
)  # fmt: skip
HALF_B = (
    "BME", "BeetleFly", "CBF", "Chinatown", "DiatomSizeReduction", "ECG200", "FaceFour",
    "FreezerSmallTrain", "GesturePebbleZ1", "Herring", "ItalyPowerDemand", "Lightning7",
    "MoteStrain", "PickupGestureWiimoteZ", "PowerCons",
)  # fmt: skip
#: Half C: six UCR datasets with large training sets (``../shared/ucr_large``), split by
#: hand so that each half holds one very large set (Crop, ElectricDevices), one of long
#: series and one of unequal lengths. Defaults are chosen on C1 (with half A) and
#: confirmed on C2 (with half B).
HALF_C1 = ("AllGestureWiimoteX", "Computers", "Crop")
HALF_C2 = ("AllGestureWiimoteZ", "ElectricDevices", "LargeKitchenAppliances")
FIXED_HALVES = {"A": HALF_A, "B": HALF_B, "C1": HALF_C1, "C2": HALF_C2}


def split_halves(names: list[str]) -> tuple[list[str], list[str]]:
    """The two halves of datasets outside the development data: alphabetical positions
    1, 3, 5, ... (half A) and 2, 4, 6, ... (half B), as the archive's own halves."""
    ordered = sorted(names)
    return ordered[0::2], ordered[1::2]


def halves(names: list[str]) -> dict[str, list[str]]:
    """Every half the datasets fall in: the fixed halves of the development data
    (:data:`FIXED_HALVES`), and other datasets split alphabetically into A and B
    (:func:`split_halves`); empty halves left out."""
    fixed = {name: label for label, members in FIXED_HALVES.items() for name in members}
    others_a, others_b = split_halves([n for n in names if n not in fixed])
    parts = {label: sorted(n for n in names if fixed.get(n) == label) for label in FIXED_HALVES}
    parts["A"] = sorted(parts["A"] + others_a)
    parts["B"] = sorted(parts["B"] + others_b)
    return {label: part for label, part in parts.items() if part}


def barycenter_cost(record: dict, method: str) -> float | None:
    """Total DTW of the training series to their class means (the averaging measure)."""
    values = np.asarray(record["methods"].get(method, {}).get("barycenter", []), dtype=float)
    return float(values.sum()) if len(values) and np.isfinite(values).all() else None


def halves_markdown(records: list[dict], methods: list[str]) -> list[str]:
    """Per half and over all: mean accuracy, and every method against the others."""
    done = [r for r in records if not r.get("error")]
    found = halves([r["dataset"] for r in done])
    parts = {f"half {label}": names for label, names in found.items()}
    parts["all"] = [name for names in found.values() for name in names]
    described = {
        "A": "the development archive's alphabetical positions 1, 3, 5, ...",
        "B": "2, 4, 6, ...",
        "C1": "large training sets where defaults are chosen",
        "C2": "large training sets where they are confirmed",
    }
    lines = [
        "## Halves",
        "",
        "; ".join(
            f"Half {label}: {described[label]} ({', '.join(names)})"
            for label, names in found.items()
        )
        + ". Defaults are chosen on halves A and C1 and confirmed on B and C2.",
        "",
        "| method | " + " | ".join(f"mean accuracy, {p}" for p in parts) + " |",
        "| --- | " + " | ".join("---" for _ in parts) + " |",
    ]
    for m in methods:
        cells = []
        for names in parts.values():
            _, acc = accuracy_matrix([r for r in done if r["dataset"] in names], [m])
            cells.append(f"{acc[:, 0].mean():.4f} (n={len(acc)})" if len(acc) else "-")
        lines.append(f"| {m} | " + " | ".join(cells) + " |")
    lines += [
        "",
        "Pairs: datasets where the first method is at least as accurate as the second, and "
        "where its class means have a total DTW cost no higher (averaging measure).",
        "",
        "| first | second | "
        + " | ".join(f"at least as accurate, {p}" for p in parts)
        + " | "
        + " | ".join(f"lower or equal DTW cost, {p}" for p in parts)
        + " |",
        "| --- | --- | " + " | ".join("---" for _ in range(2 * len(parts))) + " |",
    ]
    for a, b in HALF_PAIRS:
        if a not in methods or b not in methods:
            continue
        cells, cost_cells = [], []
        for names in parts.values():
            chosen = [r for r in done if r["dataset"] in names]
            row = wins_ties_losses(chosen, a, b)
            cells.append(f"{row['wins'] + row['ties']} / {row['n']}" if row["n"] else "-")
            costs = [(barycenter_cost(r, a), barycenter_cost(r, b)) for r in chosen]
            costs = [(x, y) for x, y in costs if x is not None and y is not None]
            cost_cells.append(f"{sum(x <= y for x, y in costs)} / {len(costs)}" if costs else "-")
        lines.append(f"| {a} | {b} | " + " | ".join(cells + cost_cells) + " |")
    lines += [
        "",
        "Seconds over all datasets (fit; prediction of the test splits), and the median "
        "per dataset of the prediction time of 1-NN DTW over the method's:",
        "",
        "| method | fit | predict | prediction speed-up over 1-NN DTW (median) | "
        "chosen windows / centroids |",
        "| --- | --- | --- | --- | --- |",
    ]
    for m in methods:
        entries = [r["methods"][m] for r in done if "accuracy" in r["methods"].get(m, {})]
        if not entries:
            continue
        fit = sum(e["fit_seconds"] for e in entries)
        predict = sum(e["predict_seconds"] for e in entries)
        ratios = [
            r["methods"]["1nn-dtw"]["predict_seconds"]
            / max(r["methods"][m]["predict_seconds"], 1e-9)
            for r in done
            if "accuracy" in r["methods"].get("1nn-dtw", {})
            and "accuracy" in r["methods"].get(m, {})
        ]
        speed = f"{np.median(ratios):.1f}x" if ratios and m != "1nn-dtw" else "-"
        picks = [(e.get("dtw_window"), e.get("n_centroids")) for e in entries]
        chosen = "-"
        if m in DEFAULT_CLASSIFIERS or m in PROTOTYPE_CLASSIFIERS or m == "1nn-dtw-band":
            counts = {pick: picks.count(pick) for pick in sorted(set(picks), key=str)}
            chosen = "; ".join(
                f"w={w}" + ("" if k is None else f", k={k}") + f": {n}"
                for (w, k), n in counts.items()
            )
        lines.append(f"| {m} | {fit:.0f} | {predict:.1f} | {speed} | {chosen} |")
    return [*lines, ""]


#: The comparisons of the halves report (first method against second).
HALF_PAIRS = (
    ("rtw", "dba"),
    ("rtw-refined", "dba"),
    ("rtw-default", "dba-default"),
    ("rtw-prototype", "rtw-default"),
    ("dba-prototype", "dba-default"),
    ("rtw-prototype", "1nn-dtw"),
    ("rtw-prototype", "minirocket"),
    ("rtw-default", "minirocket"),
    ("rtw-default", "1nn-dtw"),
    ("dba-default", "1nn-dtw"),
    ("rtw-default", "1nn-dtw-band"),
    ("dba-default", "1nn-dtw-band"),
    ("1nn-dtw-band", "1nn-dtw"),
    ("rtw-default", "rtw"),
    ("rtw", "1nn-dtw"),
    ("rtw", "ttw"),
    ("rtw", "ntw"),
)


def markdown(
    records: list[dict], methods: list[str], command: str, machine: str, halves: bool = False
) -> str:
    lines = [
        "# UCR benchmark: RTW vs TTW vs NTW vs DBA (and aeon's DBA, 1-NN DTW references)",
        "",
        f"Command: `{command}`  ",
        f"Machine: {machine}",
        "",
    ]
    failed = [r for r in records if r.get("error")]
    lines += [f"Datasets: {len(records)} ({len(failed)} failed).", ""]
    lines += ["## Verdict", "", *(f"{v}  " for v in verdict(records, methods)), ""]
    if halves:
        lines += halves_markdown(records, methods)
    names, acc = accuracy_matrix(records, methods)
    if len(names):
        ranks = np.mean([rankdata(-row) for row in acc], axis=0)
        lines += [
            "## Mean accuracy and mean rank over the datasets where every method ran "
            f"({len(names)})",
            "",
            "| method | mean accuracy | mean rank |",
            "| --- | --- | --- |",
        ]
        lines += [
            f"| {m} | {acc[:, i].mean():.4f} | {ranks[i]:.2f} |" for i, m in enumerate(methods)
        ]
        lines.append("")
    if "rtw" in methods:
        lines += [
            "## RTW against each method: datasets where RTW's accuracy is higher / equal / lower",
            "",
            "| method | RTW wins | ties | RTW losses | n | mean accuracy (RTW vs method) |",
            "| --- | --- | --- | --- | --- | --- |",
        ]
        for other in methods:
            if other == "rtw":
                continue
            row = wins_ties_losses(records, "rtw", other)
            if row["n"]:
                lines.append(
                    f"| {other} | {row['wins']} | {row['ties']} | {row['losses']} | {row['n']} "
                    f"| {row['mean_a']:.4f} vs {row['mean_b']:.4f} |"
                )
        lines.append("")
    n_tested = max((row["classification"]["n"] for row in table_ii(records)), default=0)
    lines += [
        "## Paired t-tests (alpha = 0.05): share of datasets (Table II layout)",
        "",
        f"Shares of the {n_tested} dataset(s) here (n per cell); the paper's columns are "
        "shares of its 128 UCR datasets"
        + (
            f": with n = {n_tested} one dataset is {100 / n_tested:.1f} points, so compare "
            "directions, not values."
            if 0 < n_tested < 30
            else "."
        ),
        "",
        "| comparison | averaging | classification | paper averaging | paper classification |",
        "| --- | --- | --- | --- | --- |",
    ]
    for row in table_ii(records):
        a, b = row["pair"]
        if not row["classification"]["n"]:
            continue
        paper = PAPER_TABLE_II.get((a, b))
        for key, label in (
            ("a", f"{a.upper()} significantly better than {b.upper()}"),
            ("b", f"{b.upper()} significantly better than {a.upper()}"),
            ("none", "no significant difference"),
        ):
            avg = row["averaging"]
            avg_text = f"{avg[key]:.2f} % (n={avg['n']})" if avg["n"] else "-"
            cls = row["classification"]
            p_avg, p_cls = (
                (f"{paper[key][0]:.2f} %", f"{paper[key][1]:.2f} %") if paper else ("-", "-")
            )
            lines.append(
                f"| {label} | {avg_text} | {cls[key]:.2f} % (n={cls['n']}) | {p_avg} | {p_cls} |"
            )
    lines += [
        "",
        "## Per dataset accuracy",
        "",
        "| dataset | n_train | n_test | T | " + " | ".join(methods) + " |",
        "| --- | --- | --- | --- | " + " | ".join("---" for _ in methods) + " |",
    ]
    for r in records:
        if r.get("error"):
            lines.append(f"| {r['dataset']} | failed: {r['error']} |")
            continue
        cells = []
        for m in methods:
            entry = r["methods"].get(m, {})
            cells.append(
                f"{entry['accuracy']:.3f}"
                if "accuracy" in entry
                else entry.get("error", entry.get("skipped", "-"))[:40]
            )
        lo, hi = r["lengths"]
        length = str(lo) if lo == hi else f"{lo}-{hi}"
        lines.append(
            f"| {r['dataset']} | {r['n_train']} | {r['n_test']} | {length} | "
            + " | ".join(cells)
            + " |"
        )
    notes = [f"- {r['dataset']}: {n}" for r in records for n in r.get("notes", [])]
    if notes:
        lines += ["", "## Notes", "", *notes]
    return "\n".join(lines) + "\n"


def scatter_plot(records: list[dict], path: Path) -> bool:
    """RTW accuracy (y) against TTW, NTW and DBA accuracy (x), one point per dataset; and,
    where both ran, the default classifier against 1-NN DTW."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return False
    pairs = [
        (other, colour, *accuracy_matrix(records, [other, "rtw"]))
        for other, colour in (("ttw", "tab:red"), ("ntw", "gold"), ("dba", "tab:blue"))
    ]
    pairs = [p for p in pairs if len(p[2])]
    names, default = accuracy_matrix(records, ["1nn-dtw", "rtw-default"])
    if not pairs and not len(names):
        return False
    panels = int(bool(pairs)) + int(bool(len(names)))
    fig, axes = plt.subplots(1, panels, figsize=(5 * panels, 5), squeeze=False)
    axes = list(axes[0])
    if pairs:
        ax = axes.pop(0)
        for other, colour, _, acc in pairs:
            ax.scatter(acc[:, 0], acc[:, 1], c=colour, label=f"{other.upper()} (x) vs RTW (y)",
                       edgecolors="k", linewidths=0.4)  # fmt: skip
        ax.set(xlabel="TTW / NTW / DBA accuracy", ylabel="RTW accuracy",
               title="One mean per class (the paper's protocol)")  # fmt: skip
    if len(names):
        ax = axes.pop(0)
        ax.scatter(default[:, 0], default[:, 1], c="tab:green", edgecolors="k", linewidths=0.4,
                   label="1-NN DTW (x) vs RTWNearestCentroid() (y)")  # fmt: skip
        ax.set(xlabel="1-NN DTW accuracy", ylabel="default classifier accuracy",
               title="The default classifier against 1-NN DTW")  # fmt: skip
    for ax in fig.axes:
        ax.plot([0, 1], [0, 1], "k--", lw=0.8)
        ax.set(xlim=(0, 1.02), ylim=(0, 1.02))
        ax.legend(loc="lower right")
    fig.suptitle("Nearest-centroid accuracy per UCR dataset")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return True


#: aeon's Friedman test needs at least three methods (and three datasets).
CD_MIN_METHODS = 3
CD_MIN_DATASETS = 3


def critical_difference_plot(records: list[dict], methods: list[str], path: Path) -> str | None:
    """aeon's critical-difference diagram of the accuracies (Wilcoxon, Holm, alpha 0.1).

    Returns None when the diagram was written, else why not: it needs at least
    :data:`CD_MIN_METHODS` methods on at least :data:`CD_MIN_DATASETS` datasets where every
    method ran (aeon's Friedman test), aeon and matplotlib.
    """
    names, acc = accuracy_matrix(records, methods)
    if len(methods) < CD_MIN_METHODS:
        return (
            f"it needs at least {CD_MIN_METHODS} methods (aeon's Friedman test), got "
            f"{len(methods)}"
        )
    if len(names) < CD_MIN_DATASETS:
        return (
            f"it needs at least {CD_MIN_DATASETS} datasets where every method ran, got "
            f"{len(names)}"
        )
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from aeon.visualisation import plot_critical_difference
    except ImportError as exc:
        return f"{exc.name} is not installed"
    try:
        fig, _ = plot_critical_difference(acc, list(methods))
    except Exception as exc:  # a statistics failure must not lose the summary
        return f"aeon could not draw it ({type(exc).__name__}: {exc})"
    fig.suptitle(f"Mean rank of nearest-centroid accuracy, {len(names)} UCR datasets", y=1.02)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return None
