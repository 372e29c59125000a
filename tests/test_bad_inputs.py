"""Bad and edge inputs across the public API: a clear error naming the problem, or the
correct answer. One case per item of the reliability catalogue, and more."""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
import pytest
import torch
from sklearn.exceptions import ConvergenceWarning, NotFittedError

from sk_rtw import (
    SPD,
    Euclidean,
    Product,
    Quaternion,
    RTWNearestCentroid,
    Sphere,
    align,
    dtw_distance,
    dtw_pairwise_distance,
    get_manifold,
    metrics,
)
from sk_rtw.baselines import dba_average, mmddtw_align
from sk_rtw.datasets import make_warped_signals
from sk_rtw.manifolds import Manifold, ManifoldCheckError, check_manifold
from sk_rtw.utils import from_aeon, from_tslearn, to_aeon

from .conftest import MANIFOLDS, quick

RNG = np.random.default_rng(0)
UNI = RNG.standard_normal((6, 20))  # 6 univariate series
LABELS = np.array([0, 0, 0, 1, 1, 1])
S2 = Sphere(2)
P2 = S2.random_point(5, random_state=1)
QUAT = make_warped_signals(Quaternion(), 3, 20, 0).signals
SPD_SERIES = make_warped_signals(SPD(2), 3, 20, 0).signals
FAST = {"method": quick(), "random_state": 0}


def fit_classifier(X, y=LABELS, **params):
    return RTWNearestCentroid(**{**FAST, **params}).fit(X, y)


def fitted():
    return fit_classifier(UNI)


