"""Tangent velocity on every manifold against closed forms and the invariances it must
have."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
import torch
from scipy.spatial.transform import Rotation

from sk_rtw import tangent_velocity
from sk_rtw.manifolds import SPD, Euclidean, Product, Quaternion, Sphere
from sk_rtw.representations import represent, velocity_collection
from sk_rtw.utils import check_series_collection

from .conftest import MANIFOLDS
from .test_dtw import random_walk


def quaternions(rotations: Rotation) -> np.ndarray:
    """scipy's (x, y, z, w) as this package's (w, x, y, z)."""
    return np.roll(rotations.as_quat(), 1, axis=-1)


def test_euclidean_velocity_is_numpy_diff(rng):
    X = rng.standard_normal((4, 30))
    np.testing.assert_array_equal(tangent_velocity(X), np.diff(X, axis=1))
    Y = rng.standard_normal((4, 30, 3))
    np.testing.assert_array_equal(tangent_velocity(Y), np.diff(Y, axis=1))
    ragged = [rng.standard_normal(n) for n in (5, 9, 2)]
    for got, series in zip(tangent_velocity(ragged), ragged, strict=True):
        np.testing.assert_array_equal(got, np.diff(series))


def test_a_constant_rate_rotation_has_a_constant_body_velocity():
    """q_t = q_0 exp(t w / 2): the body angular velocity is w at every step, whatever the
    start, and a sign flipped anywhere (q ~ -q) changes nothing."""
    omega = np.array([0.3, -0.2, 0.5])
    start = Rotation.from_rotvec([1.0, 2.0, -0.5])
    q = quaternions(start * Rotation.from_rotvec(np.arange(40)[:, None] * omega))
    q[::3] *= -1.0
    velocity = tangent_velocity(q[None], "quaternion")[0]
    np.testing.assert_allclose(velocity, np.tile(omega, (39, 1)), atol=1e-12)


def test_body_velocity_ignores_a_change_of_world_frame_and_matches_scipy(rng):
    q = random_walk(Quaternion(), 25, 3, step=0.4)
    world = quaternions(Rotation.from_rotvec(rng.standard_normal(3)))
    turned = Quaternion().project(_product(world, q))
    np.testing.assert_allclose(
        tangent_velocity(turned[None], "quaternion"), tangent_velocity(q[None], "quaternion"),
        atol=1e-12,
    )  # fmt: skip
    rotations = Rotation.from_quat(np.roll(q, -1, axis=-1))
    expected = (rotations[:-1].inv() * rotations[1:]).as_rotvec()
    np.testing.assert_allclose(tangent_velocity(q[None], "quaternion")[0], expected, atol=1e-12)


def _product(a, b):
    w1, v1 = a[..., :1], a[..., 1:]
    w2, v2 = b[..., :1], b[..., 1:]
    return np.concatenate(
        [w1 * w2 - (v1 * v2).sum(-1, keepdims=True), w1 * v2 + w2 * v1 + np.cross(v1, v2)], -1
    )


def test_circle_velocity_is_the_signed_angular_step():
    angles = np.cumsum(np.r_[0.3, 0.2, -0.4, 0.1, 3.0, -2.5])
    circle = np.stack([np.cos(angles), np.sin(angles)], -1)
    np.testing.assert_allclose(
        tangent_velocity(circle[None], "sphere")[0, :, 0], np.diff(angles), atol=1e-12
    )


def test_sphere_velocity_is_the_ambient_log_and_turns_with_the_sphere(rng):
    S2 = Sphere(2)
    x = random_walk(S2, 20, 5, step=0.3)
    velocity = tangent_velocity(x[None], S2)[0]
    np.testing.assert_allclose(velocity, S2.log(x[:-1], x[1:]), atol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(velocity, axis=1), S2.dist(x[:-1], x[1:]),
                               atol=1e-13)  # fmt: skip
    np.testing.assert_allclose((velocity * x[:-1]).sum(1), 0.0, atol=1e-13)
    R = Rotation.from_rotvec(rng.standard_normal(3)).as_matrix()
    np.testing.assert_allclose(tangent_velocity((x @ R.T)[None], S2)[0], velocity @ R.T,
                               atol=1e-13)  # fmt: skip


def _whitened_logarithm(p, x):
    """``logm(p^-1/2 x p^-1/2)`` by numpy's eigh and scipy's logm."""
    w, U = np.linalg.eigh(p)
    whitening = (U / np.sqrt(w)) @ U.T
    return scipy.linalg.logm(whitening @ x @ whitening).real


def _in_signed_eigenbasis(p, logarithm):
    """The logarithm in ``p``'s eigenbasis, column by column: ascending eigenvalues, each
    column's sign chosen so that the first row is non-negative (all but the last column
    for even k) and the basis a rotation."""
    k = len(p)
    U = np.linalg.eigh(p)[1]
    for j in range(1, k):
        if j == k - 1 and k % 2 == 0:
            if np.linalg.det(U) < 0:
                U[:, j] = -U[:, j]
        elif U[:, 0] @ logarithm @ U[:, j] < 0:
            U[:, j] = -U[:, j]
    return U.T @ logarithm @ U


@pytest.mark.parametrize("frame", ["eigen", "world"])
@pytest.mark.parametrize("k", [2, 3, 4])
def test_spd_velocity_is_the_whitened_logarithm_in_its_frame(k, frame):
    M = SPD(k, velocity_frame=frame)
    X = random_walk(M, 8, k, step=0.5)
    velocity = tangent_velocity(X[None], M)[0]
    assert velocity.shape == (7, k * (k + 1) // 2)
    rows, cols = np.triu_indices(k)
    weight = np.where(rows == cols, 1.0, np.sqrt(2.0))
    for t in range(7):
        logarithm = _whitened_logarithm(X[t], X[t + 1])
        if frame == "eigen":
            logarithm = _in_signed_eigenbasis(X[t], logarithm)
        np.testing.assert_allclose(velocity[t], logarithm[rows, cols] * weight, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(velocity, axis=1), M.dist(X[:-1], X[1:]),
                               rtol=1e-12)  # fmt: skip


def _rotation(rng, k):
    Q, _ = np.linalg.qr(rng.standard_normal((k, k)))
    Q[:, 0] *= np.sign(np.linalg.det(Q))
    return Q


def test_spd_world_velocity_under_congruence(rng):
    """Any congruence A X A^T keeps each step's norm (the affine-invariant distance); a
    scaling keeps the velocity itself; a rotation R turns its matrix to R L R^T."""
    M = SPD(3, velocity_frame="world")
    X = random_walk(M, 10, 7, step=0.5)
    velocity = tangent_velocity(X[None], M)[0]
    A = rng.standard_normal((3, 3)) + 3 * np.eye(3)
    moved = tangent_velocity((A @ X @ A.T)[None], M)[0]
    np.testing.assert_allclose(np.linalg.norm(moved, axis=1), np.linalg.norm(velocity, axis=1),
                               rtol=1e-10)  # fmt: skip
    np.testing.assert_allclose(tangent_velocity((7.5 * X)[None], M)[0], velocity, atol=1e-12)
    R = Rotation.from_rotvec(rng.standard_normal(3)).as_matrix()
    turned = tangent_velocity((R @ X @ R.T)[None], M)[0]
    expected = M.to_coordinates(
        np.eye(3), R @ M.from_coordinates(np.eye(3), velocity) @ R.T
    )  # coordinates at the identity are the plain isometric ones
    np.testing.assert_allclose(turned, expected, atol=1e-12)
    assert np.abs(turned - velocity).max() > 0.1  # the world frame turns


@pytest.mark.parametrize("k", [2, 3, 4, 5])
def test_spd_eigen_velocity_is_the_same_in_every_world_frame(k, rng):
    """A series congruent by a rotation (recorded in another world frame) has the same
    eigenframe velocity; a scaling too; a reflection, only for odd k (where -I turns no
    matrix), and for k = 2 it flips the sign of the off-diagonal coordinate."""
    M = SPD(k)
    X = random_walk(M, 12, 3 + k, step=0.5)
    velocity = tangent_velocity(X[None], M)[0]
    for _ in range(3):
        R = _rotation(rng, k)
        np.testing.assert_allclose(tangent_velocity((R @ X @ R.T)[None], M)[0], velocity,
                                   atol=1e-11)  # fmt: skip
    np.testing.assert_allclose(tangent_velocity((0.01 * X)[None], M)[0], velocity, atol=1e-12)
    mirror = np.diag(np.r_[-1.0, np.ones(k - 1)])
    mirrored = tangent_velocity((mirror @ X @ mirror)[None], M)[0]
    if k % 2:
        np.testing.assert_allclose(mirrored, velocity, atol=1e-11)
    elif k == 2:
        np.testing.assert_allclose(mirrored, velocity * [1.0, -1.0, 1.0], atol=1e-11)


def test_spd_eigen_velocity_at_a_diagonal_point_is_the_world_one():
    """At a diagonal point with ascending entries the eigenbasis is the identity up to
    the signs the rule fixes: both frames give the same diagonal, the same magnitudes."""
    p = np.diag([0.5, 1.0, 3.0])
    x = SPD(3).exp(p, np.array([[0.2, 0.1, -0.3], [0.1, -0.1, 0.05], [-0.3, 0.05, 0.4]]))
    eigen = SPD(3).velocity(p, x)
    world = SPD(3, velocity_frame="world").velocity(p, x)
    np.testing.assert_allclose(np.abs(eigen), np.abs(world), atol=1e-13)
    np.testing.assert_allclose(eigen[[0, 3, 5]], world[[0, 3, 5]], atol=1e-13)
    assert eigen[1] >= 0 and eigen[2] >= 0  # the first row made non-negative (k odd)


def test_products_concatenate_their_factors_velocities():
    pose = Product((Euclidean(3), Quaternion()))
    X = random_walk(pose, 12, 9)
    velocity = tangent_velocity(X[None], pose)[0]
    np.testing.assert_allclose(velocity[:, :3], np.diff(X[:, :3], axis=0), atol=1e-15)
    np.testing.assert_allclose(velocity[:, 3:], tangent_velocity(X[None, :, 3:], "quaternion")[0],
                               atol=1e-15)  # fmt: skip
    assert pose.velocity_dim == 6


@pytest.mark.parametrize("manifold", MANIFOLDS, ids=repr)
def test_every_manifold_gives_steps_of_its_stated_size_and_geodesic_length(manifold):
    X = [random_walk(manifold, n, n) for n in (9, 6)]
    velocity = tangent_velocity(X, manifold)
    assert [v.shape for v in velocity] == [(8, manifold.velocity_dim), (5, manifold.velocity_dim)]
    for v, x in zip(velocity, X, strict=True):
        np.testing.assert_allclose(np.linalg.norm(v, axis=1), _step_length(manifold, x),
                                   rtol=1e-10)  # fmt: skip


def _step_length(manifold, x):
    """The norm each step's velocity must have: the geodesic length, a quaternion's
    rotation angle (twice it), a product's factors combined."""
    if isinstance(manifold, Product):
        parts = np.split(x, np.cumsum([f.point_shape[0] for f in manifold.factors])[:-1], -1)
        lengths = [_step_length(f, part) for f, part in zip(manifold.factors, parts, strict=True)]
        return np.sqrt(np.sum(np.square(lengths), axis=0))
    scale = 2.0 if isinstance(manifold, Quaternion) else 1.0
    return scale * manifold.dist(x[:-1], x[1:])


