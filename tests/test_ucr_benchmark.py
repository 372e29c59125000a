"""The UCR benchmark tool: results per dataset, resume, failures recorded, odd datasets."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from benchmarks.ucr._data import load_split
from benchmarks.ucr._protocol import paired_test
from benchmarks.ucr._summary import HALF_A, HALF_B, HALF_C1, HALF_C2, halves
from benchmarks.ucr.run import main
from sk_rtw import AutoChoice, RTWNearestCentroid, dtw_pairwise_distance

from .conftest import UCR_DIR

WINDOWS, CENTROIDS, PRIOR = (AutoChoice().windows, AutoChoice().centroids,
                             AutoChoice().prior)  # fmt: skip


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


# ------------------------------------------------------------ command-line checks (27)
@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--data-dir", "/no/such/folder", "--all"], "is not an existing folder"),
        (["--epochs", "-1"], "'-1' is not an integer >= 0"),
        (["--max-series-per-class", "0"], "'0' is not a positive integer"),
        (["--time-budget", "-1"], "'-1' is not a positive number"),
        (["--jobs", "0"], "0 jobs would run nothing"),
        (["--output-length", "1"], "is not an integer >= 2"),
        (["--device", "gpu"], "torch device"),
        (["--scheduler", "tcp://host:8786"], "only with --backend dask"),
        (["--backend", "spark"], "is not one of"),
    ],
)
def test_nonsense_on_the_command_line_stops_before_any_work(args, words, tmp_path, capsys):
    with pytest.raises(SystemExit) as info:
        main([*args, "--out", str(tmp_path / "out"), "--quiet"])
    assert info.value.code == 2 and words in capsys.readouterr().err
    assert not (tmp_path / "out" / "datasets").exists()  # nothing was run


def test_an_output_folder_that_cannot_be_written_stops_the_run_first(tmp_path):
    blocker = tmp_path / "a file"
    blocker.write_text("")
    with pytest.raises(SystemExit, match="exists and is not a folder"):
        main(["--datasets", "ItalyPowerDemand", "--methods", "dba", "--out", str(blocker)])


def test_a_method_that_fails_everywhere_fails_the_run(tmp_path, monkeypatch, capsys):
    import benchmarks.ucr._protocol as protocol

    def broken(*args, **kwargs):
        raise RuntimeError("no averaging today")

    monkeypatch.setattr(protocol, "_fit_estimator", broken)
    args = ["--datasets", "ItalyPowerDemand", "--methods", "dba", "1nn-dtw",
            "--max-series-per-class", "4", "--out", str(tmp_path), "--quiet"]  # fmt: skip
    assert main(args) == 1
    assert "every fit of dba failed" in capsys.readouterr().err
    record = json.loads((tmp_path / "datasets" / "ItalyPowerDemand.json").read_text())
    assert record["methods"]["1nn-dtw"]["accuracy"] > 0  # the other method still ran
    failed = record["methods"]["dba"]
    assert failed["error"] == "RuntimeError: no averaging today"
    assert "in broken" in failed["traceback"]  # where it failed, for the reader of the record


def test_the_documented_output_length_is_the_one_used(tmp_path, capsys):
    """6: --help states the preset's rule; the means of a run have that length."""
    from sk_rtw.align import PRESETS

    rule = PRESETS["class-means"].output_length
    with pytest.raises(SystemExit):
        main(["--help"])
    assert rule.formula in " ".join(capsys.readouterr().out.split())
    args = ["--datasets", "PickupGestureWiimoteZ", "--methods", "rtw", "--epochs", "1",
            "--max-series-per-class", "3", "--out", str(tmp_path), "--quiet"]  # fmt: skip
    assert main(args) == 0
    record = json.loads((tmp_path / "datasets" / "PickupGestureWiimoteZ.json").read_text())
    split = load_split("PickupGestureWiimoteZ", "train", None)
    kept = np.asarray(record["train_index"])
    expected = [rule(split.lengths[kept][split.y[kept] == c])
                for c in record["methods"]["rtw"]["classes"]]  # fmt: skip
    assert record["methods"]["rtw"]["output_length"] == expected


def _start(command, log, env):
    import subprocess

    return subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT, env=env,
                            cwd=log.name.rsplit("/", 1)[0])  # fmt: skip


