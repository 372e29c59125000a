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


# ------------------------------------------------------------ defects found by use (70)
def test_an_spd_mean_beyond_float64_is_a_clear_error_not_a_torch_trace():
    """1: diagonal points of eigenvalues 1e-150 and 1e150 among ordinary ones: the means
    between them leave float64; a ValueError says so (was torch's LinAlgError)."""
    from sk_rtw import align
    from sk_rtw.datasets import make_warped_signals

    X = make_warped_signals("spd", n_signals=2, length=8, random_state=0).signals
    X[0, 4] = np.diag([1e-150, 1.0])
    X[1, 4] = np.diag([1.0, 1e150])
    with pytest.raises(ValueError, match=r"Fréchet mean .* cannot be computed in float64"):
        align(X, manifold="spd", n_epochs=2)


def test_velocity_series_of_one_sample_are_series():
    """2: series of length 2 have velocity series of one sample: the means of that
    length are used, not refused, by fit, transform and predict."""
    from sk_rtw import RTWAverager, RTWNearestCentroid

    rng = np.random.default_rng(0)
    X, y = rng.standard_normal((8, 2)), np.arange(8) % 2
    clf = RTWNearestCentroid(method="dba", representation="velocity", n_centroids=1,
                             dtw_window=None).fit(X, y)  # fmt: skip
    assert clf.means_.shape == (2, 1, 1)
    velocity = X[:, 1] - X[:, 0]
    expected = np.abs(velocity[:, None] - clf.means_[None, :, 0, 0])
    np.testing.assert_allclose(clf.transform(X), expected, rtol=1e-12)
    assert clf.predict(X).tolist() == expected.argmin(1).tolist()
    averager = RTWAverager(method="dba", representation="velocity").fit(X, y)
    assert averager.transform(X).shape == (8, 2)


def test_spd_velocity_at_far_apart_scales_is_the_distance():
    """3: the velocity's norm is the affine-invariant distance at any scale (was NaN for
    1e170 I and 1e-170 I, 6.5e-7 off for 1e160 A and 1e-160 B)."""
    from sk_rtw import SPD, tangent_velocity

    eye = np.eye(2)
    v = tangent_velocity(np.array([[1e170 * eye, 1e-170 * eye]]), "spd")
    assert np.linalg.norm(v) == pytest.approx(2**0.5 * 340 * np.log(10), rel=1e-14)
    A, B = SPD(2).random_point(2, random_state=0)
    v = tangent_velocity(np.array([[1e160 * A, 1e-160 * B]]), "spd")
    eigenvalues = np.linalg.eigvals(np.linalg.solve(A, B)).real
    exact = np.sqrt(((np.log(eigenvalues) - 320 * np.log(10)) ** 2).sum())
    assert np.linalg.norm(v) == pytest.approx(exact, rel=1e-13)
    ordinary = SPD(3).random_point((2, 5), random_state=1)
    np.testing.assert_allclose(
        np.linalg.norm(tangent_velocity(ordinary, "spd"), axis=-1),
        SPD(3).dist(ordinary[:, :-1], ordinary[:, 1:]), rtol=1e-12,
    )  # fmt: skip


def test_a_non_finite_velocity_is_named():
    """4: a velocity that is not finite (here a step of R^1 that overflows) is refused,
    naming the series and the time, before it reaches any DTW; the forest, which
    divides the series by a power of two near their magnitude first, takes them."""
    from sk_rtw import RTWProximityForest, tangent_velocity

    X = np.ones((4, 6))
    X[2, 3] = 1.7e308
    X[2, 4] = -1.7e308
    with pytest.raises(ValueError, match=r"velocity of series 2 between time points 3 and 4"):
        tangent_velocity(X)
    forest = RTWProximityForest(n_trees=2, representation="velocity", random_state=0)
    assert forest.fit(X, [0, 1, 0, 1]).scale_ == 2.0**1023
    assert np.isfinite(forest.predict_proba(X)).all()


@pytest.mark.parametrize("scale", [2.0**600, 1e155, 1e200, 1e-200])
def test_the_forest_is_the_same_at_any_magnitude(scale):
    """5: squared costs of series at 1e200 overflowed (ties, silent changes); the forest
    divides the series by a power of two near their magnitude."""
    from sk_rtw import RTWProximityForest, dtw_distance

    rng = np.random.default_rng(0)
    t = np.linspace(0, 1, 30)
    X = np.stack([np.sin(2 * np.pi * t * (1 + (i % 2))) + 0.1 * rng.standard_normal(30)
                  for i in range(16)])  # fmt: skip
    y = np.arange(16) % 2
    base = RTWProximityForest(n_trees=6, random_state=0).fit(X[:10], y[:10])
    scaled = RTWProximityForest(n_trees=6, random_state=0).fit(X[:10] * scale, y[:10])
    assert scaled.scale_ != 1.0 and base.scale_ == 1.0
    np.testing.assert_array_equal(scaled.predict_proba(X[10:] * scale),
                                  base.predict_proba(X[10:]))  # fmt: skip
    assert not np.isfinite(dtw_distance(X[0] * 1e200, X[5] * 1e200, squared=True))


def _segments_manifold(segments):
    from dataclasses import dataclass

    from sk_rtw.manifolds import Euclidean

    @dataclass(frozen=True)
    class Segmented(Euclidean):
        @property
        def distance_segments(self):
            return segments

    return Segmented(3)


@pytest.mark.parametrize(
    "segments", [((0, 5, "euclidean"),), ((0, 2, "euclidean"),),
                 ((0, 1, "euclidean"), (2, 3, "euclidean"))],
)
def test_distance_segments_that_do_not_tile_a_point_are_refused(segments):
    """6, 7: segments reading past a point (26.64 against 20.13) or skipping a
    coordinate (14.72) are refused by DTW and by check_manifold."""
    from sk_rtw import check_manifold, dtw_distance, dtw_pairwise_distance

    M = _segments_manifold(segments)
    X = np.random.default_rng(0).standard_normal((3, 7, 3))
    with pytest.raises(ValueError, match="distance_segments"):
        dtw_distance(X[0], X[1], manifold=M)
    with pytest.raises(ValueError, match="distance_segments"):
        dtw_pairwise_distance(X, manifold=M)
    with pytest.raises(AssertionError, match="compiled distance"):
        check_manifold(M)


def test_check_manifold_compares_the_compiled_distance_with_dist():
    """7: segments of the right size but the wrong kind: the compiled distance is not
    the manifold's; check_manifold says so; the right ones pass."""
    from sk_rtw import check_manifold

    assert "the compiled distance (distance_segments) = dist" in check_manifold(
        _segments_manifold(((0, 3, "euclidean"),))
    )
    wrong = _segments_manifold(((0, 1, "euclidean"), (1, 3, "sphere")))
    with pytest.raises(AssertionError, match="compiled distance"):
        check_manifold(wrong)


def test_a_factory_that_returns_no_manifold_is_named(monkeypatch):
    """8: a ManifoldSpec whose factory returns an array registered, then failed with an
    AttributeError deep inside."""
    from sk_rtw.manifolds import ManifoldSpec, _registry, get_manifold, register_manifold

    monkeypatch.setattr(_registry, "_REGISTRY", dict(_registry._REGISTRY))
    register_manifold(ManifoldSpec("array-space", lambda d: np.zeros(3),
                                   lambda shape: 3 if shape == (3,) else None, "bad"))  # fmt: skip
    with pytest.raises(TypeError, match=r"factory .* returned a ndarray, not a Manifold"):
        get_manifold("array-space", point_shape=(3,))