# (id, call, exception type, words the message must contain)
ERRORS = [
    # ---- silently wrong before: now a clear error
    (
        "aeon channels-first multivariate",
        lambda: fit_classifier(np.zeros((6, 6, 100))),
        ValueError,
        "from_aeon",
    ),
    (
        "aeon channels-first: the aeon-native entry point named",
        lambda: fit_classifier(np.zeros((6, 1, 150))),
        ValueError,
        "sk_rtw.aeon.RTWClassifier",
    ),
    (
        "aeon channels-first univariate",
        lambda: align(np.zeros((6, 1, 150))),
        ValueError,
        "channels-first",
    ),
    (
        "quaternion with another dim",
        lambda: get_manifold("quaternion", dim=7),
        ValueError,
        "fixed dimension",
    ),
    ("pose with another dim", lambda: get_manifold("pose", dim=2), ValueError, "fixed dimension"),
    (
        "SPD dist of an indefinite matrix",
        lambda: SPD(2).dist(np.diag([1.0, -1.0]), np.eye(2)),
        ValueError,
        "positive definite",
    ),
    (
        "Euclidean dist with NaN",
        lambda: Euclidean(2).dist(np.array([np.nan, 0.0]), np.zeros(2)),
        ValueError,
        "NaN",
    ),
    (
        "Sphere mean with a NaN sample",
        lambda: S2.mean(np.vstack([P2, [np.nan, 0.0, 1.0]])),
        ValueError,
        "NaN",
    ),
    (
        "Sphere(2) dist on S^3 points",
        lambda: S2.dist(np.ones((3, 4)) / 2, np.ones((3, 4)) / 2),
        ValueError,
        "shape (3,)",
    ),
    (
        "None among string labels",
        lambda: fit_classifier(UNI, ["a", "a", None, "b", "b", "b"]),
        ValueError,
        "None",
    ),
    (
        "NaN among string labels",
        lambda: fit_classifier(UNI, np.array(["a", "a", np.nan, "b", "b", "b"], dtype=object)),
        ValueError,
        "nan",
    ),
    (
        "NaN float labels",
        lambda: fit_classifier(UNI, [0.0, 0.0, np.nan, 1.0, 1.0, 1.0]),
        ValueError,
        "NaN",
    ),
    # ---- unclear errors before: now in the library's words
    ("align given a generator", lambda: align(s for s in UNI), TypeError, "generator"),
    ("estimator given a generator", lambda: fit_classifier(iter(UNI)), TypeError, "iterator"),
    ("huge output_length", lambda: align(UNI, output_length=10**9), MemoryError, "GiB"),
    ("device cuda without CUDA", lambda: align(UNI, device="cuda:7"), ValueError, "CUDA"),
    ("device gpu", lambda: align(UNI, device="gpu"), ValueError, "torch device"),
    ("align random_state=-1", lambda: align(UNI, random_state=-1), ValueError, "random_state"),
    (
        "estimator random_state=-1",
        lambda: fit_classifier(UNI, random_state=-1),
        ValueError,
        "random_state",
    ),
    ("random_state as a float", lambda: align(UNI, random_state=1.5), TypeError, "random_state"),
    ("pairwise DTW n_jobs=0", lambda: dtw_pairwise_distance(UNI, n_jobs=0), ValueError, "n_jobs"),
    (
        "pairwise DTW n_jobs=1.5",
        lambda: dtw_pairwise_distance(UNI, n_jobs=1.5),
        TypeError,
        "n_jobs",
    ),
    ("estimator n_jobs=0", lambda: fit_classifier(UNI, n_jobs=0), ValueError, "n_jobs"),
    ("wrong number of weights in mean", lambda: S2.mean(P2, np.ones(3)), ValueError, "weights"),
    ("negative weights in mean", lambda: S2.mean(P2, -np.ones(5)), ValueError, "non-negative"),
    ("NaN weights in mean", lambda: S2.mean(P2, np.full(5, np.nan)), ValueError, "NaN"),
    ("mismatched shapes in exp", lambda: S2.exp(P2, np.zeros((4, 3))), ValueError, "broadcast"),
    (
        "tangent vector of the wrong size",
        lambda: S2.exp(P2, np.zeros((5, 2))),
        ValueError,
        "shape",
    ),
    (
        "scalar reference in a metric",
        lambda: metrics.barycenter_loss(UNI, 3.0),
        ValueError,
        "scalar",
    ),
    (
        "sktime nested DataFrame",
        lambda: align(pd.DataFrame({"dim_0": [pd.Series(np.arange(5.0)) for _ in range(3)]})),
        TypeError,
        "nested",
    ),
    # ---- validated in fit, not only at predict time
    ("dtw_window=2 at fit", lambda: fit_classifier(UNI, dtw_window=2), ValueError, "dtw_window"),
    (
        "mmddtw max_memory=-1",
        lambda: mmddtw_align(UNI[:2], max_memory=-1),
        ValueError,
        "max_memory",
    ),
    # ---- messages in time points and series
    ("one time point per series", lambda: align(np.zeros((3, 1))), ValueError, "time points"),
    ("no series", lambda: align(np.zeros((0, 5))), ValueError, "series"),
    # ---- more of our own
    ("empty list", lambda: align([]), ValueError, "empty"),
    ("string data", lambda: align(np.array([["a", "b"], ["c", "d"]])), ValueError, "numeric"),
    ("complex data", lambda: align(np.ones((2, 5)) * 1j), ValueError, "omplex"),
    (
        "infinite value",
        lambda: align(np.array([[0.0, np.inf, 1.0], [0.0, 1.0, 2.0]])),
        ValueError,
        "infinite",
    ),
    (
        "ragged point shapes",
        lambda: align([np.zeros((5, 2)), np.zeros((5, 3))]),
        ValueError,
        "shape",
    ),
    (
        "off-sphere data",
        lambda: align(np.ones((2, 5, 3)), manifold="sphere"),
        ValueError,
        "not a point",
    ),
    (
        "non-unit quaternions",
        lambda: align(2 * QUAT, manifold="quaternion"),
        ValueError,
        "not a point",
    ),
    (
        "non-symmetric SPD",
        lambda: align(SPD_SERIES + np.array([[0, 1.0], [0, 0]]), manifold="spd"),
        ValueError,
        "symmetric",
    ),
    ("unknown manifold", lambda: align(UNI, manifold="torus"), ValueError, "unknown manifold"),
    ("manifold of the wrong type", lambda: align(UNI, manifold=3), TypeError, "manifold"),
    ("unknown method", lambda: align(UNI, method="dtw"), ValueError, "method"),
    ("unknown preset", lambda: align(UNI, preset="fast"), ValueError, "preset"),
    ("unknown option", lambda: align(UNI, bogus=1), TypeError, "bogus"),
    ("n_epochs as a float", lambda: align(UNI, n_epochs=1.5), ValueError, "n_epochs"),
    ("NaN learning rate", lambda: align(UNI, learning_rate=np.nan), ValueError, "learning_rate"),
    ("negative sinc window", lambda: align(UNI, sinc_window=-1), ValueError, "sinc_window"),
    ("warp_knots=1", lambda: align(UNI, warp_knots=1), ValueError, "warp_knots"),
    ("unknown warp start", lambda: align(UNI, warp_start="medoid"), ValueError, "warp_start"),
    (
        "warp start of the wrong shape",
        lambda: align(UNI, warp_start=np.zeros((2, 5))),
        ValueError,
        "warp_start",
    ),
    ("unknown init", lambda: align(UNI, init="he"), ValueError, "init"),
    ("cuda_graph not a bool", lambda: align(UNI, cuda_graph="yes"), ValueError, "cuda_graph"),
    ("labels of the wrong length", lambda: fit_classifier(UNI, [0, 1]), ValueError, "labels"),
    (
        "one class for a classifier",
        lambda: fit_classifier(UNI, np.zeros(6)),
        ValueError,
        "2 classes",
    ),
    ("unknown estimator method", lambda: fit_classifier(UNI, method="knn"), ValueError, "method"),
    ("predict before fit", lambda: RTWNearestCentroid().predict(UNI), NotFittedError, "fit"),
    (
        "predict on another manifold's points",
        lambda: fitted().predict(np.zeros((2, 5, 3))),
        ValueError,
        "shape",
    ),
    ("DTW window 1.5", lambda: dtw_distance(UNI[0], UNI[1], window=1.5), ValueError, "window"),
    (
        "DTW window as a string",
        lambda: dtw_distance(UNI[0], UNI[1], window="10%"),
        TypeError,
        "window",
    ),
    (
        "DTW normalize unknown",
        lambda: dtw_distance(UNI[0], UNI[1], normalize="max"),
        ValueError,
        "normalize",
    ),
    (
        "DTW between different dimensions",
        lambda: dtw_distance(np.zeros((5, 3)), np.zeros((5, 2))),
        ValueError,
        "shape",
    ),
    ("Sphere(dim=0)", lambda: Sphere(0), ValueError, "dim"),
    ("SPD(dim=1.5)", lambda: SPD(1.5), ValueError, "dim"),
    ("an unknown SPD velocity frame", lambda: SPD(2, "body"), ValueError, "velocity_frame"),
    ("empty product", lambda: Product(()), ValueError, "Product"),
    (
        "zero signals to generate",
        lambda: make_warped_signals("sphere", 0, 20),
        ValueError,
        "n_signals",
    ),
    ("DBA with max_iter=0", lambda: dba_average(UNI, max_iter=0), ValueError, "max_iter"),
    ("aeon conversion of a 2-D array", lambda: from_aeon(np.zeros((3, 5))), ValueError, "3-D"),
    (
        "tslearn array with an empty series",
        lambda: from_tslearn(np.full((2, 4, 1), np.nan)),
        ValueError,
        "NaN everywhere",
    ),
]


