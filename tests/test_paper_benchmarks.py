"""Helpers of the paper experiments: robot kinematics, letters on S^3, a small S^1 run."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from benchmarks.paper import inverted_s1
from benchmarks.paper._data import (
    letters_on_s3,
    planar_arm_kinematics,
    planar_arm_mass_matrix,
    quaternion_exp,
    quaternion_product,
    track_with_planar_arm,
)
from sk_rtw.datasets import make_warped_signals


def test_planar_arm_jacobian_matches_finite_differences(rng):
    lengths, q = rng.uniform(0.1, 0.3, 5), rng.uniform(-1, 1, 5)
    _, J = planar_arm_kinematics(q, lengths)
    eps = 1e-6
    fd = np.stack(
        [
            (
                planar_arm_kinematics(q + eps * e, lengths)[0]
                - planar_arm_kinematics(q - eps * e, lengths)[0]
            )
            / (2 * eps)
            for e in np.eye(5)
        ],
        axis=-1,
    )
    np.testing.assert_allclose(J, fd, atol=1e-8)


def test_planar_arm_mass_matrix_gives_the_kinetic_energy_of_the_rods(rng):
    n = 4
    lengths, masses = rng.uniform(0.1, 0.3, n), rng.uniform(0.5, 2.0, n)
    q, qdot = rng.uniform(-1, 1, n), rng.standard_normal(n)
    s = np.linspace(0.0, 1.0, 4001)

    def rod_points(angles):
        theta, base, points = np.cumsum(angles), np.zeros(2), []
        for k in range(n):
            direction = np.array([np.cos(theta[k]), np.sin(theta[k])])
            points.append(base + np.outer(s * lengths[k], direction))
            base = base + lengths[k] * direction
        return points

    h = 1e-6
    ahead, behind = rod_points(q + h * qdot), rod_points(q - h * qdot)
    energy = sum(
        0.5 * m * np.trapezoid((((a - b) / (2 * h)) ** 2).sum(1), s)
        for m, a, b in zip(masses, ahead, behind, strict=True)
    )
    M = planar_arm_mass_matrix(q, lengths, masses)
    assert 0.5 * qdot @ M @ qdot == pytest.approx(energy, rel=1e-6)
    np.testing.assert_allclose(M, M.T)
    assert np.linalg.eigvalsh(M).min() > 0


def test_inverse_kinematics_follows_the_targets():
    lengths = np.full(4, 0.25)
    t = np.linspace(0, 1, 30)
    targets = np.stack([0.5 + 0.1 * np.cos(2 * np.pi * t), 0.2 * np.sin(2 * np.pi * t)], -1)
    q = track_with_planar_arm(targets[None], lengths)
    reached, _ = planar_arm_kinematics(q, lengths)
    np.testing.assert_allclose(reached[0], targets, atol=1e-8)


def test_quaternion_helpers_match_scipy(rng):
    p, q = rng.standard_normal((2, 10, 4))
    p /= np.linalg.norm(p, axis=-1, keepdims=True)
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    expected = Rotation.from_quat(p, scalar_first=True) * Rotation.from_quat(q, scalar_first=True)
    got = Rotation.from_quat(quaternion_product(p, q), scalar_first=True)
    np.testing.assert_allclose((got.inv() * expected).magnitude(), 0.0, atol=1e-10)
    u = rng.standard_normal((10, 3)) * 0.5
    rotvec = Rotation.from_quat(quaternion_exp(u), scalar_first=True).as_rotvec()
    np.testing.assert_allclose(rotvec, 2 * u, atol=1e-12)  # Exp without the factor 1/2
    letters = rng.uniform(-10, 10, (2, 20, 2))
    on_s3 = letters_on_s3(letters, 0.05)
    np.testing.assert_allclose(np.linalg.norm(on_s3, axis=-1), 1.0)


def test_inverted_s1_runs_the_dtw_baselines(capsys):
    inverted_s1.main(["--n-signals", "3", "--trials", "1", "--methods", "mmddtw", "pdtw", "dba"])
    out = capsys.readouterr().out
    for label in ("MMDDTW", "p-DTW", "DBA", "unaligned", "| method | RA | BL | AQ"):
        assert label in out


@pytest.mark.parametrize("space", ["pose", "quaternion", "euclidean"])
def test_imitation_models_reproduce_identical_demonstrations(space):
    """Three copies of one demonstration: GMR and GP reproduce it, and the DMP is the
    one-demonstration DMP (the average of identical weights)."""
    from benchmarks.paper.imitation import POSE, factors, fit_dmp, prepare, reproduce
    from sk_rtw import dtw_distance
    from sk_rtw.manifolds import Euclidean, Quaternion

    manifold = {"pose": POSE, "quaternion": Quaternion(), "euclidean": Euclidean(2)}[space]
    demo = make_warped_signals(manifold, 1, 80, 0, amplitude=0.5).original
    prepared, mean = prepare("raw", [demo] * 3, manifold, 80, 2, 0)
    np.testing.assert_allclose(mean, demo, atol=1e-9)
    for model in ("GMR", "GP"):
        out = reproduce(model, prepared, manifold, 0)
        assert out.shape == demo.shape
        for cols, part in factors(manifold).values():
            scale = dtw_distance(demo[:, cols], demo[::-1, cols], manifold=part, normalize="path")
            error = dtw_distance(out[:, cols], demo[:, cols], manifold=part, normalize="path")
            assert error < 0.05 * scale, (model, error, scale)
    np.testing.assert_allclose(fit_dmp(prepared, manifold), fit_dmp(prepared[:1], manifold),
                               atol=1e-9)  # fmt: skip
    dmp = fit_dmp(prepared, manifold)
    assert dmp.shape == demo.shape and np.all(np.isfinite(dmp))
    for cols, part in factors(manifold).values():  # a DMP lags, but follows the shape
        scale = dtw_distance(demo[:, cols], demo[::-1, cols], manifold=part, normalize="path")
        assert dtw_distance(dmp[:, cols], demo[:, cols], manifold=part, normalize="path") < (
            0.3 * scale
        )


# ------------------------------------------------------------ command-line checks (27)
def test_imitation_reads_only_the_tasks_asked_for_and_names_a_missing_file(tmp_path):
    """10: an empty data folder and --tasks rcfs: the RCFS file is named with the
    folder it was looked for in, before any work; no other task's file is read."""
    from benchmarks.paper import imitation

    with pytest.raises(SystemExit, match=r"no C\.npy in .*rcfs/2Dletters") as info:
        imitation.main(["--data-dir", str(tmp_path), "--tasks", "rcfs", "--quick"])
    assert "CarrotGrating" not in str(info.value)


