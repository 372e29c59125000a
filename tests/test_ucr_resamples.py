"""The UCR benchmark's resamples and its tsml-format results: aeon's stratified
resampling, resample 0 unchanged, resume per resample, files that aeon's loader and
tsml-eval's evaluation read."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest
from sklearn.metrics import accuracy_score

pytest.importorskip("aeon")

from aeon.benchmarking.resampling import stratified_resample_data
from aeon.benchmarking.results_loaders import get_estimator_results
from aeon.datasets import load_classification

from benchmarks.ucr._data import load_split, resample_split
from benchmarks.ucr._resamples import paired_over_resamples
from benchmarks.ucr._tsml import MEASURES, tsml_name
from benchmarks.ucr.run import main
from sk_rtw.utils import from_aeon

DATASETS = ["ArrowHead", "GunPoint", "ItalyPowerDemand"]  # shipped with aeon
METHODS = ["dba-default", "1nn-dtw", "minirocket"]
#: tsml-eval pins aeon < 1.2 and scikit-learn < 1.7: CI installs it in a second
#: environment and names its interpreter here.
TSML_EVAL_PYTHON = os.environ.get("SK_RTW_TSML_EVAL_PYTHON")


@pytest.mark.parametrize("resample", [1, 4])
def test_a_resample_is_aeons_stratified_resample(resample):
    train, test = (
        load_split("ItalyPowerDemand", "train", None),
        load_split("ItalyPowerDemand", "test", None),
    )
    new_train, new_test = resample_split(train, test, resample)
    X_train, y_train = load_classification("ItalyPowerDemand", split="train")
    X_test, y_test = load_classification("ItalyPowerDemand", split="test")
    ref = stratified_resample_data(X_train, y_train, X_test, y_test, random_state=resample)
    np.testing.assert_array_equal(new_train.X, from_aeon(ref[0]))
    np.testing.assert_array_equal(new_train.y, ref[1])
    np.testing.assert_array_equal(new_test.X, from_aeon(ref[2]))
    np.testing.assert_array_equal(new_test.y, ref[3])
    # the archive's class counts, and not the archive's split
    for old, new in ((train, new_train), (test, new_test)):
        assert sorted(np.unique(old.y, return_counts=True)[1]) == sorted(
            np.unique(new.y, return_counts=True)[1]
        )
    assert not np.array_equal(new_train.X, train.X)


def test_resample_zero_is_the_archives_split():
    train, test = load_split("GunPoint", "train", None), load_split("GunPoint", "test", None)
    assert resample_split(train, test, 0) == (train, test)


def test_paired_over_resamples():
    a = np.array([0.90, 0.91, 0.92, 0.90, 0.93])
    lower = a - np.array([0.05, 0.04, 0.06, 0.05, 0.03])
    assert paired_over_resamples(a, lower) == "a"
    assert paired_over_resamples(lower, a) == "b"
    assert paired_over_resamples(a, a) == "none"
    assert paired_over_resamples(a, a + np.array([0.02, -0.02, 0.01, -0.01, 0.0])) == "none"


def _parse_predictions(path: Path) -> dict:
    """An independent reading of a tsml predictions file, by its format."""
    lines = path.read_text().splitlines()
    first = lines[0].split(",")
    third = lines[2].split(",")
    cases = [line.split(",") for line in lines[3:]]
    n_classes = int(third[5])
    return {
        "dataset": first[0], "classifier": first[1], "split": first[2],
        "resample": int(first[3]), "unit": first[4], "comment": ",".join(first[5:]),
        "accuracy": float(third[0]), "n_classes": n_classes,
        "truth": np.array([int(c[0]) for c in cases]),
        "predicted": np.array([int(c[1]) for c in cases]),
        "blank": {c[2] for c in cases},
        "probabilities": np.array([[float(v) for v in c[3:3 + n_classes]] for c in cases]),
    }  # fmt: skip


@pytest.fixture(scope="module")
def two_resamples(tmp_path_factory):
    out = tmp_path_factory.mktemp("resamples")
    args = ["--datasets", *DATASETS, "--methods", *METHODS, "--resamples", "2",
            "--out", str(out), "--quiet"]  # fmt: skip
    assert main(args) == 0
    return out


def test_every_classifier_dataset_and_resample_has_a_predictions_file(two_resamples):
    out = two_resamples
    for dataset in DATASETS:
        for resample in (0, 1):
            name = "datasets/" + dataset if resample == 0 else f"resamples/{dataset}/resample1"
            record = json.loads((out / f"{name}.json").read_text())
            classes = sorted(set(record["test_labels"]))
            for method in METHODS:
                path = (out / "tsml" / tsml_name(method) / "Predictions" / dataset
                        / f"testResample{resample}.csv")  # fmt: skip
                parsed = _parse_predictions(path)
                entry = record["methods"][method]
                assert (parsed["dataset"], parsed["classifier"]) == (dataset, tsml_name(method))
                assert (parsed["split"], parsed["resample"]) == ("TEST", resample)
                assert parsed["unit"] == "MILLISECONDS" and parsed["blank"] == {""}
                assert parsed["n_classes"] == len(classes)
                np.testing.assert_array_equal(
                    parsed["truth"], [classes.index(c) for c in record["test_labels"]]
                )
                np.testing.assert_array_equal(
                    parsed["predicted"], [classes.index(c) for c in entry["predictions"]]
                )
                # exactly scikit-learn's accuracy of the cases, which tsml-eval checks
                assert parsed["accuracy"] == accuracy_score(parsed["truth"], parsed["predicted"])
                assert parsed["accuracy"] == pytest.approx(entry["accuracy"], rel=1e-12)
                np.testing.assert_allclose(parsed["probabilities"].sum(1), 1.0, rtol=1e-9)
                assert np.all(parsed["probabilities"].argmax(1) == parsed["predicted"])
                for label, code in zip(classes, range(len(classes)), strict=True):
                    assert f"'{label}': {code}" in parsed["comment"]


def test_summaries_load_with_aeons_results_loader(two_resamples):
    root = two_resamples / "tsml"
    # aeon's public loader knows the published classifiers' names (1NN-DTW, MiniROCKET)
    loaded = get_estimator_results(
        ["1NN-DTW", "MiniROCKET"], datasets=DATASETS, num_resamples=2, path=str(root)
    )
    for name, method in (("1NN-DTW", "1nn-dtw"), ("MiniROCKET", "minirocket")):
        for dataset in DATASETS:
            zero = json.loads((two_resamples / "datasets" / f"{dataset}.json").read_text())
            one = json.loads(
                (two_resamples / "resamples" / dataset / "resample1.json").read_text()
            )
            expected = [zero["methods"][method]["accuracy"], one["methods"][method]["accuracy"]]
            np.testing.assert_allclose(loaded[name][dataset], expected, rtol=1e-12)
    for measure in MEASURES:
        path = root / "classification" / measure / f"DBANearestCentroid_{measure}.csv"
        assert path.is_file()


def test_resample_zero_is_unchanged_by_resamples_and_resume_computes_what_is_missing(
    two_resamples, tmp_path, capsys
):
    out = tmp_path / "one"
    args = ["--datasets", *DATASETS, "--methods", "dba-default", "1nn-dtw", "--out", str(out),
            "--quiet"]  # fmt: skip
    assert main(args) == 0
    for dataset in DATASETS:
        alone = json.loads((out / "datasets" / f"{dataset}.json").read_text())
        with_resamples = json.loads((two_resamples / "datasets" / f"{dataset}.json").read_text())
        for method in ("dba-default", "1nn-dtw"):
            assert (
                alone["methods"][method]["predictions"]
                == (with_resamples["methods"][method]["predictions"])
            )
            assert (
                alone["methods"][method]["accuracy"]
                == (with_resamples["methods"][method]["accuracy"])
            )
    # a killed run: resample 1 of one dataset missing; --resume computes only that
    capsys.readouterr()
    assert main([*args, "--resamples", "2"]) == 0
    (out / "resamples" / "GunPoint" / "resample1.json").unlink()
    before = {p: p.stat().st_mtime_ns for p in out.rglob("*.json")}
    assert main([*args, "--resamples", "2", "--resume"]) == 0
    assert "3 dataset(s) x 2 resamples, 5 already done" in capsys.readouterr().err
    assert all(p.stat().st_mtime_ns == t for p, t in before.items())
    assert (out / "resamples" / "GunPoint" / "resample1.json").is_file()
    assert "## Over 2 stratified resamples" in (out / "summary.md").read_text()


TSML_EVAL_CHECK = """
import sys
from tsml_eval.evaluation import evaluate_classifiers_by_problem
from tsml_eval.utils.results_loading import load_estimator_results
root, save = sys.argv[1], sys.argv[2]
names, datasets = sys.argv[3].split(","), sys.argv[4].split(",")
for name in names:
    for dataset in datasets:
        for resample in (0, 1):
            path = f"{root}/{name}/Predictions/{dataset}/testResample{resample}.csv"
            r = load_estimator_results(path)
            print("loaded", name, dataset, resample, repr(r.accuracy))