@pytest.mark.parametrize(("call", "error", "words"), [c[1:] for c in ERRORS],
                         ids=[c[0] for c in ERRORS])  # fmt: skip
def test_bad_input_gives_a_clear_error(call, error, words):
    with pytest.raises(error) as info:
        call()
    assert words.lower() in str(info.value).lower(), str(info.value)


def test_catalogue_is_large():
    assert len(ERRORS) + len(CORRECT) >= 60


# ----------------------------------------------------------------- right answers
def dtw_scales_linearly(scale):
    x, y = np.array([0.0, 1.0, 2.0]), np.array([0.0, 0.0, 1.0, 3.0])
    for X, Y in ((x, y), (np.c_[x, -x], np.c_[y, -y])):
        expected = dtw_distance(X, Y)
        assert dtw_distance(scale * X, scale * Y) == pytest.approx(scale * expected, rel=1e-12)


def barycenter_loss_scales_linearly(scale):
    mean = UNI.mean(0)
    expected = metrics.barycenter_loss(UNI, mean)
    assert metrics.barycenter_loss(scale * UNI, scale * mean) == pytest.approx(
        scale * expected, rel=1e-12
    )


def align_at_scale(scale):
    data = make_warped_signals("euclidean", 4, 40, 1).signals
    factor = Euclidean(1).extreme_scale(scale * data)
    assert factor is not None
    options = {"n_epochs": 30, "n_iter_no_change": None, "random_state": 0}
    result = align(scale * data, **options)
    reference = align(scale * data / factor, **options)  # the same frame
    np.testing.assert_allclose(result.warps, reference.warps, atol=1e-12)
    np.testing.assert_allclose(result.mean, reference.mean * factor, rtol=1e-9)
    assert result.best_epoch > 0  # the warps were trained, not left at their start