@pytest.mark.parametrize("script", ["imitation", "pose", "spd", "quaternion_s3", "inverted_s1"])
def test_an_unwritable_markdown_path_stops_the_run_before_any_work(script, tmp_path):
    """11: checked on the command line, not after the first task (minutes)."""
    import importlib

    module = importlib.import_module(f"benchmarks.paper.{script}")
    blocker = tmp_path / "a file"
    blocker.write_text("")
    with pytest.raises(SystemExit, match="cannot write"):
        module.main(["--markdown", str(blocker / "tables.md"), "--epochs", "1"])


def test_settings_of_the_paper_runs_are_checked_on_the_command_line(capsys):
    with pytest.raises(SystemExit, match="'bogus' is no setting"):
        inverted_s1.main(["--options", '{"bogus": 1}', "--trials", "1"])
    with pytest.raises(SystemExit, match="hidden_size must be an integer >= 1"):
        inverted_s1.main(["--options", '{"hidden_size": 0}', "--trials", "1"])
    with pytest.raises(SystemExit):
        inverted_s1.main(["--epochs", "-3"])
    assert "is not an integer >= 0" in capsys.readouterr().err


def test_the_clustering_benchmark_classifies_manifold_demonstrations(monkeypatch, capsys):
    """Section 4 of benchmarks/clustering.py on two well-separated shapes on S^2: every row
    is printed with its accuracy, the tuned rows with their choice, and 1-NN DTW."""
    from benchmarks import clustering
    from benchmarks.paper import _data

    t = np.linspace(0, 1, 30)
    rng = np.random.default_rng(0)
    X, y = [], []
    for label, bend in enumerate((0.2, -0.2)):
        for _ in range(6):
            shifted = np.clip(t + 0.05 * rng.standard_normal(), 0, 1)
            angle = np.stack([shifted, bend * np.sin(np.pi * shifted)], axis=1)
            X.append(np.concatenate([np.sin(angle), np.cos(angle).prod(1, keepdims=True)], 1))
            y.append(label)
    X = [x / np.linalg.norm(x, axis=1, keepdims=True) for x in X]
    monkeypatch.setattr(_data, "data_dir", lambda demo_dir: demo_dir)
    data = [("two arcs on S^2", "sphere", X, np.array(y))]
    monkeypatch.setattr(clustering, "labelled_demonstrations", lambda root: iter(data))
    clustering.section_classify("unused", epochs=2)
    line = next(row for row in capsys.readouterr().out.splitlines() if "two arcs" in row)
    assert line.split("|")[0].split()[-1] == "12"
    cells = line.split("|")[1].split()
    assert cells[0] == "1.000"  # default RTW separates the arcs
    assert line.count("w=") == 2 and line.count("k=") == 2
    assert float(cells[-1]) == 1.0  # 1-NN DTW


