"""Bad options and inputs found by use: each a clear error naming the problem."""

from __future__ import annotations

import json

import numpy as np
import pytest

from sk_rtw import dtw_nearest_distance


def _summaries(root):
    """Three classifiers' tsml accuracy summaries over four datasets and two resamples."""
    folder = root / "classification" / "accuracy"
    folder.mkdir(parents=True)
    rng = np.random.default_rng(0)
    for name in ("A", "B", "C"):
        rows = ["Resamples:,0,1"] + [
            f"D{k},{rng.uniform(0.5, 1):.3f},{rng.uniform(0.5, 1):.3f}" for k in range(4)
        ]
        (folder / f"{name}_accuracy.csv").write_text("\n".join(rows) + "\n")
    return root


@pytest.mark.parametrize("value", ["-1", "0"])
def test_critical_difference_refuses_a_resample_count_below_one(value, tmp_path, capsys):
    from benchmarks.ucr.critical_difference import main

    root = _summaries(tmp_path / "cdtest")
    with pytest.raises(SystemExit):
        main([str(root), "--resamples", value, "--out", str(tmp_path / "cd.png")])
    assert "--resamples" in capsys.readouterr().err
    assert main([str(root), "--resamples", "2", "--out", str(tmp_path / "cd.png")]) == 0


def test_critical_difference_names_a_missing_or_empty_folder(tmp_path):
    from benchmarks.ucr.critical_difference import main

    with pytest.raises(SystemExit, match="not an existing folder"):
        main([str(tmp_path / "no_such_folder")])
    (tmp_path / "empty").mkdir()
    with pytest.raises(SystemExit, match="no accuracy summary"):
        main([str(tmp_path / "empty")])


def test_seeds_refuses_a_half_the_results_do_not_hold(tmp_path, capsys):
    from benchmarks.ucr import seeds

    folder = tmp_path / "s0" / "datasets"
    folder.mkdir(parents=True)
    record = {"dataset": "GunPoint", "methods": {}, "config": {"seed": 0}, "error": None}
    (folder / "GunPoint.json").write_text(json.dumps(record))
    for spec in ("X=C9", "X=", "=A"):
        with pytest.raises(SystemExit):
            seeds.main([str(tmp_path / "s0"), "--combine", spec])
        assert "--combine" in capsys.readouterr().err


def test_nearest_search_names_a_max_distance_of_the_wrong_shape():
    X, Y = np.zeros((3, 20)), np.ones((4, 20))
    with pytest.raises(ValueError, match="max_distance must be a number or 3 numbers"):
        dtw_nearest_distance(X, Y, groups=[0, 1, 0, 1], max_distance=[1.0, 2.0])
    with pytest.raises(TypeError, match="max_distance must be numeric"):
        dtw_nearest_distance(X, Y, max_distance="far")
    got = dtw_nearest_distance(X, Y, groups=[0, 1, 0, 1], max_distance=[100.0, 1.0, 100.0])
    assert np.isinf(got[1]).all() and np.isfinite(got[0]).all()


def test_the_aeon_classifiers_refuse_zero_jobs_as_sk_rtw_does():
    pytest.importorskip("aeon")
    from sk_rtw.aeon import RTWClassifier, RTWProximityForestClassifier

    X = np.random.default_rng(0).standard_normal((6, 1, 12))
    y = np.array([0, 1] * 3)
    for cls in (RTWClassifier, RTWProximityForestClassifier):
        with pytest.raises(ValueError, match="n_jobs must not be 0"):
            cls(n_jobs=0).fit(X, y)


def test_prototype_classifier_says_how_many_folds_it_used():
    from sk_rtw import RTWPrototypeClassifier

    from .test_estimators import two_shape_classes

    X, y = two_shape_classes(n_per_class=4)
    with pytest.warns(UserWarning, match="4 folds are used"):
        proto = RTWPrototypeClassifier(method="dba", cv=10).fit(X, y)
    assert proto.n_folds_ == 4


def test_prototype_probabilities_say_why_the_readout_has_none():
    from sk_rtw import RTWPrototypeClassifier

    from .test_estimators import two_shape_classes

    X, y = two_shape_classes()
    proto = RTWPrototypeClassifier(method="dba", decision="readout", cv=2).fit(X, y)
    with pytest.raises(AttributeError) as raised:
        proto.predict_proba(X)
    # scikit-learn's available_if raises its own message from ours, shown above it
    assert "LogisticRegression" in str(raised.value.__cause__)
    assert not hasattr(proto, "predict_proba")
    nearest = RTWPrototypeClassifier(method="dba", decision="nearest", cv=2).fit(X, y)
    assert nearest.predict_proba(X).shape == (len(X), 2)


@pytest.mark.parametrize("k", [2, 3])
def test_spd_maps_refuse_a_tangent_vector_that_is_not_symmetric(k):
    """exp and norm used the symmetric part of a non-symmetric vector without a word;
    symmetric vectors (within 1e-6 of their largest entry) are still accepted."""
    from sk_rtw import SPD

    space, P = SPD(k), np.eye(k)
    V = np.zeros((k, k))
    V[0, 0], V[0, 1] = 0.1, 0.4
    for method in (space.exp, space.norm):
        with pytest.raises(ValueError, match=r"v is not a tangent vector of SPD.*not symmetric"):
            method(P, V)
    symmetric = V + V.T
    symmetric[0, 1] += 1e-9
    expected = space.exp(P, (symmetric + symmetric.T) / 2)
    np.testing.assert_allclose(space.exp(P, symmetric), expected, rtol=1e-8)


@pytest.mark.parametrize("pipeline", [False, True])
def test_prototype_readout_parameters_are_checked_before_any_work(pipeline, monkeypatch):
    """A readout refused by scikit-learn's own check was refused only after the centroids
    and the out-of-fold refits; now before the centroids are fitted (a fit that starts
    them would fail the test)."""
    from sklearn.linear_model import LogisticRegression
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    from sk_rtw import RTWNearestCentroid, RTWPrototypeClassifier

    def no_centroids(*args, **kwargs):
        raise AssertionError("the centroids were fitted before the readout was checked")

    monkeypatch.setattr(RTWNearestCentroid, "fit", no_centroids)
    readout = LogisticRegression(C=-1)
    if pipeline:
        readout = make_pipeline(StandardScaler(), readout)
    X = np.random.default_rng(0).standard_normal((8, 20))
    with pytest.raises(ValueError, match="readout: The 'C' parameter of LogisticRegression"):
        RTWPrototypeClassifier(readout=readout).fit(X, [0, 1] * 4)