def align_spd_at_scale(scale):
    data = make_warped_signals(SPD(2), 3, 25, 2).signals
    result = align(scale * data, manifold="spd", n_epochs=5, random_state=0)
    plain = align(data, manifold="spd", n_epochs=5, random_state=0)
    assert np.all(np.isfinite(result.mean))
    # the affine-invariant metric ignores the scale: the same warps, the mean scaled
    np.testing.assert_allclose(result.warps, plain.warps, atol=1e-3)
    np.testing.assert_allclose(result.mean / scale, plain.mean, rtol=1e-2)


def sphere_log_at_the_antipode():
    for M in (Sphere(1), Sphere(2), Sphere(5)):
        p = M.random_point(random_state=3)
        v = M.log(p, -p)
        assert np.linalg.norm(v) == pytest.approx(np.pi)
        assert abs(v @ p) < 1e-12  # tangent
        np.testing.assert_allclose(M.exp(p, v), -p, atol=1e-12)
        np.testing.assert_array_equal(v, M.log(p, -p))  # deterministic


def quaternion_log_at_minus_q_is_zero():
    q = Quaternion().random_point(random_state=4)
    np.testing.assert_allclose(Quaternion().log(q, -q), 0.0, atol=1e-12)


def predict_length_one_series():
    clf = fitted()
    assert clf.predict([np.array([0.3]), np.array([1.0, 2.0])]).shape == (2,)


def n_jobs_all_and_more_than_cores():
    expected = dtw_pairwise_distance(UNI)
    np.testing.assert_array_equal(dtw_pairwise_distance(UNI, n_jobs=-1), expected)
    np.testing.assert_array_equal(dtw_pairwise_distance(UNI, n_jobs=64), expected)


def mean_warns_when_not_converged():
    X = S2.random_point(7, random_state=5)
    with pytest.warns(ConvergenceWarning, match="did not converge"):
        S2.mean(X, max_iter=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        S2.mean(X, max_iter=1, tol=0.0)  # a fixed number of steps asked for: no warning


def aeon_round_trip():
    X = RNG.standard_normal((5, 3, 40))
    np.testing.assert_array_equal(to_aeon(from_aeon(X)), X)
    assert from_aeon(X).shape == (5, 40, 3)
    assert from_aeon(X[:, :1]).shape == (5, 40)
    unequal = [RNG.standard_normal((2, n)) for n in (10, 12)]
    assert [s.shape for s in from_aeon(unequal)] == [(10, 2), (12, 2)]


def tslearn_padding_becomes_unequal_lengths():
    X = np.full((2, 6, 1), np.nan)
    X[0, :6, 0] = np.arange(6.0)
    X[1, :4, 0] = np.arange(4.0)
    series = from_tslearn(X)
    assert [len(s) for s in series] == [6, 4]
    assert fit_classifier([*series, *series], [0, 1, 0, 1]).predict(series).shape == (2,)


def channels_first_is_fine_when_the_layout_is_stated():
    X = np.zeros((4, 3, 10))  # 3 time points of R^10, on purpose
    assert align(X, manifold=Euclidean(10), n_epochs=1).mean.shape == (12, 10)


CORRECT = [
    ("DTW at 1e200", lambda: dtw_scales_linearly(1e200)),
    ("DTW at 1e-300", lambda: dtw_scales_linearly(1e-300)),
    ("barycenter loss at 1e200", lambda: barycenter_loss_scales_linearly(1e200)),
    ("barycenter loss at 1e-300", lambda: barycenter_loss_scales_linearly(1e-300)),
    ("align at 1e200", lambda: align_at_scale(1e200)),
    ("align at 1e-300", lambda: align_at_scale(1e-300)),
    ("align SPD at 1e150", lambda: align_spd_at_scale(1e150)),
    ("align SPD at 1e-150", lambda: align_spd_at_scale(1e-150)),
    ("sphere log at the antipode", sphere_log_at_the_antipode),
    ("quaternion log at -q", quaternion_log_at_minus_q_is_zero),
    ("predict on length-1 series", predict_length_one_series),
    ("n_jobs=-1 and above the core count", n_jobs_all_and_more_than_cores),
    ("Fréchet mean at max_iter warns", mean_warns_when_not_converged),
    ("aeon round trip", aeon_round_trip),
    ("tslearn NaN padding", tslearn_padding_becomes_unequal_lengths),
    ("stated layout with T < d", channels_first_is_fine_when_the_layout_is_stated),
]


@pytest.mark.parametrize("check", [c[1] for c in CORRECT], ids=[c[0] for c in CORRECT])
def test_valid_input_gives_the_right_answer(check):
    check()


@pytest.mark.parametrize("manifold", MANIFOLDS, ids=repr)
def test_a_mean_of_zero_samples_says_so(manifold):
    import torch

    for empty in (np.zeros((0, *manifold.point_shape)), torch.zeros((0, *manifold.point_shape))):
        with pytest.raises(ValueError, match="mean of zero samples"):
            manifold.mean(empty)


def test_spd_beyond_float64_conditioning_is_rejected_with_its_eigenvalues():
    """A rotated SPD matrix with eigenvalues 1e-150 and 1e150 cannot be held in float64
    (its small eigenvalue is rounding noise): rejected, naming the range and the limit;
    the same eigenvalues on the diagonal are a valid extreme input."""
    theta = 0.3
    rotation = np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])
    rotated = np.stack([rotation @ np.diag([1e-150, 1e150]) @ rotation.T] * 8)
    with pytest.raises(ValueError, match=r"eigenvalues run from .* to 1e\+150.*1e\+13"):
        RTWNearestCentroid(manifold="spd", method=quick()).fit([rotated, rotated * 2], [0, 1])
    diagonal = np.stack([np.diag([1e-150 * (1 + t / 10), 1e150]) for t in range(8)])
    clf = RTWNearestCentroid(manifold="spd", method=quick()).fit([diagonal, diagonal * 3], [0, 1])
    assert clf.predict([diagonal * 3]).tolist() == [1] and np.isfinite(clf.means_).all()


