"""Contract tests over every manifold, plus closed-form and scipy references."""

from __future__ import annotations

import math
import pickle
import warnings
from dataclasses import dataclass

import numpy as np
import pytest
import scipy.linalg
import torch
from sklearn.base import BaseEstimator, clone

from sk_rtw import RTWNearestCentroid, align
from sk_rtw.datasets import make_warped_signals
from sk_rtw.manifolds import (
    SPD,
    Euclidean,
    Manifold,
    ManifoldCheckError,
    Product,
    Quaternion,
    Sphere,
    available_manifolds,
    check_manifold,
    get_manifold,
)

from .conftest import MANIFOLDS, manifold_id

parametrize_manifolds = pytest.mark.parametrize("M", MANIFOLDS, ids=manifold_id)


def _tangent_within_radius(M: Manifold, p, fraction, seed):
    """Tangent vectors at ``p`` with norm ``fraction`` of the injectivity radius (or 1)."""
    v = M.random_tangent(p, 1.0, seed)
    lead = p.shape[: p.ndim - M.point_ndim]
    norms = np.asarray(M.norm(p, v)).reshape(*lead, *([1] * M.point_ndim))
    radius = M.injectivity_radius if math.isfinite(M.injectivity_radius) else 2.0
    return v / norms * fraction * radius


@parametrize_manifolds
def test_log_inverts_exp_within_injectivity_radius(M):
    p = M.random_point(20, 0)
    v = _tangent_within_radius(M, p, 0.9, 1)
    np.testing.assert_allclose(M.log(p, M.exp(p, v)), v, atol=1e-9)


@parametrize_manifolds
def test_exp_inverts_log(M):
    p = M.random_point(20, 2)
    x = M.exp(p, _tangent_within_radius(M, p, 0.8, 3))
    np.testing.assert_allclose(M.dist(M.exp(p, M.log(p, x)), x), 0.0, atol=1e-7)


@parametrize_manifolds
def test_exp_lands_on_manifold(M):
    p = M.random_point(30, 4)
    v = M.random_tangent(p, 3.0, 5)  # also far beyond the injectivity radius
    M.validate(M.exp(p, v), atol=1e-9)


@parametrize_manifolds
def test_dist_is_symmetric_and_satisfies_triangle_inequality(M):
    a, b, c = M.random_point(50, 6), M.random_point(50, 7), M.random_point(50, 8)
    np.testing.assert_allclose(M.dist(a, b), M.dist(b, a), atol=1e-10)
    assert np.all(M.dist(a, c) <= M.dist(a, b) + M.dist(b, c) + 1e-10)
    assert np.all(M.dist(a, b) >= 0)
    np.testing.assert_allclose(M.dist(a, a), 0.0, atol=1e-7)


@parametrize_manifolds
def test_dist_to_exp_equals_tangent_norm(M):
    p = M.random_point(20, 9)
    v = _tangent_within_radius(M, p, 0.7, 10)
    np.testing.assert_allclose(M.dist(p, M.exp(p, v)), M.norm(p, v), rtol=1e-9, atol=1e-12)


@parametrize_manifolds
def test_mean_of_identical_points_is_that_point(M):
    p = M.random_point((), 11)
    X = np.stack([p] * 5)
    np.testing.assert_allclose(M.dist(M.mean(X), p), 0.0, atol=1e-7)


@parametrize_manifolds
def test_mean_of_two_points_is_geodesic_midpoint(M):
    p = M.random_point((), 12)
    x = M.exp(p, _tangent_within_radius(M, p, 0.6, 13))
    midpoint = M.exp(p, 0.5 * M.log(p, x))
    np.testing.assert_allclose(M.dist(M.mean(np.stack([p, x])), midpoint), 0.0, atol=1e-7)


@parametrize_manifolds
def test_mean_is_a_critical_point_of_the_frechet_function(M):
    p = M.random_point((), 14)
    X = M.exp(p, M.random_tangent(np.stack([p] * 7), 0.3, 15))
    w = np.linspace(1.0, 2.0, 7)
    mean = M.mean(X, weights=w)
    gradient = (w.reshape(-1, *([1] * M.point_ndim)) * M.log(mean, X)).sum(0)
    assert float(M.norm(mean, gradient)) < 1e-8


