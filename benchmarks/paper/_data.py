"""Loaders for the manifold-valued demonstrations in ``../shared/data`` (read in place).

That data is partly copyleft (see its READMEs), so it is read from the shared folder
next to the repository and never copied into the package.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

ENV_DATA_DIR = "SK_RTW_DATA_DIR"


def data_dir(path: str | None = None) -> Path:
    """The shared data folder: ``path``, ``$SK_RTW_DATA_DIR`` or ``../shared/data``."""
    candidate = path or os.environ.get(ENV_DATA_DIR)
    if candidate is None:
        candidate = Path(__file__).resolve().parents[3] / "shared" / "data"
    candidate = Path(candidate)
    if not candidate.is_dir():
        raise FileNotFoundError(
            f"no demonstration data at {candidate}; pass --data-dir or set ${ENV_DATA_DIR}"
        )
    return candidate


def required(root: Path, *parts: str) -> Path:
    """The file ``root/parts``, or a ``FileNotFoundError`` naming it and its folder."""
    path = Path(root).joinpath(*parts)
    if not path.is_file():
        raise FileNotFoundError(
            f"no {path.name} in {path.parent} (the demonstrations are read from --data-dir "
            f"or ${ENV_DATA_DIR}: {Path(root)}; see the data README there)"
        )
    return path


def rcfs_letter(root: Path, letter: str = "G") -> np.ndarray:
    """2-D positions of the RCFS handwritten letter demonstrations, ``(n, 200, 2)``."""
    return np.load(required(root, "rcfs", "2Dletters", f"{letter}.npy"))[:, :, :2]


def rlasa_shapes(root: Path) -> list[str]:
    return sorted(p.name.removesuffix("_UQ.mat") for p in (root / "r_lasa" / "UQ").glob("*.mat"))


def rlasa_quaternions(root: Path, shape: str) -> np.ndarray:
    """R-LASA unit-quaternion demonstrations ``(4, 1000, 4)``, w first."""
    from scipy.io import loadmat

    demos = loadmat(required(root, "r_lasa", "UQ", f"{shape}_UQ.mat"))["demoUQ"][0]
    return np.stack([d["quat"][0, 0].T for d in demos])


def rlasa_spd(root: Path, shape: str) -> np.ndarray:
    """R-LASA SPD(2) demonstrations ``(4, 1000, 2, 2)``."""
    from scipy.io import loadmat

    demos = loadmat(required(root, "r_lasa", "SPD", f"{shape}_SPD.mat"))["demoSPD"][0]
    return np.stack([np.moveaxis(d["spd"][0, 0], -1, 0) for d in demos])


def quaternion_product(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Hamilton product of quaternions ``(..., 4)`` with w first."""
    pw, pv = p[..., :1], p[..., 1:]
    qw, qv = q[..., :1], q[..., 1:]
    w = pw * qw - (pv * qv).sum(-1, keepdims=True)
    v = pw * qv + qw * pv + np.cross(pv, qv)
    return np.concatenate([w, v], axis=-1)


def quaternion_exp(u: np.ndarray) -> np.ndarray:
    """``Exp(u) = (cos|u|, sin|u| u/|u|)`` for tangent vectors ``(..., 3)`` at the identity."""
    angle = np.linalg.norm(u, axis=-1, keepdims=True)
    scale = np.where(angle > 1e-12, np.sin(angle) / np.maximum(angle, 1e-300), 1.0)
    return np.concatenate([np.cos(angle), scale * u], axis=-1)


def letters_on_s3(positions: np.ndarray, scale: float) -> np.ndarray:
    """Map 2-D letters onto unit quaternions as PbDlib's S^3 demo does.

    ``u = scale * [x1, x2, x2]`` (the last coordinate repeated) is taken to S^3 by the
    exponential map at the identity and rotated to the base ``mu = (0, 1, 0, 0)``:
    ``q = mu ⊗ Exp(u)``.
    """
    u = scale * positions[..., [0, 1, 1]]
    base = np.array([0.0, 1.0, 0.0, 0.0])
    return quaternion_product(np.broadcast_to(base, (*u.shape[:-1], 4)), quaternion_exp(u))


def icsc_carrot_grating(root: Path) -> list[np.ndarray]:
    """The 12 carrot-grating poses ``(T_i, 7)``: x, y, z, qw, qx, qy, qz."""
    from scipy.io import loadmat

    m = loadmat(required(root, "icsc_hmm", "CarrotGrating_robot.mat"))
    return [np.asarray(m["Data"][0, i], dtype=float) for i in range(m["Data"].shape[1])]