evaluate_classifiers_by_problem(root, names, datasets, save, resamples=2, eval_name="check")
"""


@pytest.mark.skipif(
    not TSML_EVAL_PYTHON, reason="no tsml-eval environment ($SK_RTW_TSML_EVAL_PYTHON unset)"
)
def test_tsml_eval_reads_and_evaluates_the_files(two_resamples, tmp_path):
    names = [tsml_name(m) for m in METHODS]
    done = subprocess.run(
        [TSML_EVAL_PYTHON, "-c", TSML_EVAL_CHECK, str(two_resamples / "tsml"),
         str(tmp_path), ",".join(names), ",".join(DATASETS)],
        capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    loaded = [line.split()[1:] for line in done.stdout.splitlines() if line.startswith("loaded ")]
    for name, dataset, resample, accuracy in loaded:
        method = METHODS[names.index(name)]
        path = "datasets/" + dataset if resample == "0" else f"resamples/{dataset}/resample1"
        record = json.loads((two_resamples / f"{path}.json").read_text())
        assert float(accuracy) == pytest.approx(record["methods"][method]["accuracy"], rel=1e-12)
    assert len(loaded) == len(names) * len(DATASETS) * 2
    summary = (tmp_path / "check" / "Accuracy" / "accuracy_mean.csv").read_text()
    assert all(name in summary for name in names)


def test_critical_difference_diagram_from_the_files(two_resamples, tmp_path, capsys):
    from benchmarks.ucr.critical_difference import main as cd_main

    picture = tmp_path / "cd.png"
    assert cd_main([str(two_resamples / "tsml"), "--out", str(picture)]) == 0
    assert picture.stat().st_size > 0
    printed = capsys.readouterr().out
    for method in METHODS:
        accuracies = [
            json.loads((two_resamples / f"{path}.json").read_text())["methods"][method]["accuracy"]
            for dataset in DATASETS
            for path in (f"datasets/{dataset}", f"resamples/{dataset}/resample1")
        ]
        assert f"{tsml_name(method)}: mean accuracy {np.mean(accuracies):.4f}" in printed
    with pytest.raises(SystemExit, match="no accuracy summary for HC2"):
        cd_main([str(two_resamples / "tsml"), "--classifiers", "HC2", "MiniROCKET", "1NN-DTW"])