@parametrize_manifolds
def test_pairwise_dist_matches_dist(M):
    A, B = M.random_point(4, 16), M.random_point(6, 17)
    expected = np.array([[M.dist(a, b) for b in B] for a in A])
    np.testing.assert_allclose(M.pairwise_dist(A, B), expected, atol=1e-10)


@parametrize_manifolds
def test_numpy_in_numpy_out_torch_in_torch_out(M):
    p, x = M.random_point(3, 18), M.random_point(3, 19)
    assert isinstance(M.log(p, x), np.ndarray)
    out = M.log(torch.from_numpy(p), torch.from_numpy(x))
    assert isinstance(out, torch.Tensor)
    np.testing.assert_allclose(out.numpy(), M.log(p, x))
    # points around one point, whose Fréchet mean converges (random points of a sphere
    # may sit around its cut locus)
    base = np.stack([p[0]] * 3)
    near = M.exp(base, M.random_tangent(base, 0.2, 19))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert isinstance(M.mean(torch.from_numpy(near)), torch.Tensor)


@parametrize_manifolds
def test_broadcasting_over_leading_axes(M):
    p = M.random_point((), 20)
    X = M.random_point((2, 3), 21)
    assert M.log(p, X).shape == X.shape
    assert M.dist(p, X).shape == (2, 3)
    assert M.mean(X, axis=1).shape == (2, *M.point_shape)


@parametrize_manifolds
def test_project_lands_on_manifold_and_fixes_points(M):
    p = M.random_point(5, 22)
    np.testing.assert_allclose(M.project(p), p, atol=1e-10)
    noisy = p + 0.01 * np.random.default_rng(0).standard_normal(p.shape)
    M.validate(M.project(noisy), atol=1e-9)


@parametrize_manifolds
def test_value_semantics(M):
    assert M == pickle.loads(pickle.dumps(M))
    assert hash(M) == hash(pickle.loads(pickle.dumps(M)))
    assert type(M).__name__ in repr(M)
    with pytest.raises(AttributeError):
        M.dim = 7  # frozen

    class Holder(BaseEstimator):
        def __init__(self, manifold="euclidean"):
            self.manifold = manifold

    assert clone(Holder(manifold=M)).manifold == M


# ----------------------------------------------------------------- gradients
def _t(x):
    return torch.tensor(np.asarray(x), dtype=torch.float64, requires_grad=True)


@parametrize_manifolds
def test_gradcheck_at_zero_tangent_and_coincident_points(M):
    p = M.random_point((), 23)
    zero = np.zeros(M.point_shape)
    assert torch.autograd.gradcheck(lambda v: M.exp(_t(p).detach(), v), (_t(zero),))
    assert torch.autograd.gradcheck(lambda x: M.log(_t(p).detach(), x), (_t(p),))
    assert torch.autograd.gradcheck(lambda q: M.log(q, _t(p).detach()), (_t(p),))
    assert torch.autograd.gradcheck(lambda x: M.squared_dist(_t(p).detach(), x), (_t(p),))
    # dist itself has a kink at zero; its gradient there must still be finite.
    x = _t(p)
    M.dist(_t(p).detach(), x).backward()
    assert torch.isfinite(x.grad).all()


@pytest.mark.parametrize("M", [m for m in MANIFOLDS if type(m) is Sphere], ids=manifold_id)
def test_gradcheck_near_antipodes(M):
    p = M.random_point((), 24)
    tangent = M.random_tangent(p, 1.0, 25)
    tangent /= np.linalg.norm(tangent)
    near_antipode = M.exp(p, (math.pi - 1e-4) * tangent)
    assert torch.autograd.gradcheck(lambda x: M.dist(_t(p).detach(), x), (_t(near_antipode),))
    assert torch.autograd.gradcheck(lambda x: M.log(_t(p).detach(), x), (_t(near_antipode),))
    v = _t((math.pi - 1e-4) * tangent)
    assert torch.autograd.gradcheck(lambda v: M.exp(_t(p).detach(), v), (v,))
    # exactly antipodal: values and gradients finite
    x = _t(-p)
    out = M.log(_t(p).detach(), x).sum() + M.dist(_t(p).detach(), x)
    out.backward()
    assert torch.isfinite(out) and torch.isfinite(x.grad).all()