@pytest.mark.slow
def test_a_run_on_a_dask_cluster_started_the_usual_way(tmp_path, capsys):
    """13: a scheduler and a worker started as separate processes, with sk_rtw installed
    and nothing of this repository importable; then a worker that lacks aeon."""
    import os
    import shutil
    import subprocess
    import sys
    import time

    dask = shutil.which("dask") or str(Path(sys.executable).parent / "dask")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    file = tmp_path / "scheduler.json"
    processes = []
    try:
        scheduler = [dask, "scheduler", "--host", "127.0.0.1", "--port", "0",
                     "--no-dashboard", "--scheduler-file", str(file)]  # fmt: skip
        with open(tmp_path / "scheduler.log", "w") as log:
            processes.append(_start(scheduler, log, env))
        for _ in range(60):
            if file.is_file() and file.stat().st_size:
                break
            time.sleep(0.5)
        worker = [dask, "worker", "--scheduler-file", str(file), "--nworkers", "1",
                  "--nthreads", "1", "--no-dashboard", "--memory-limit", "0"]  # fmt: skip
        with open(tmp_path / "worker.log", "w") as log:
            processes.append(_start(worker, log, env))
        address = json.loads(file.read_text())["address"]
        args = ["--datasets", "ItalyPowerDemand", "GunPoint", "--methods", "dba",
                "--max-series-per-class", "4", "--backend", "dask", "--scheduler", address,
                "--jobs", "2", "--quiet"]  # fmt: skip
        assert main([*args, "--out", str(tmp_path / "run")]) == 0
        for name in ("ItalyPowerDemand", "GunPoint"):
            record = json.loads((tmp_path / "run" / "datasets" / f"{name}.json").read_text())
            assert record["error"] is None and record["methods"]["dba"]["accuracy"] > 0
        # a worker whose environment lacks aeon: named, within seconds, nothing run
        fake = tmp_path / "fake" / "aeon"
        fake.mkdir(parents=True)
        (fake / "__init__.py").write_text('raise ImportError("not installed")\n')
        with open(tmp_path / "fake" / "worker.log", "w") as log:
            processes.append(_start([*worker, "--name", "without-aeon"], log,
                                    {**env, "PYTHONPATH": str(tmp_path / "fake")}))  # fmt: skip
        from dask.distributed import Client

        with Client(address, timeout=10) as client:
            client.wait_for_workers(2, timeout=60)
        start = time.perf_counter()
        with pytest.raises(SystemExit, match=r"worker tcp://\S+ cannot import aeon"):
            main([*args, "--out", str(tmp_path / "run2")])
        assert time.perf_counter() - start < 30
        assert not (tmp_path / "run2" / "datasets").exists()
    finally:
        for process in processes:
            process.terminate()
        for process in processes:
            try:
                process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                process.kill()


def test_default_rows_make_the_same_choice_and_the_halves_report_adds_up(tmp_path, capsys):
    """The default classifier's rows (RTW and DBA centroids) record the same choice, made
    from the training series; the one-mean rows keep one mean per class; the halves report
    splits alphabetically and its cells are the records'; the verdict states the default
    classifier against 1-NN DTW."""
    out = tmp_path / "run"
    args = ["--datasets", "ItalyPowerDemand", "GunPoint", "ArrowHead", "--methods", "dba",
            "dba-default", "rtw-default", "1nn-dtw", "--epochs", "2", "--max-series-per-class",
            "6", "--halves", "--quiet", "--out", str(out)]  # fmt: skip
    assert main(args) == 0
    records = {
        name: json.loads((out / "datasets" / f"{name}.json").read_text())
        for name in ("ArrowHead", "GunPoint", "ItalyPowerDemand")
    }
    for record in records.values():
        dba, rtw = record["methods"]["dba-default"], record["methods"]["rtw-default"]
        assert (dba["dtw_window"], dba["n_centroids"]) == (rtw["dtw_window"], rtw["n_centroids"])
        assert [c["z"] for c in dba["selection"]["candidates"]] == [
            c["z"] for c in rtw["selection"]["candidates"]
        ]
        assert len(dba["selection"]["candidates"]) == len(WINDOWS) * len(CENTROIDS)
        assert rtw["fit_seconds"] >= rtw["selection"]["seconds"] > 0
        one = record["methods"]["dba"]
        assert (one["dtw_window"], one["n_centroids"], one["selection"]) == (None, 1, {})
        assert len(one["output_length"]) == record["n_classes"]
    summary = (out / "summary.md").read_text().split("## Halves")[1]
    assert (
        "Half A: the development archive's alphabetical positions 1, 3, 5, ... (ArrowHead, "
        "GunPoint); Half B: 2, 4, 6, ... (ItalyPowerDemand)" in summary
    )
    row = next(line for line in summary.splitlines() if line.startswith("| dba | 0"))
    half_a = np.mean(
        [records[n]["methods"]["dba"]["accuracy"] for n in ("ArrowHead", "GunPoint")]
    )
    assert row.split(" | ")[1] == f"{half_a:.4f} (n=2)"
    pair = next(
        line for line in summary.splitlines() if line.startswith("| dba-default | 1nn-dtw |")
    )
    at_least = sum(
        r["methods"]["dba-default"]["accuracy"] >= r["methods"]["1nn-dtw"]["accuracy"]
        for r in records.values()
    )
    assert pair.split(" | ")[4] == f"{at_least} / 3"
    printed = capsys.readouterr().out
    default = np.mean([r["methods"]["rtw-default"]["accuracy"] for r in records.values()])
    assert (
        f"RTWNearestCentroid() (band and centroids per class chosen from the training "
        f"data): mean accuracy {default:.4f}" in printed
    )