def test_the_scale_benchmark_adds_rows_for_given_centroids_and_checks_them(monkeypatch, capsys):
    """benchmarks/classifier_scale.py on a tiny set: one row per --n-centroids value (auto:
    the default) with its ratio to one mean per class, no 1-NN line at --nn-test 0, bad
    values refused."""
    from benchmarks import classifier_scale

    monkeypatch.setattr(classifier_scale, "SETS", {"handoutlines": (24, 8, 40, 2)})
    classifier_scale.main(["--sets", "handoutlines", "--methods", "dba",
                           "--n-centroids", "auto", "2", "0.5", "--nn-test", "0"])  # fmt: skip
    out = capsys.readouterr().out
    assert "dba      k=2: fit" in out and "dba    k=0.5: fit" in out
    assert "dba k=2 / one mean fit" in out and "dba k=0.5 / one mean fit" in out
    assert "dba  default: fit" in out and "dba default / one mean fit" in out
    assert "1-NN DTW" not in out
    for bad in ("0", "1.5", "many"):
        with pytest.raises(SystemExit):
            classifier_scale.main(["--n-centroids", bad])
        assert "is not auto, an integer >= 1 or a fraction in (0, 1]" in capsys.readouterr().err


def test_the_scale_benchmark_fixes_the_band_of_its_rows_when_asked(monkeypatch, capsys):
    """--dtw-window fixes the band of the --n-centroids rows (no choice runs: the row
    prints none) and is refused outside auto, none and [0, 1]."""
    from benchmarks import classifier_scale

    monkeypatch.setattr(classifier_scale, "SETS", {"handoutlines": (24, 8, 40, 2)})
    classifier_scale.main(["--sets", "handoutlines", "--methods", "dba", "--n-centroids",
                           "2", "--dtw-window", "0.1", "--nn-test", "0"])  # fmt: skip
    rows = [line for line in capsys.readouterr().out.splitlines() if "k=2, band 0.1" in line]
    assert len(rows) == 2 and "fit" in rows[0] and "choice" not in rows[0]
    assert "k=2, band 0.1 / one mean fit" in rows[1]
    for bad in ("-0.1", "1.5", "wide"):
        with pytest.raises(SystemExit):
            classifier_scale.main(["--dtw-window", bad])
        assert "is not auto, none or a fraction in [0, 1]" in capsys.readouterr().err