@pytest.mark.parametrize("M", [m for m in MANIFOLDS if type(m) is Sphere], ids=manifold_id)
def test_sphere_log_of_a_batch_with_one_antipode_equals_the_pointwise_logs(M):
    """The antipodal branch runs only where a batch holds an antipode (on a CPU): a batch
    with one gives, entry for entry, the logs of the points taken one at a time (to
    rounding), and the
    antipode's log has length pi and is tangent."""
    p = M.random_point(6, 31)
    x = M.random_point(6, 32)
    x[2] = -p[2]
    batch = M.log(p, x)
    single = np.stack([M.log(p[i], x[i]) for i in range(6)])
    np.testing.assert_allclose(batch, single, rtol=0, atol=1e-14)  # batched rounding
    assert np.linalg.norm(batch[2]) == pytest.approx(math.pi)
    assert abs(batch[2] @ p[2]) < 1e-12

def test_spd_gradients_finite_at_repeated_eigenvalues():
    M = SPD(3)
    eye = _t(np.eye(3))
    loss = M.squared_dist(torch.eye(3, dtype=torch.float64), eye) + M.log(eye, eye).sum()
    loss.backward()
    assert torch.isfinite(eye.grad).all()
    p = M.random_point((), 26)
    x = _t(M.random_point((), 27))
    assert torch.autograd.gradcheck(lambda x: M.dist(_t(p).detach(), x), (x,))


# ------------------------------------------------------- independent references
def test_sphere_closed_forms():
    M = Sphere(2)
    p, x = M.random_point(10, 28), M.random_point(10, 29)
    np.testing.assert_allclose(M.dist(p, x), np.arccos(np.clip((p * x).sum(-1), -1, 1)), atol=1e-7)
    log = M.log(p, x)
    np.testing.assert_allclose((log * p).sum(-1), 0.0, atol=1e-12)  # tangent to the sphere
    # S^1: the distance is the absolute angle difference.
    angles = np.array([0.3, 2.9])
    pts = np.stack([np.cos(angles), np.sin(angles)], -1)
    assert Sphere(1).dist(pts[0], pts[1]) == pytest.approx(2.6)


def test_spd_against_scipy():
    M = SPD(3)
    P, X = M.random_point(5, 30), M.random_point(5, 31)
    for p, x in zip(P, X, strict=True):
        s = scipy.linalg.sqrtm(p).real
        si = np.linalg.inv(s)
        expected_log = s @ scipy.linalg.logm(si @ x @ si).real @ s
        np.testing.assert_allclose(M.log(p, x), expected_log, atol=1e-9)
        v = M.random_tangent(p, 0.5, 32)
        np.testing.assert_allclose(M.exp(p, v), s @ scipy.linalg.expm(si @ v @ si) @ s, atol=1e-9)
        eig = scipy.linalg.eigvalsh(x, p)  # generalised eigenvalues of (x, p)
        assert M.dist(p, x) == pytest.approx(np.sqrt((np.log(eig) ** 2).sum()), rel=1e-9)


def test_spd_mean_of_commuting_matrices_is_geometric_mean():
    M = SPD(2)
    X = np.stack([np.diag([1.0, 4.0]), np.diag([4.0, 9.0]), np.diag([16.0, 1.0])])
    expected = np.diag(np.exp(np.log(np.diagonal(X, axis1=1, axis2=2)).mean(0)))
    np.testing.assert_allclose(M.mean(X), expected, atol=1e-9)


def test_euclidean_mean_is_weighted_average(rng):
    X = rng.standard_normal((10, 3))
    w = rng.uniform(0.1, 1.0, 10)
    np.testing.assert_allclose(Euclidean(3).mean(X, weights=w), np.average(X, 0, w), atol=1e-12)