# ------------------------------------------------------------ defects found by use (27)
def test_every_setting_is_checked_for_every_method_and_refused_where_it_does_not_belong():
    """1: a setting a method does not have is refused, naming where it belongs; one it
    has is checked, DBA's included, before any work."""
    from sk_rtw import DBA, RTW, RTWKMeans

    with pytest.raises(TypeError, match=r"mean_weights is a setting of the averaging method"):
        RTWNearestCentroid(method="dba", mean_weights="bad")
    with pytest.raises(TypeError, match=r"method=RTW\(n_epochs=\.\.\.\)"):
        RTWNearestCentroid(method="dba", n_epochs=-1)
    with pytest.raises(TypeError, match="n_epochs is a setting of RTW, TTW, NTW, not of DBA"):
        DBA(n_epochs=-1)
    with pytest.raises(TypeError, match="averaging settings are the method object's"):
        RTWKMeans(method="dba", averager_params={"mean_weights": "bad"})
    for estimator, words in (
        (RTWNearestCentroid(method=RTW(mean_weights="bad")), "mean_weights must be one of"),
        (RTWNearestCentroid(method=DBA(max_iter=0)), "max_iter must be an integer >= 1"),
        (RTWKMeans(2, method=DBA(tol=-1.0)), "tol must be a finite number >= 0"),
        (RTWNearestCentroid(method=RTW(n_epochs=-1)), "n_epochs must be an integer >= 0"),
    ):
        with pytest.raises(ValueError, match=words):
            estimator.fit(UNI, LABELS)


def _statistics(manifold, aligned, **kwargs):
    from sk_rtw import aligned_statistics

    return aligned_statistics(aligned=aligned, manifold=manifold, **kwargs)


def test_mahalanobis_refuses_nan_and_points_off_the_manifold():
    """2, 3: NaN named by series and time; points off the manifold named as elsewhere."""
    stats = _statistics(S2, S2.random_point((5, 10), random_state=0))
    bad = S2.random_point((2, 10), random_state=1)
    bad[1, 5, 0] = np.nan
    with pytest.raises(ValueError, match=r"aligned\[1, 5\] contains NaN"):
        stats.mahalanobis(bad)
    quat = _statistics(Quaternion(), QUAT[:, :8])
    with pytest.raises(ValueError, match="not a point of Quaternion"):
        quat.mahalanobis(2 * QUAT[:, :8])
    spd = _statistics(SPD(2), SPD_SERIES[:, :4])
    indefinite = np.broadcast_to(np.diag([1.0, -1.0]), (1, 4, 2, 2))
    with pytest.raises(ValueError, match="positive definite"):
        spd.mahalanobis(indefinite)
    np.testing.assert_array_less(-1e-12, stats.mahalanobis(S2.random_point((2, 10), 3)))