def test_the_candidates_benchmark_scores_every_candidate_and_the_prior_rule(tmp_path, capsys):
    """Every candidate is a fixed classifier on the test split; the prior rule picks what
    the estimator's choice picks on the same training series."""
    from benchmarks.studies import candidates

    out = tmp_path / "candidates"
    candidates.main(["--data-dir", str(tmp_path), "--datasets", "GunPoint", "ItalyPowerDemand",
                     "--methods", "dba", "--out", str(out)])  # fmt: skip
    printed = capsys.readouterr().out
    prior = candidates.key(*PRIOR)
    assert f"| prior {prior.replace('|', ', k=')}, z=1.0 |" in printed
    assert "| best leave-one-out score |" in printed
    record = json.loads((out / "GunPoint.json").read_text())
    grid = [candidates.key(w, k) for w in WINDOWS for k in CENTROIDS]
    assert list(record["test"]["dba"]) == list(record["loo"]) == grid
    train = load_split("GunPoint", "train", None)
    clf = RTWNearestCentroid(method="dba").fit(train.X, train.y)
    chosen = candidates.key(clf.dtw_window_, clf.n_centroids_)
    assert candidates.prior_rule(record["loo"], prior, 1.0, grid) == chosen
    test = load_split("GunPoint", "test", None)
    assert record["test"]["dba"][chosen] == pytest.approx(clf.score(test.X, test.y))
    assert candidates.parse(candidates.key(None, 1.0)) == (None, 1.0)
    assert candidates.parse(candidates.key(0.05, 1)) == (0.05, 1)


def test_the_halves_of_the_archive_and_of_the_large_training_sets():
    names = ["Beef", "ArrowHead", "Crop", "Computers", "Coffee", "ElectricDevices"]
    assert halves(names) == {
        "A": ["ArrowHead", "Beef", "Coffee"],  # the archive's fixed halves
        "C1": ["Computers", "Crop"],
        "C2": ["ElectricDevices"],
    }
    assert halves(["Zeta", "Alpha", "Beta", "BME"]) == {
        "A": ["Alpha", "Zeta"],  # other datasets: alphabetical positions 1, 3, ...
        "B": ["BME", "Beta"],
    }
    # the fixed halves of the development archive are its alphabetical halves
    archive = sorted(HALF_A + HALF_B)
    assert (archive[0::2], archive[1::2]) == (list(HALF_A), list(HALF_B))
    assert not set(HALF_C1) & set(HALF_C2) and len(HALF_C1) == len(HALF_C2) == 3


def test_1nn_with_a_learned_band_and_a_resume_across_seeds(tmp_path, capsys):
    """The learned band is the leave-one-out best of the candidates' bands (squared costs,
    ties to the narrower); --resume keeps finished methods with the same settings, and
    the 1-NN rows across seeds."""
    out = tmp_path / "run"
    args = ["--datasets", "ItalyPowerDemand", "--methods", "dba", "1nn-dtw-band",
            "--max-series-per-class", "10", "--quiet", "--out", str(out)]  # fmt: skip
    assert main(args) == 0
    path = out / "datasets" / "ItalyPowerDemand.json"
    record = json.loads(path.read_text())
    entry = record["methods"]["1nn-dtw-band"]
    train = load_split("ItalyPowerDemand", "train", None)
    kept = np.asarray(record["train_index"])
    X, y = train.X[kept], train.y[kept]
    scores = {}
    for window in WINDOWS:
        D = dtw_pairwise_distance(X, window=window, squared=True)
        np.fill_diagonal(D, np.inf)
        scores[window] = float(np.mean(y[D.argmin(1)] == y))
    best = max(scores.values())
    assert entry["dtw_window"] == next(w for w in WINDOWS if scores[w] == best)
    test = load_split("ItalyPowerDemand", "test", None)
    nearest = dtw_pairwise_distance(test.X, X, window=entry["dtw_window"], squared=True)
    assert entry["accuracy"] == pytest.approx(np.mean(y[nearest.argmin(1)] == test.y))
    # the same settings: nothing to do; another seed: the 1-NN row is kept, DBA is not
    # (with --max-series-per-class the seed draws the training series: both are redone)
    mtime = path.stat().st_mtime_ns
    assert main([*args, "--resume"]) == 0
    assert path.stat().st_mtime_ns == mtime
    full = [a for a in args if a not in ("--max-series-per-class", "10")]
    assert main(full) == 0
    before = json.loads(path.read_text())["methods"]
    assert main([*full, "--resume", "--seed", "1"]) == 0
    after = json.loads(path.read_text())
    assert after["config"]["seed"] == 1
    assert after["methods"]["1nn-dtw-band"]["fit_seconds"] == before["1nn-dtw-band"]["fit_seconds"]
    assert after["methods"]["dba"]["fit_seconds"] != before["dba"]["fit_seconds"]


