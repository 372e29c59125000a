"""
A manifold of your own: rotation matrices SO(3)
===============================================

The package ships quaternions for orientations, but a robot controller may log rotation
matrices. A new space needs two torch functions, ``exp`` and ``log``, and its point
shape; distances, Fréchet means, DTW cost matrices and the alignment engine follow from
them. :func:`sk_rtw.check_manifold` checks the new space the way the package's own are
tested before anything is aligned on it.

Here SO(3) gets the bi-invariant metric in which the distance between two rotations is
the angle of the rotation between them: ``Exp_R(R W) = R expm(W)`` and
``Log_R(S) = R log(R^T S)`` for skew-symmetric ``W``, with Rodrigues' formula for the
logarithm. Quaternion demonstrations converted to matrices are aligned both ways: the
unit-quaternion distance is half that angle, the same geometry up to a factor, so the
two means agree.
"""

import math
from dataclasses import dataclass

import matplotlib.pyplot as plt
import numpy as np
import torch

from sk_rtw import Manifold, Quaternion, align, check_manifold
from sk_rtw.datasets import make_warped_signals


def hat(w):
    """Skew-symmetric matrices (..., 3, 3) of vectors (..., 3)."""
    zero = torch.zeros_like(w[..., 0])
    rows = [
        torch.stack([zero, -w[..., 2], w[..., 1]], -1),
        torch.stack([w[..., 2], zero, -w[..., 0]], -1),
        torch.stack([-w[..., 1], w[..., 0], zero], -1),
    ]
    return torch.stack(rows, -2)


def vee(W):
    """The vectors of skew-symmetric matrices (the inverse of ``hat``)."""
    return torch.stack([W[..., 2, 1], W[..., 0, 2], W[..., 1, 0]], -1)


@dataclass(frozen=True)
class Rotations(Manifold):
    """SO(3) as 3x3 rotation matrices; the distance is the rotation angle."""

    name = "so3"

    @property
    def point_shape(self):
        return (3, 3)

    @property
    def intrinsic_dim(self):
        return 3

    @property
    def injectivity_radius(self):
        return math.pi

    def _exp(self, R, V):
        W = R.transpose(-1, -2) @ V
        return R @ torch.linalg.matrix_exp(0.5 * (W - W.transpose(-1, -2)))

    def _log(self, R, S):
        Q = R.transpose(-1, -2) @ S
        axis = vee(Q - Q.transpose(-1, -2)) / 2  # sin(angle) times the unit axis
        sin_sq = (axis * axis).sum(-1, keepdim=True)
        small = sin_sq < 1e-12
        sin = torch.sqrt(torch.where(small, torch.ones_like(sin_sq), sin_sq))
        cos = (Q.diagonal(dim1=-2, dim2=-1).sum(-1, keepdim=True) - 1) / 2
        # angle / sin(angle), with its Taylor expansion where the rotation is tiny
        factor = torch.where(small, 1 + sin_sq / 6, torch.atan2(sin, cos) / sin)
        return R @ hat(factor * axis)

    def _norm(self, R, V):  # the rotation angle: |w| for V = R hat(w)
        w = vee(R.transpose(-1, -2) @ V)
        sq = (w * w).sum(-1)
        positive = sq > 0  # a zero gradient, not NaN, at the zero vector
        return torch.where(positive, torch.sqrt(torch.where(positive, sq, 1.0)), 0.0 * sq)

    def _to_coordinates(self, R, V):
        return vee(R.transpose(-1, -2) @ V)

    def _from_coordinates(self, R, c):
        return R @ hat(c)

    def _point_problems(self, x, atol):
        eye = torch.eye(3, dtype=x.dtype)
        orthogonal = (x.transpose(-1, -2) @ x - eye).abs().amax((-2, -1)) > atol
        return [
            (orthogonal, "it is not orthogonal (R^T R != I)"),
            (torch.linalg.det(x) < 0, "its determinant is -1 (a reflection)"),
        ]


def to_matrices(q):
    """Rotation matrices (..., 3, 3) of unit quaternions (w, x, y, z)."""
    w, x, y, z = np.moveaxis(q, -1, 0)
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        -2,
    )


SO3 = Rotations()
data = make_warped_signals(Quaternion(), n_signals=4, length=60, random_state=2, amplitude=1.0)
demos = to_matrices(data.signals)  # (4, 60, 3, 3)
print("checks passed:", ", ".join(check_manifold(SO3, demos[0, ::6])))

# %%
# The same demonstrations aligned as rotation matrices and as quaternions, with the same
# seed. The two means differ by a small fraction of a degree: the loss is measured in
# each space's own units (the angle, or half of it), so the monotonicity penalty weighs
# a little differently against it.

as_matrices = align(demos, manifold=SO3, n_epochs=32, random_state=0)
as_quaternions = align(data.signals, manifold=Quaternion(), n_epochs=32, random_state=0)
gap = SO3.dist(as_matrices.mean, to_matrices(as_quaternions.mean))
print(f"largest angle between the two means: {gap.max():.2e} rad")

fig, axes = plt.subplots(1, 2, figsize=(10, 3.6), sharey=True)
for ax, series, title in ((axes[0], demos, "demonstrations"),
                          (axes[1], as_matrices.aligned, "aligned, and the mean")):  # fmt: skip
    t = np.linspace(0, 1, series.shape[1])
    angle = SO3.dist(np.broadcast_to(np.eye(3), series.shape), series)
    ax.plot(t, angle.T, lw=1, alpha=0.8)
    ax.set_title(title)
    ax.set_xlabel("normalised time")
mean_angle = SO3.dist(np.broadcast_to(np.eye(3), as_matrices.mean.shape), as_matrices.mean)
axes[1].plot(np.linspace(0, 1, len(mean_angle)), mean_angle, "k--", lw=2)
axes[0].set_ylabel("rotation angle from the identity (rad)")
fig.tight_layout()
plt.show()