def test_samples_and_tubes_say_when_float64_cannot_hold_them():
    """4: SPD statistics with eigenvalues 1e-12 / 1e12: samples and tube boundary are not
    valid points in float64, and a warning says so (and names the first)."""
    M = SPD(2)
    spread = [np.diag([1e-12 * (1 + 0.3 * n), 1e12 / (1 + 0.3 * n)]) for n in range(4)]
    rotation = np.array([[np.cos(0.4), -np.sin(0.4)], [np.sin(0.4), np.cos(0.4)]])
    aligned = np.stack([np.stack([d] * 6) for d in spread])
    aligned[1] = rotation @ np.diag([1.0, 1.0]) @ rotation.T  # one series elsewhere
    stats = _statistics(M, aligned)
    with pytest.warns(RuntimeWarning, match="the samples are not valid points of SPD"):
        stats.sample(4, random_state=0)
    with pytest.warns(RuntimeWarning, match="the tube's boundary are not valid points"):
        stats.tube(0.9).boundary(M)


def test_a_tube_beyond_the_injectivity_radius_is_announced():
    """5: x and -x on the sphere: half-widths beyond pi, a boundary that wraps round."""
    p = S2.random_point(7, random_state=1)
    stats = _statistics(S2, np.stack([p, -p]))
    with pytest.warns(RuntimeWarning, match="injectivity radius 3.14 of Sphere"):
        tube = stats.tube(0.9)
    assert tube.half_widths.max() > np.pi
    with warnings.catch_warnings():  # a tight set stays inside: no warning
        warnings.simplefilter("error")
        _statistics(S2, S2.random_point((5, 7), random_state=2) * 0 + p).tube(0.9)


def test_a_singular_covariance_names_reg():
    p = S2.random_point(7, random_state=1)
    stats = _statistics(S2, np.stack([p, p, p]), reg=0.0)
    with pytest.raises(ValueError, match="reg=0: pass reg > 0"):
        stats.mahalanobis(p[None])
    assert np.isfinite(_statistics(S2, np.stack([p, p, p])).mahalanobis(p[None])).all()


def test_an_spd_alignment_of_widely_spread_diagonal_points_is_exact():
    """9: diagonal (valid) points whose geodesics overflowed the closed forms (this was a
    clear error naming the eigenvalue range); diagonal pairs now take the maps entry by
    entry: three copies of one series align by the identity, the mean on the manifold
    and through the series' first point."""
    D = np.diag([1e-150, 1e150])
    X = np.stack([np.stack([D if t % 2 else D[::-1, ::-1] for t in range(8)])] * 3)
    result = align(X, manifold="spd", n_epochs=2)
    SPD(2).validate(result.mean)
    np.testing.assert_allclose(result.warps, np.broadcast_to(result.warps[0], result.warps.shape))
    np.testing.assert_allclose(np.diag(result.mean[0]), [1e150, 1e-150], rtol=1e-6)


def test_an_object_array_of_unequal_series_reads_like_the_list():
    """12: np.array(list_of_series, dtype=object) is what many pipelines hand over."""
    series = [np.sin(np.linspace(0, 6, n)) for n in (30, 40)]
    series += [np.cos(np.linspace(0, 6, n)) for n in (25, 35)]
    packed = np.empty(len(series), dtype=object)
    packed[:] = series
    from_list = RTWNearestCentroid(method="dba").fit(series, [0, 0, 1, 1])
    from_array = RTWNearestCentroid(method="dba").fit(packed, [0, 0, 1, 1])
    for a, b in zip(from_list.means_, from_array.means_, strict=True):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(from_array.predict(packed), [0, 0, 1, 1])


# ---------------------------------------------------------- defects found by use (31)
class _Line(Manifold):
    """R^d written by hand: the base of the broken spaces below."""

    def __init__(self, dim: int = 1):
        self.dim = dim

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.dim})"

    def __eq__(self, other) -> bool:
        return type(self) is type(other) and self.dim == other.dim

    def __hash__(self) -> int:
        return hash((type(self), self.dim))

    @property
    def point_shape(self):
        return (self.dim,)

    def _exp(self, p, v):
        return p + v

    def _log(self, p, x):
        return x - p


class DoubleStep(_Line):
    """exp(p, v) = p + 2 v does not invert log(p, x) = x - p."""

    def _exp(self, p, v):
        return p + 2 * v