def test_torch_input_gives_a_differentiable_velocity():
    p = torch.tensor(random_walk(Quaternion(), 2, 1), requires_grad=True)
    Quaternion().velocity(p[0], p[1]).sum().backward()
    assert torch.isfinite(p.grad).all()


def test_unequal_lengths_are_padded_by_the_last_velocity():
    collection = check_series_collection([np.arange(6.0), np.arange(3.0) * 2], "euclidean")
    velocity = velocity_collection(collection)
    assert velocity.lengths.tolist() == [5, 2]
    np.testing.assert_array_equal(velocity.data[1, :, 0], [2.0, 2.0, 2.0, 2.0, 2.0])
    assert represent(collection, "raw") is collection
    with pytest.raises(ValueError, match="representation"):
        represent(collection, "derivative")


def test_series_too_short_or_not_finite_are_refused():
    with pytest.raises(ValueError, match="time points"):
        tangent_velocity([np.arange(4.0), np.array([1.0])])
    with pytest.raises(ValueError, match="NaN"):
        tangent_velocity(np.array([[0.0, np.nan, 1.0]]))
    with pytest.raises(ValueError, match="not a point"):
        tangent_velocity(np.ones((2, 5, 3)), "sphere")


def test_spd_coordinates_keep_float64_under_a_float32_default_dtype():
    """sqrt(2) of the off-diagonal coordinates was rounded to float32 when torch's default
    dtype was float32 (the tests run with float64): 1.6e-8 relative error."""
    M = SPD(3)
    p = M.random_point(random_state=0)
    v = M.random_tangent(p, 1.0, random_state=1)
    before = torch.get_default_dtype()
    torch.set_default_dtype(torch.float32)
    try:
        coordinates = M.to_coordinates(p, v)
    finally:
        torch.set_default_dtype(before)
    np.testing.assert_allclose(np.linalg.norm(coordinates), M.norm(p, v), rtol=1e-14)
