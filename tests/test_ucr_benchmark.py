"""The UCR benchmark tool: results per dataset, resume, failures recorded, odd datasets."""

from __future__ import annotations

import json

import numpy as np
import pytest

from benchmarks.ucr._data import load_split
from benchmarks.ucr._protocol import paired_test
from benchmarks.ucr.run import main

from .conftest import UCR_DIR


def test_small_run_writes_results_resumes_and_records_failures(tmp_path, capsys):
    out = tmp_path / "results"
    args = [
        "--datasets",
        "ItalyPowerDemand",
        "NoSuchDataset",
        "--methods",
        "rtw",
        "ttw",
        "dba",
        "1nn-dtw",
        "--epochs",
        "2",
        "--max-series-per-class",
        "6",
        "--out",
        str(out),
        "--quiet",
    ]
    assert main(args) == 0
    record = json.loads((out / "datasets" / "ItalyPowerDemand.json").read_text())
    assert record["error"] is None and record["n_train"] == 12
    for method in ("rtw", "ttw", "dba", "1nn-dtw"):
        entry = record["methods"][method]
        assert 0.0 <= entry["accuracy"] <= 1.0
        assert len(entry["predictions"]) == record["n_test"] == 1029
    assert len(record["methods"]["rtw"]["alignment"]) == 12
    assert set(record["tests"]) >= {"rtw|ttw", "rtw|dba"}
    assert not (out / "datasets" / "NoSuchDataset.json").exists()  # never tried to download
    captured = capsys.readouterr()
    assert "'NoSuchDataset' is not available offline" in captured.err
    assert "RTW against dba:" in captured.out  # the verdict
    summary = (out / "summary.md").read_text()
    assert "Table II" in summary and "ItalyPowerDemand" in summary and "## Verdict" in summary
    assert (out / "accuracy_scatter.png").stat().st_size > 0
    for path in (out / "summary.md", out / "datasets" / "ItalyPowerDemand.json"):
        assert path.stat().st_mode & 0o777 == 0o644  # readable result files
    mtime = (out / "datasets" / "ItalyPowerDemand.json").stat().st_mtime_ns
    capsys.readouterr()
    main([*args, "--resume"])
    assert (out / "datasets" / "ItalyPowerDemand.json").stat().st_mtime_ns == mtime
    assert "1 already done" in capsys.readouterr().err


def test_a_run_with_no_available_dataset_fails_clearly(tmp_path, capsys):
    assert main(["--datasets", "NoSuchDataset", "--out", str(tmp_path), "--quiet"]) == 1
    err = capsys.readouterr().err
    assert "none of the requested datasets is available offline" in err
    assert "nothing is downloaded" in err


def test_failing_datasets_are_recorded_and_make_the_run_fail(tmp_path, monkeypatch, capsys):
    import benchmarks.ucr._protocol as protocol

    def broken(*args, **kwargs):
        raise OSError("disk on fire")

    monkeypatch.setattr(protocol, "load_split", broken)
    args = ["--datasets", "ItalyPowerDemand", "--methods", "dba", "--out", str(tmp_path)]
    assert main([*args, "--quiet"]) == 1
    record = json.loads((tmp_path / "datasets" / "ItalyPowerDemand.json").read_text())
    assert "disk on fire" in record["error"]
    assert "every dataset failed" in capsys.readouterr().err


def test_help_lists_every_option_with_examples(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    text = capsys.readouterr().out
    for option in ("--data-dir", "--methods", "--epochs", "--jobs", "--resume", "--verbose"):
        assert option in text
    assert "python benchmarks/ucr/run.py --data-dir ../shared/ucr" in text
    assert "nothing is downloaded" in text.lower()


def test_paired_test_decisions():
    a = np.array([1.0, 2.0, 3.0, 4.0, 5.0, 6.0])
    assert paired_test(a, a + 1.0 + 0.01 * np.arange(6), True)["better"] == "a"
    assert paired_test(a, a + 1.0 + 0.01 * np.arange(6), False)["better"] == "b"
    assert paired_test(a, a, True)["better"] == "none"
    noisy = a + np.array([0.5, -0.5, 0.4, -0.4, 0.1, -0.1])
    assert paired_test(a, noisy, True)["better"] == "none"


def test_unequal_lengths_are_kept_as_lists():
    split = load_split("PickupGestureWiimoteZ", "train", None)
    assert isinstance(split.X, list) and split.lengths.min() < split.lengths.max()


@pytest.mark.skipif(not (UCR_DIR / "DodgerLoopGame").is_dir(), reason="no DodgerLoopGame")
def test_missing_values_are_interpolated_and_reported():
    split = load_split("DodgerLoopGame", "train", str(UCR_DIR))
    assert np.isfinite(np.asarray(split.X)).all()
    assert any("interpolation" in note for note in split.notes)


@pytest.mark.skipif(not UCR_DIR.is_dir(), reason="needs the UCR development archive")
@pytest.mark.parametrize("methods", [["dba"], ["rtw", "dba"]])
def test_one_or_two_methods_finish_with_summary_and_verdict(methods, tmp_path, capsys):
    """aeon's Friedman test needs three methods: with fewer the diagram is skipped and
    said so, and the summary and the verdict still come (exit 0)."""
    out = tmp_path / "results"
    args = ["--data-dir", str(UCR_DIR), "--datasets", "Chinatown", "ItalyPowerDemand",
            "Coffee", "BME", "--methods", *methods, "--epochs", "2",
            "--max-series-per-class", "4", "--out", str(out), "--quiet"]  # fmt: skip
    assert main(args) == 0
    printed = capsys.readouterr().out
    assert "critical-difference diagram not drawn: it needs at least 3 methods" in printed
    assert "Verdict over 4 dataset(s)" in printed
    assert (out / "summary.md").is_file() and not (out / "critical_difference.png").exists()