class ShortSighted(_Line):
    """log is NaN beyond a distance of 0.5."""

    def _log(self, p, x):
        v = x - p
        return torch.where(v.abs() > 0.5, torch.full_like(v, float("nan")), v)


class ShapeLying(_Line):
    """Declares points of shape (3,), returns 2-vectors."""

    @property
    def point_shape(self):
        return (3,)

    def _exp(self, p, v):
        return (p + v)[..., :2]

    def _log(self, p, x):
        return (x - p)[..., :2]


def smooth_series(n=4, length=25, offset=0.0, seed=0):
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 1, length)
    return np.stack([np.sin(2 * np.pi * t ** rng.uniform(0.8, 1.2)) * 0.2 + offset
                     for _ in range(n)])[..., None]  # fmt: skip


def test_a_manifold_whose_exp_does_not_invert_log_is_refused_before_any_work():
    X = smooth_series()
    for call in (
        lambda: align(X, manifold=DoubleStep(), n_epochs=2),
        lambda: RTWNearestCentroid(manifold=DoubleStep(), method="dba").fit(X, [0, 0, 1, 1]),
        lambda: dba_average(X, manifold=DoubleStep()),
    ):
        with pytest.raises(ValueError, match=r"exp must invert log.*check_manifold"):
            call()
    # the package's own spaces are not re-checked; a correct space of one's own passes
    result = align(X, manifold=_Line(), n_epochs=2, random_state=0)
    assert np.isfinite(result.mean).all()


def test_non_finite_point_costs_are_an_error_naming_the_manifold_and_the_samples():
    x = np.linspace(0, 2, 10)[:, None]  # neighbouring samples 0.22 apart: log is fine there
    with pytest.raises(ValueError, match=r"ShortSighted\(1\) gives the distance nan between "
                       r"x at time 0 and y at time 0"):  # fmt: skip
        dtw_distance(x, x[::-1], manifold=ShortSighted())
    with pytest.raises(ValueError, match=r"between X\[0\] at time 0 and Y\[0\] at time 3"):
        dtw_pairwise_distance([x], [x, x[::-1]], manifold=ShortSighted())
    # aligning or averaging such series says the same, not "the window is too narrow"
    X = np.stack([x[:, 0], x[::-1, 0], x[:, 0]])[..., None]
    for call in (
        lambda: align(X, manifold=ShortSighted(), n_epochs=2),
        lambda: RTWNearestCentroid(manifold=ShortSighted(), method="dba").fit(X, [0, 0, 1]),
    ):
        with pytest.raises(ValueError, match="non-finite point costs") as info:
            call()
        assert "window" not in str(info.value).split("DTW needs")[0]


def test_a_manifold_that_lies_about_its_point_shape_is_named():
    X = np.zeros((3, 10, 3)) + np.linspace(0, 1, 10)[:, None]
    with pytest.raises(ValueError, match=r"shape \(2,\) for points of shape \(3,\).*point_shape"):
        align(X, manifold=ShapeLying(), n_epochs=2)
    with pytest.raises(ManifoldCheckError, match=r"exp and log keep the point shape.*point_shape"):
        check_manifold(ShapeLying(), X[0, :4])


def test_check_manifold_names_log_when_it_fails_during_set_up():
    points = np.linspace(0, 3, 5)[:, None]  # far apart: log is NaN between them
    with pytest.raises(ManifoldCheckError, match=r"tangent vectors at the points.*log"):
        check_manifold(ShortSighted(), points)


def test_read_only_arrays_reach_torch_without_a_warning():
    p = Sphere(2).random_point(4, random_state=0)
    p.flags.writeable = False
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        np.testing.assert_allclose(Sphere(2).log(p, p), 0.0, atol=1e-12)


def test_a_network_too_large_for_memory_names_hidden_size_before_any_allocation():
    with pytest.raises(MemoryError, match=r"hidden_size=100000.*lower hidden_size"):
        align(UNI[:3], hidden_size=10**5, n_epochs=1)


def test_wide_sinc_windows_and_smoothing_are_bounded_by_the_series(monkeypatch):
    """A sinc window wider than the series reads no more data; a smoothing kernel never
    exceeds the series: both finish at once (were 129 s and a 4.5 GiB allocation)."""
    import time

    X = UNI[:3]  # 20 samples
    start = time.perf_counter()
    wide = align(X, sinc_window=10**6, n_epochs=3, random_state=0)
    assert wide.config.sinc_window == 20  # what ran
    capped = align(X, sinc_window=20, n_epochs=3, random_state=0)
    np.testing.assert_array_equal(wide.mean, capped.mean)
    smooth = align(X, smoothing=1e8, n_epochs=3, random_state=0)
    assert np.isfinite(smooth.mean).all()
    assert time.perf_counter() - start < 20