def icsc_wiping(root: Path) -> list[np.ndarray]:
    """The 4 circular-wiping poses ``(T_i, 7)``: positions from ``H``, quaternions from ``X``.

    ``X`` holds author-shifted positions for demos 2-4 (see the data README), so the
    positions come from the homogeneous transforms ``H``; the quaternions (with their
    q -> -q flips) come from ``X``.
    """
    from scipy.io import loadmat

    m = loadmat(required(root, "icsc_hmm", "circular_wiping_dataset.mat"))
    poses = []
    for demo in m["proc_data"][0]:
        H, X = demo["H"][0, 0], demo["X"][0, 0]
        q = X[3:7].T
        q = q / np.linalg.norm(q, axis=1, keepdims=True)
        poses.append(np.concatenate([H[:3, 3, :].T, q], axis=1))
    return poses


def planar_arm_kinematics(q: np.ndarray, lengths: np.ndarray):
    """End-effector position and position Jacobian of a planar serial arm.

    ``q`` has shape ``(..., n)`` (relative joint angles); returns ``(..., 2)`` and
    ``(..., 2, n)``.
    """
    theta = np.cumsum(q, axis=-1)
    link = lengths * np.stack([np.cos(theta), np.sin(theta)], axis=-2)  # (..., 2, n)
    position = link.sum(-1)
    # d p / d q_i = sum_{j >= i} l_j (-sin theta_j, cos theta_j)
    rotated = np.stack([-link[..., 1, :], link[..., 0, :]], axis=-2)
    jacobian = np.flip(np.cumsum(np.flip(rotated, -1), -1), -1)
    return position, jacobian


def planar_arm_mass_matrix(q: np.ndarray, lengths: np.ndarray, masses: np.ndarray):
    """Joint-space mass matrix ``(..., n, n)`` of a planar arm of uniform rods.

    Rod k (mass m_k, length l_k, centre of mass at its middle, inertia m_k l_k^2 / 12)
    contributes ``m_k Jc_k^T Jc_k + I_k a_k^T a_k``, with ``Jc_k`` the Jacobian of its
    centre of mass and ``a_k`` the indicator of the joints before it.
    """
    n = q.shape[-1]
    theta = np.cumsum(q, axis=-1)
    direction = np.stack([-np.sin(theta), np.cos(theta)], axis=-2)  # (..., 2, n)
    lower = np.tril(np.ones((n, n)))  # lower[k, i] = 1 for i <= k
    strictly = lower - np.eye(n)
    # Jc[k, :, i] = sum_{j=i}^{k-1} l_j dir_j + l_k / 2 dir_k, for i <= k
    full = direction * lengths  # (..., 2, n)
    suffix = np.flip(np.cumsum(np.flip(full, -1), -1), -1)  # sum_{j >= i}
    # sum_{j=i}^{k-1} = suffix_i - suffix_k
    partial = suffix[..., :, None, :] - suffix[..., :, :, None]  # (..., 2, k, i)
    jc = partial * strictly + 0.5 * full[..., :, :, None] * lower  # (..., 2, k, i)
    inertia = masses * lengths**2 / 12.0
    translational = np.einsum("k,...dki,...dkj->...ij", masses, jc, jc)
    rotational = np.einsum("k,ki,kj->ij", inertia, lower, lower)
    return translational + rotational


def track_with_planar_arm(
    targets: np.ndarray, lengths: np.ndarray, iterations: int = 60, damping: float = 1e-2
) -> np.ndarray:
    """Joint angles ``(N, T, n)`` that make the arm follow targets ``(N, T, 2)``.

    Damped least-squares inverse kinematics, warm-started from the previous sample (the
    first sample from a fixed bent configuration), for all N trajectories at once.
    """
    n = len(lengths)
    q = np.tile(np.full(n, 2.0 / n), (targets.shape[0], 1))
    out = np.empty((*targets.shape[:2], n))
    eye = damping**2 * np.eye(2)
    for t in range(targets.shape[1]):
        for _ in range(iterations * (20 if t == 0 else 1)):
            position, J = planar_arm_kinematics(q, lengths)
            error = targets[:, t] - position
            step = np.linalg.solve(J @ np.swapaxes(J, -1, -2) + eye, error[..., None])
            q = q + (np.swapaxes(J, -1, -2) @ step)[..., 0]
        out[:, t] = q
    return out
