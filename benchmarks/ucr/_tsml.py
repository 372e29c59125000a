"""Results in the tsml format, which aeon's and tsml-eval's evaluation tools read.

Two kinds of file under ``<out>/tsml`` (``root`` below), so that a researcher can put
these rows beside published results of other classifiers offline:

- **predictions**, one file per classifier, dataset and resample, in tsml-eval's layout
  ``root/<Classifier>/Predictions/<Dataset>/testResample<r>.csv``: line 1 ``dataset,
  classifier,TEST,resample,MILLISECONDS,comment`` (the comment holds the label encoding),
  line 2 the classifier's parameters, line 3 ``accuracy,fit time,predict time,-1,-1,
  n_classes,,-1,-1``, then per test case ``true,predicted,,p_0,...,p_{c-1}`` with labels
  encoded ``0 .. c-1`` in sorted order (scikit-learn's ``LabelEncoder``, as tsml-eval);
  read by ``tsml_eval.evaluation.evaluate_classifiers_by_problem`` and
  ``tsml_eval.utils.results_loading.load_estimator_results``;
- **summaries**, one per classifier and measure, in the layout of the reference results
  that ``aeon.benchmarking.results_loaders.get_estimator_results(..., path=root)``
  reads: ``root/classification/<measure>/<Classifier>_<measure>.csv``, a row per dataset
  and a column per resample (only datasets with every resample ``0 .. K-1``).
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterable
from pathlib import Path

import numpy as np
from sklearn.metrics import accuracy_score, balanced_accuracy_score, log_loss, roc_auc_score

#: The classifier names written in the files (the benchmark's other rows keep their own).
TSML_NAMES = {
    "rtw-default": "RTWNearestCentroid",
    "dba-default": "DBANearestCentroid",
    "ttw-default": "TTWNearestCentroid",
    "ntw-default": "NTWNearestCentroid",
    "rtw-prototype": "RTWPrototypeClassifier",
    "dba-prototype": "DBAPrototypeClassifier",
    "1nn-dtw": "1NN-DTW",
    "1nn-dtw-band": "1NN-DTW-LearnedBand",
    "minirocket": "MiniROCKET",
    "aeon-dba": "aeon-DBA-NearestCentroid",
}
#: Measures of the summary files, as aeon's loader names them.
MEASURES = ("accuracy", "balacc", "auroc", "logloss")


def tsml_name(method: str) -> str:
    return TSML_NAMES.get(method, method)


def predictions_path(root: Path, method: str, dataset: str, resample: int) -> Path:
    return root / tsml_name(method) / "Predictions" / dataset / f"testResample{resample}.csv"


def encoded(record: dict, entry: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray, list]:
    """True and predicted labels as ``0 .. c-1`` (sorted classes), the probabilities
    (columns in that order) and the classes."""
    classes = list(entry["classes"])
    order = np.argsort(np.asarray(classes), kind="stable")  # as np.unique, LabelEncoder
    classes = [classes[i] for i in order]
    index = {str(c): i for i, c in enumerate(classes)}
    truth = np.array([index[str(c)] for c in record["test_labels"]])
    predicted = np.array([index[str(c)] for c in entry["predictions"]])
    probabilities = np.asarray(entry["probabilities"], dtype=float)[:, order]
    return truth, predicted, probabilities, classes


def predictions_text(record: dict, method: str) -> str:
    """The tsml predictions file of one method of one dataset's record."""
    entry = record["methods"][method]
    resample = record.get("config", {}).get("resample", 0)
    truth, predicted, probabilities, classes = encoded(record, entry)
    accuracy = accuracy_score(truth, predicted)
    encoder = {str(c): i for i, c in enumerate(classes)}
    parameters = " ".join(str(entry.get("parameters", "No Parameter Info")).split())
    fit_ms = round(1000 * entry.get("fit_seconds", -0.001))
    predict_ms = round(1000 * entry.get("predict_seconds", -0.001))
    lines = [
        f"{record['dataset']},{tsml_name(method)},TEST,{resample},MILLISECONDS,"
        f"Written by sk_rtw's UCR benchmark (row {method}). Encoder dictionary: {encoder}",
        parameters,
        f"{accuracy!r},{fit_ms},{predict_ms},-1,-1,{len(classes)},,-1,-1",
    ]
    for t, p, row in zip(truth, predicted, probabilities, strict=True):
        lines.append(f"{t},{p},," + ",".join(repr(float(v)) for v in row))
    return "\n".join(lines) + "\n"


def scores(record: dict, method: str) -> dict[str, float]:
    """Every measure of :data:`MEASURES` for one method of one record, as tsml-eval
    computes them from the predictions file."""
    truth, predicted, probabilities, classes = encoded(record, record["methods"][method])
    labels = np.arange(len(classes))
    positive = probabilities[:, 1] if len(classes) == 2 else probabilities
    try:
        auroc = float(
            roc_auc_score(truth, positive, average="weighted", multi_class="ovr", labels=labels)
        )
    except ValueError:  # a class absent from the test split
        auroc = float("nan")
    return {
        "accuracy": float(accuracy_score(truth, predicted)),
        "balacc": float(balanced_accuracy_score(truth, predicted)),
        "auroc": auroc,
        "logloss": float(log_loss(truth, probabilities, labels=labels)),
    }


def _write(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    with os.fdopen(fd, "w") as handle:
        handle.write(text)
    os.chmod(tmp, 0o644)
    os.replace(tmp, path)


def export(records: Iterable[dict], methods: list[str], root: Path, n_resamples: int) -> dict:
    """Write every finished method of every record (all resamples) as tsml files.

    Returns the number of prediction files and the summary files written.
    """
    table: dict[tuple[str, str], dict[int, dict[str, float]]] = {}
    n_files = 0
    for record in records:
        if record.get("error") or "test_labels" not in record:
            continue
        resample = record.get("config", {}).get("resample", 0)
        for method in methods:
            entry = record.get("methods", {}).get(method, {})
            if "accuracy" not in entry or "probabilities" not in entry:
                continue
            _write(
                predictions_path(root, method, record["dataset"], resample),
                predictions_text(record, method),
            )
            n_files += 1
            table.setdefault((method, record["dataset"]), {})[resample] = scores(record, method)
    summaries = []
    for method in methods:
        complete = {
            dataset: by_resample
            for (m, dataset), by_resample in sorted(table.items())
            if m == method and all(r in by_resample for r in range(n_resamples))
        }
        if not complete:
            continue
        for measure in MEASURES:
            lines = ["Resamples:," + ",".join(str(r) for r in range(n_resamples))]
            lines += [
                f"{dataset}," + ",".join(repr(by[r][measure]) for r in range(n_resamples))
                for dataset, by in complete.items()
            ]
            path = root / "classification" / measure / f"{tsml_name(method)}_{measure}.csv"
            _write(path, "\n".join(lines) + "\n")
            summaries.append(path)
    return {"predictions": n_files, "summaries": summaries}