def test_quaternion_sign_invariance_and_hemisphere_alignment():
    Q = Quaternion()
    q = Q.random_point(8, 33)
    r = Q.random_point(8, 34)
    np.testing.assert_allclose(Q.dist(q, r), Q.dist(q, -r), atol=1e-12)
    np.testing.assert_allclose(Q.dist(q, -q), 0.0, atol=1e-7)
    assert np.all(Q.dist(q, r) <= math.pi / 2 + 1e-12)
    base = Q.random_point((), 35)
    samples = Q.exp(base, Q.random_tangent(np.stack([base] * 6), 0.1, 36))
    samples[::2] *= -1  # half of them in the other hemisphere
    mean = Q.mean(samples)
    assert Q.dist(mean, base) < 0.2
    np.testing.assert_allclose(np.linalg.norm(mean), 1.0)


def test_product_acts_factorwise():
    pose = get_manifold("pose")
    E, Q = Euclidean(3), Quaternion()
    a, b = pose.random_point(5, 37), pose.random_point(5, 38)
    np.testing.assert_allclose(pose.log(a, b)[:, :3], b[:, :3] - a[:, :3])
    np.testing.assert_allclose(pose.log(a, b)[:, 3:], Q.log(a[:, 3:], b[:, 3:]))
    expected = np.sqrt(E.dist(a[:, :3], b[:, :3]) ** 2 + Q.dist(a[:, 3:], b[:, 3:]) ** 2)
    np.testing.assert_allclose(pose.dist(a, b), expected)


# ------------------------------------------------------------- registry, errors
def test_registry_builds_and_infers_dimensions():
    assert set(available_manifolds()) == {"euclidean", "sphere", "quaternion", "spd", "pose"}
    assert get_manifold("sphere", dim=2) == Sphere(2)
    assert get_manifold("sphere", point_shape=(2,)) == Sphere(1)
    assert get_manifold("spd", point_shape=(4, 4)) == SPD(4)
    assert get_manifold("euclidean", point_shape=()) == Euclidean(1)
    assert get_manifold("quaternion") == Quaternion()
    assert get_manifold("pose") == Product((Euclidean(3), Quaternion()))
    assert get_manifold(SPD(2), point_shape=(2, 2)) == SPD(2)


@pytest.mark.parametrize(
    ("args", "kwargs", "match"),
    [
        (("torus",), {}, "unknown manifold"),
        (("sphere",), {}, "needs a dimension"),
        (("spd",), {"point_shape": (2, 3)}, "do not fit"),
        (("quaternion",), {"point_shape": (3,)}, "do not fit"),
        ((SPD(2),), {"point_shape": (3, 3)}, "do not fit"),
    ],
)
def test_registry_errors(args, kwargs, match):
    with pytest.raises(ValueError, match=match):
        get_manifold(*args, **kwargs)


@pytest.mark.parametrize("bad", [0, -1, 2.5, True])
def test_invalid_dimensions_rejected(bad):
    with pytest.raises(ValueError, match="dim"):
        Sphere(bad)


def test_validate_names_the_offending_point():
    X = np.tile(np.eye(2), (3, 4, 1, 1))
    X[2, 1] = [[1.0, 0.5], [0.4, 1.0]]
    with pytest.raises(ValueError, match=r"X\[2, 1\].*not symmetric"):
        SPD(2).validate(X)
    X[2, 1] = [[1.0, 2.0], [2.0, 1.0]]
    with pytest.raises(ValueError, match=r"X\[2, 1\].*not positive definite"):
        SPD(2).validate(X)
    S = np.tile([1.0, 0.0, 0.0], (2, 5, 1))
    S[1, 3] = [1.0, 1.0, 0.0]
    with pytest.raises(ValueError, match=r"X\[1, 3\].*norm"):
        Sphere(2).validate(S)
    S[1, 3] = [np.nan, 0.0, 0.0]
    with pytest.raises(ValueError, match=r"X\[1, 3\].*NaN"):
        Sphere(2).validate(S)
    with pytest.raises(ValueError, match="shape"):
        Sphere(2).validate(np.ones((3, 4)))