def test_the_spd_speed_benchmark_prints_each_manifold_against_r3(capsys):
    """benchmarks/spd_speed.py's DTW section: one row per manifold with the time a cell,
    R^3 the 1.0x row."""
    import numba
    import torch

    from benchmarks import spd_speed

    threads = torch.get_num_threads(), numba.get_num_threads()
    spd_speed.main(["--sections", "dtw", "--repeats", "1"])
    assert (torch.get_num_threads(), numba.get_num_threads()) == threads  # put back
    rows = [line for line in capsys.readouterr().out.splitlines() if "x R^3" in line]
    assert [row.split(":")[0].strip() for row in rows] == [
        "Euclidean(dim=3)", "SPD(dim=2)", "SPD(dim=3)", "SPD(dim=4)", "SPD(dim=8)"
    ]
    assert rows[0].endswith("1.0x R^3")
    assert all(" ns a cell," in row for row in rows)


def test_the_spd_speed_benchmark_counts_eigendecompositions(capsys):
    """The eigh section counts LAPACK calls by SPD size and puts torch back as it was."""
    import torch

    from benchmarks import spd_speed

    eigh, threads = torch.linalg.eigh, torch.get_num_threads()
    spd_speed.eigh_rows(n_series=3, length=12, n_epochs=1)
    rows = [line for line in capsys.readouterr().out.splitlines() if "SPD(dim=" in line]
    assert [row.split(":")[0].strip() for row in rows] == ["SPD(dim=8)", "SPD(dim=2)"]
    assert "eigh " in rows[0] and "million matrices" in rows[0]
    assert "eigh " not in rows[1]  # SPD(2) has closed forms: no eigendecomposition
    assert torch.linalg.eigh is eigh and torch.get_num_threads() == threads


@pytest.mark.parametrize("manifold", ["sphere", "quaternion", "spd2"])
def test_the_maps_benchmark_times_both_paths_of_the_maps(manifold, capsys):
    """log, exp and dist, compiled against the torch formulas, with the switch between
    them put back afterwards (the SPD speed benchmark's maps section is the spd2 row)."""
    from benchmarks import manifold_maps, spd_speed
    from sk_rtw.manifolds import _spd2, _sphere

    switches = _spd2.compiled, _sphere.compiled
    if manifold == "spd2":
        spd_speed.map_rows(1, n_series=2, length=5)
    else:
        manifold_maps.map_rows(manifold, 1, n_series=2, length=5)
    rows = [line for line in capsys.readouterr().out.splitlines() if "faster" in line]
    assert [row.split(":")[0].strip() for row in rows] == ["log", "exp", "dist"]
    assert (_spd2.compiled, _sphere.compiled) == switches


def test_manifold_classification_runs_one_fold(tmp_path):
    """R-LASA, one fold, a coarse step: every row scores, the page is written."""
    from benchmarks import manifold_classification
    from benchmarks.paper._data import data_dir

    try:
        data_dir()
    except FileNotFoundError:
        pytest.skip("the shared demonstration data is not next to the repository")
    page = tmp_path / "page.md"
    argv = ["--spaces", "quaternion", "spd", "--folds", "0", "--step", "50", "--method",
            "dba", "--rows", "prototype", "nearest-centroid", "forest", "1nn-dtw",
            "1nn-dtw-velocity", "--markdown", str(page), "--quiet"]  # fmt: skip
    assert manifold_classification.main(argv) == 0
    text = page.read_text()
    for row in ("prototype", "nearest-centroid", "forest", "1nn-dtw", "1nn-dtw-velocity"):
        assert f"| quaternion | {row}" in text and f"| spd | {row}" in text
    coords = manifold_classification.coordinates(np.ones((2, 3, 2, 2)), "spd")
    assert coords.shape == (2, 3, 3)  # (n, channels, T): the three distinct entries