def test_refinement_stops_when_the_cost_stops_falling():
    import time

    X = UNI[:4]
    start = time.perf_counter()
    many = align(X, refine_steps=10**4, n_epochs=2, random_state=0)
    assert time.perf_counter() - start < 20
    few = align(X, refine_steps=200, n_epochs=2, random_state=0)
    np.testing.assert_array_equal(many.mean, few.mean)  # both stopped at the same step


def test_a_method_given_by_name_is_searchable_through_its_settings():
    from sklearn.model_selection import GridSearchCV

    search = GridSearchCV(
        RTWNearestCentroid(n_centroids=1, dtw_window=None), {"method__n_epochs": [1, 2]}, cv=2
    ).fit(UNI, LABELS)
    assert search.best_estimator_.method.get_params()["n_epochs"] in (1, 2)
    assert RTWNearestCentroid(method="ttw").set_params(method__n_epochs=3).method.name == "ttw"


def test_set_params_says_where_a_setting_belongs():
    with pytest.raises(ValueError, match=r"n_epochs.*method=RTW\(n_epochs=\.\.\.\)"):
        RTWNearestCentroid().set_params(n_epochs=5)
    from sk_rtw import RTWKMeans

    with pytest.raises(ValueError, match="method__hidden_size"):
        RTWKMeans().set_params(hidden_size=5)


def test_a_long_format_table_is_explained():
    table = pd.DataFrame({"series": np.repeat(np.arange(6), 20), "time": np.tile(np.arange(20), 6),
                          "value": RNG.standard_normal(120)})  # fmt: skip
    with pytest.raises(ValueError, match=r"120 series but y has 6 labels.*long-format.*pivot"):
        RTWNearestCentroid(method="dba").fit(table, LABELS)


def test_align_points_dba_to_its_own_function():
    with pytest.raises(ValueError, match=r"dba_average"):
        align(UNI[:3], method="dba")


def test_an_early_stop_is_announced_with_the_epoch_kept(capsys):
    result = align(QUAT, manifold="quaternion", verbose=True, random_state=0,
                   n_iter_no_change=3, n_epochs=200)  # fmt: skip
    err = capsys.readouterr().err
    assert result.n_iter < 200
    assert f"stopped early after {result.n_iter} of 200 epochs: 3 epochs without" in err
    assert f"keeping the warps of epoch {result.best_epoch} (best_epoch" in err


def test_every_field_of_a_refined_result_describes_the_refined_mean():
    from sk_rtw.align._loss import window_weights

    X = np.random.default_rng(0).standard_normal((4, 30)).cumsum(1)
    plain = align(X, n_epochs=5, random_state=0)
    refined = align(X, n_epochs=5, refine_steps=2, random_state=0)
    assert not np.allclose(refined.mean, plain.mean)
    n, z = refined.warps.shape
    weights = window_weights(z, refined.config.loss_window, refined.config.loss_step).numpy()
    distances = Euclidean(1).dist(refined.aligned, refined.mean[None])
    assert refined.cost == pytest.approx(float((distances @ weights).sum()) / (n * z))
    assert refined.cost < plain.cost  # the loss at the refined mean, not the stale one
    assert np.all(np.diff(refined.warps, axis=1) >= 0)
    np.testing.assert_allclose(refined.warps[:, [0, -1]], [[0.0, 1.0]] * n)
    # the aligned series sit around the refined mean (before: those of the unrefined one)
    spread = np.abs((refined.aligned - refined.mean).mean(0)).mean()
    stale = np.abs((plain.aligned - refined.mean).mean(0)).mean()
    assert spread < stale / 2


def test_help_of_align_states_the_default_output_length():
    from sk_rtw.align import PRESETS

    text = " ".join(align.__doc__.split())
    for name in ("alignment", "paper"):
        assert PRESETS[name].output_length.formula in text


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_missing_or_infinite_labels_are_refused_without_a_library_warning(bad):
    y = LABELS.astype(float)
    y[2] = bad
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ValueError, match=r"y\[2\] is (nan|inf)"):
            RTWNearestCentroid(method="dba").fit(UNI, y)