@pytest.mark.parametrize("squared_norm", [0.99e-12, 1.01e-12])
def test_sphere_series_expansions_match_closed_forms_at_the_switch(squared_norm):
    """Both sides of the Taylor switch-over agree with the closed forms to ~1 ulp."""
    M = Sphere(2)
    p = np.array([1.0, 0.0, 0.0])
    n = math.sqrt(squared_norm)
    v = np.array([0.0, n, 0.0])
    expected = np.array([math.cos(n), math.sin(n), 0.0])
    np.testing.assert_allclose(M.exp(p, v), expected, rtol=2e-15, atol=1e-25)
    x = expected
    np.testing.assert_allclose(
        M.log(p, x), [0.0, math.atan2(x[1], x[0]), 0.0], rtol=2e-15, atol=1e-25
    )


def test_continuous_removes_quaternion_sign_flips_and_nothing_else(rng):
    Q = Quaternion()
    series = np.stack([random_walk_on(Q, 30, seed) for seed in range(3)])
    flipped = series * np.where(rng.random((3, 30)) < 0.5, -1.0, 1.0)[..., None]
    fixed = Q.continuous(flipped)
    assert np.all((fixed[:, 1:] * fixed[:, :-1]).sum(-1) > 0)
    np.testing.assert_allclose(np.abs(fixed), np.abs(flipped))
    np.testing.assert_allclose(Q.dist(fixed, series), 0.0, atol=1e-7)
    pose = Product((Euclidean(3), Q))
    poses = np.concatenate([rng.standard_normal((3, 30, 3)), flipped], axis=-1)
    fixed_pose = pose.continuous(poses)
    np.testing.assert_array_equal(fixed_pose[..., :3], poses[..., :3])
    np.testing.assert_allclose(fixed_pose[..., 3:], fixed)
    X = rng.standard_normal((2, 10, 3))
    np.testing.assert_array_equal(Sphere(2).continuous(X), X)


def random_walk_on(manifold, length, seed, step=0.3):
    rng = np.random.default_rng(seed)
    points = [manifold.random_point((), rng.integers(1 << 30))]
    for _ in range(length - 1):
        v = manifold.random_tangent(points[-1], step, rng.integers(1 << 30))
        points.append(manifold.exp(points[-1], v))
    return np.stack(points)


@pytest.mark.parametrize("shape", [(7, 2), (3, 5, 3), (4, 1), (2, 3, 4, 4)])
def test_sum_last_and_inner_equal_torch_sums(shape):
    from sk_rtw._backend import inner, sum_last

    x = torch.randn(*shape, dtype=torch.float64, requires_grad=True)
    y = torch.randn(*shape, dtype=torch.float64)
    torch.testing.assert_close(sum_last(x), x.sum(-1))
    torch.testing.assert_close(sum_last(x, keepdim=True), x.sum(-1, keepdim=True))
    torch.testing.assert_close(sum_last(x, n_axes=2), x.sum((-2, -1)))
    torch.testing.assert_close(inner(x, y), (x * y).sum(-1))
    (grad,) = torch.autograd.grad(inner(x, y).sum(), x)
    torch.testing.assert_close(grad, y)


# ------------------------------------------------------------ check_manifold (public)
@parametrize_manifolds
def test_check_manifold_passes_every_space_of_the_package(M):
    passed = check_manifold(M)
    assert "log inverts exp" in passed and "finite gradients" in passed


@dataclass(frozen=True)
class PlaneRotations(Manifold):
    """SO(2) as 2x2 rotation matrices, from exp and log only (the rest derived)."""

    @property
    def point_shape(self):
        return (2, 2)

    @property
    def injectivity_radius(self):
        return math.pi

    def _exp(self, R, V):
        angle = (R.transpose(-1, -2) @ V)[..., 1, 0]
        c, s = torch.cos(angle), torch.sin(angle)
        return R @ torch.stack([torch.stack([c, -s], -1), torch.stack([s, c], -1)], -2)

    def _log(self, R, S):
        Q = R.transpose(-1, -2) @ S
        angle = torch.atan2(Q[..., 1, 0], Q[..., 0, 0])
        zero = torch.zeros_like(angle)
        skew = torch.stack([torch.stack([zero, -angle], -1), torch.stack([angle, zero], -1)], -2)
        return R @ skew