def test_the_fingerprint_is_reproducible_and_compares(tmp_path, capsys, monkeypatch):
    """Two runs of the manifold part give the same bytes; an array one rounding step
    away is named."""
    from benchmarks import fingerprint

    first, second = tmp_path / "a.npz", tmp_path / "b.npz"
    kept = {k: fingerprint.MANIFOLDS[k] for k in ("euc1", "quat", "spd2")}
    monkeypatch.setattr(fingerprint, "MANIFOLDS", kept)
    for path in (first, second):
        assert fingerprint.main(["--out", str(path), "--quick", "--quiet"]) == 0
    assert fingerprint.main(["--compare", str(first), str(second)]) == 0
    arrays = dict(np.load(first))
    arrays["pw/quat/None/False"] = np.nextafter(arrays["pw/quat/None/False"], np.inf)
    np.savez(second, **arrays)
    assert fingerprint.main(["--compare", str(first), str(second)]) == 1
    assert "different: pw/quat/None/False" in capsys.readouterr().out


def test_the_forest_speed_benchmark_records_a_dataset_and_sums_a_half(monkeypatch, tmp_path):
    """benchmarks/forest_speed.py on a bundled dataset (fewer trees): a record with CPU
    seconds, 1-NN DTW's time a series, the pickle and memory figures, the two-thread fit;
    the summary divides the half's totals by 0.6x the published seconds; ``--elastic``
    measures the forest with the elastic splitter alone."""
    from benchmarks import forest_speed
    from sk_rtw import RTWProximityForest

    splitters = []

    def few_trees(**kwargs):
        splitters.append(kwargs.get("splitters"))
        return RTWProximityForest(**{"n_trees": 3, **kwargs})

    monkeypatch.setattr(forest_speed, "RTWProximityForest", few_trees)
    args = forest_speed.main.__globals__["halves_parser"]("t", out_required=False).parse_args(
        ["--data-dir", str(tmp_path), "--halves", "B"]
    )
    args.dtw_series, args.parallel, args.pf2_factor, args.elastic = 0, False, 0.6, True
    forest_speed.measure("ItalyPowerDemand", 0, None, args)
    assert [type(s).__name__ for s in splitters[-1]] == ["ElasticSplitter"]
    args.dtw_series, args.parallel, args.elastic = 4, True, False
    record = forest_speed.measure("ItalyPowerDemand", 0, None, args)
    assert splitters[-1] is None  # the default forest
    assert record["n_train"] == 67 and record["n_test"] == 1029
    assert 0.5 < record["accuracy"] <= 1.0
    for key in ("fit_cpu", "predict_cpu", "dtw_per_series", "fit_wall_1", "fit_wall_2"):
        assert record[key] > 0
    # both sizes measured (three trees on 67 short series keep fewer exemplars than the
    # training set holds: the pickle may be the smaller)
    assert record["pickle_bytes"] > 0 and record["train_bytes"] == 67 * 24 * 8
    published = tmp_path / "published_results.csv"
    published.write_text("dataset,half,PF2_split0,PF2_train_s,PF2_test_s\n"
                         "ItalyPowerDemand,B,0.9679,0.5,2.0\n")  # fmt: skip
    args.published = published
    lines = forest_speed.summary([record], args)
    row = next(line for line in lines if line.startswith("| B | 0 | 1 |"))
    cells = [cell.strip() for cell in row.strip("|").split("|")]
    assert cells[4] == "0.3" and cells[5] == f"{record['fit_cpu'] / 0.3:.2f}x"
    assert cells[7] == "1.2" and cells[8] == f"{record['predict_cpu'] / 1.2:.2f}x"
    assert any("n_jobs=2 against n_jobs=1" in line for line in lines)