def test_the_seeds_report_gives_every_target_per_half_and_seed(tmp_path, capsys):
    """Two runs that differ in the seed: each target once per half, seeds in order, the
    1-NN rows reused by --resume; the choice counted the same when it is."""
    import shutil

    from benchmarks.ucr import seeds

    args = ["--datasets", "ItalyPowerDemand", "GunPoint", "--methods", "rtw", "rtw-default",
            "1nn-dtw", "1nn-dtw-band", "--epochs", "2", "--quiet"]  # fmt: skip
    assert main([*args, "--out", str(tmp_path / "s0")]) == 0
    shutil.copytree(tmp_path / "s0", tmp_path / "s1")
    assert main([*args, "--out", str(tmp_path / "s1"), "--seed", "1", "--resume"]) == 0
    capsys.readouterr()
    # a dataset only a baseline ran on (no default row) is left out, not a KeyError
    baseline_only = json.loads((tmp_path / "s0" / "datasets" / "GunPoint.json").read_text())
    baseline_only["dataset"] = "ArrowHead"
    baseline_only["methods"] = {"1nn-dtw": baseline_only["methods"]["1nn-dtw"]}
    (tmp_path / "s0" / "datasets" / "ArrowHead.json").write_text(json.dumps(baseline_only))
    seeds.main([str(tmp_path / "s0"), str(tmp_path / "s1"), "--combine", "all=A+B"])
    printed = capsys.readouterr().out
    assert "Seeds 0, 1" in printed
    assert "| target | half A (1) | half B (1) | half all (2) |" in printed
    record = json.loads((tmp_path / "s0" / "datasets" / "GunPoint.json").read_text())
    default = f"{record['methods']['rtw-default']['accuracy']:.4f}"
    row = next(line for line in printed.splitlines() if line.startswith("| mean accuracy, def"))
    assert row.split(" | ")[1].startswith(default)  # half A holds GunPoint
    assert "| the same choice on every seed (datasets) | 1 of 1 | 1 of 1 | 2 of 2 |" in printed


def test_prototype_and_minirocket_rows(tmp_path, capsys):
    """The prototype rows keep their decision and the nearest centroid's accuracy beside
    their own; MiniRocket runs on unequal lengths through resampling."""
    out = tmp_path / "results"
    args = ["--datasets", "ItalyPowerDemand", "--methods", "rtw-default", "rtw-prototype",
            "dba-prototype", "minirocket", "--epochs", "2", "--max-series-per-class", "8",
            "--halves", "--out", str(out), "--quiet"]  # fmt: skip
    assert main(args) == 0
    record = json.loads((out / "datasets" / "ItalyPowerDemand.json").read_text())
    for row in ("rtw-prototype", "dba-prototype"):
        entry = record["methods"][row]
        assert entry["decision"] in ("readout", "nearest")
        assert 0.0 <= entry["nearest_accuracy"] <= 1.0
        if entry["decision"] == "nearest":
            assert entry["accuracy"] == entry["nearest_accuracy"]
    assert record["methods"]["minirocket"]["accuracy"] > 0.5
    summary = (out / "summary.md").read_text()
    assert "The prototype classifier, RTWPrototypeClassifier()" in summary
    assert "| rtw-prototype | minirocket |" in summary


def test_series_are_resampled_to_one_length_for_minirocket():
    from benchmarks.ucr._protocol import equal_length

    ramp = [np.linspace(0.0, 1.0, 5), np.linspace(0.0, 1.0, 9)]
    resampled = equal_length(ramp, 17)
    np.testing.assert_allclose(resampled[:, :, 0], np.tile(np.linspace(0, 1, 17), (2, 1)))
    stacked = np.zeros((3, 17))
    assert equal_length(stacked, 17) is stacked