def rotations(angles):
    c, s = np.cos(angles), np.sin(angles)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def test_a_space_written_with_exp_and_log_only_is_checked_aligned_and_classified():
    SO2 = PlaneRotations()
    angles = np.random.default_rng(0).uniform(-2.5, 2.5, 8)
    passed = check_manifold(SO2, rotations(angles))
    assert len(passed) == 17  # every property; tangent coordinates and the compiled
    # distance skipped (not defined)
    # distance derived as the norm of the log: sqrt(2) times the angle between rotations
    assert SO2.dist(rotations(0.1), rotations(0.6)) == pytest.approx(np.sqrt(2) * 0.5)
    # the same demonstrations as unit vectors of S^1: the same geometry, the same mean
    data = make_warped_signals(Sphere(1), 3, 30, random_state=1)
    theta = np.arctan2(data.signals[..., 1], data.signals[..., 0])
    as_matrices = align(rotations(theta), manifold=SO2, n_epochs=0, random_state=0)
    as_circle = align(data.signals, manifold=Sphere(1), n_epochs=0, random_state=0)
    mean_angle = np.arctan2(as_matrices.mean[:, 1, 0], as_matrices.mean[:, 0, 0])
    circle_angle = np.arctan2(as_circle.mean[:, 1], as_circle.mean[:, 0])
    np.testing.assert_allclose(mean_angle, circle_angle, atol=1e-8)
    labels = [0, 0, 0, 1, 1, 1]
    X = np.concatenate([rotations(theta), rotations(theta[:, ::-1])])
    clf = RTWNearestCentroid(manifold=SO2, method="dba").fit(X, labels)
    assert clf.score(X, labels) == 1.0


def test_check_manifold_names_the_broken_property():
    class WrongLog(Sphere):
        def _log(self, p, x):
            return 1.1 * super()._log(p, x)

    class LeavesTheSphere(Sphere):
        def _exp(self, p, v):
            return p + v

    with pytest.raises(ManifoldCheckError, match=r"WrongLog.*'log inverts exp'"):
        check_manifold(WrongLog(2))
    with pytest.raises(ManifoldCheckError, match="'exp lands on the manifold'"):
        check_manifold(LeavesTheSphere(2))
    with pytest.raises(TypeError, match="pass points="):
        check_manifold(PlaneRotations())


@pytest.mark.parametrize("space", [Sphere(2), Quaternion(), SPD(2), SPD(3)], ids=repr)
def test_compiled_maps_off_runs_the_torch_formulas(space, monkeypatch):
    """The switch sends every map to the torch formulas (no kernel runs: each kernel
    module's entry points are made to fail), and both paths agree to rounding."""
    from sk_rtw.manifolds import _spd2_kernels, _sphere_kernels, _symmetric, compiled_maps

    X = np.asarray(make_warped_signals(space, 2, 30, random_state=0).signals)
    compiled = [np.asarray(f(X[0], X[1])) for f in (space.log, space.dist)]
    compiled.append(np.asarray(space.exp(X[0], compiled[0])))

    def fail(*args, **kwargs):
        raise AssertionError("a compiled kernel ran")

    for module in (_sphere_kernels, _spd2_kernels):
        for name in dir(module):
            if not name.startswith("__") and callable(getattr(module, name)):
                monkeypatch.setattr(module, name, fail)
    monkeypatch.setattr(_symmetric, "jacobi_eigh", fail)  # SPD(3..6) decompositions
    with compiled_maps(False):
        reference = [np.asarray(f(X[0], X[1])) for f in (space.log, space.dist)]
        reference.append(np.asarray(space.exp(X[0], reference[0])))
    for a, b in zip(compiled, reference, strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)
    with pytest.raises(AssertionError, match="compiled kernel"):  # switched back on
        space.log(X[0], X[1])


def test_compiled_maps_checks_its_argument():
    from sk_rtw.manifolds import compiled_maps

    with pytest.raises(TypeError, match="True or False"):
        with compiled_maps("no"):
            pass
