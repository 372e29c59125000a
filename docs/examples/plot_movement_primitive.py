"""
From demonstrations to a movement primitive
===========================================

Four demonstrations of a robot wiping three circles on a whiteboard (poses: position in
R^3 and orientation as a unit quaternion, R^3 x S^3; Figueroa and Billard's ICSC-HMM
data, read from ``../shared/data`` where it is available). They are aligned with RTW,
the aligned set is summarised by its mean and a time-varying covariance in the tangent
spaces at the mean (:func:`sk_rtw.aligned_statistics`), and a movement model,
Gaussian mixture regression (`gmr <https://github.com/AlexanderFabisch/gmr>`_), is
learned once from the raw demonstrations and once from the aligned ones.

GMR learns ``(phase, tangent coordinates at the mean)``: positions and orientations in
one Gaussian model, with no Euclidean shortcut for the quaternions, and the reproduction
is mapped back to poses by the exponential map at the mean.
"""

import os
import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from gmr import GMM

from sk_rtw import align, aligned_statistics, dtw_distance
from sk_rtw.datasets import make_warped_signals
from sk_rtw.manifolds import Euclidean, Product, Quaternion

POSE = Product((Euclidean(3), Quaternion()))


def wiping_demonstrations():
    """The four wiping demonstrations (every 5th sample), or warped synthetic poses."""
    here = Path(__file__).resolve() if "__file__" in globals() else Path.cwd() / "x"
    root = Path(os.environ.get("SK_RTW_DATA_DIR", here.parents[2].parent / "shared" / "data"))
    if (root / "icsc_hmm").is_dir():
        sys.path.insert(0, str(here.parents[2]))  # the loaders of the paper benchmarks
        from benchmarks.paper._data import icsc_wiping

        return [s[::5] for s in icsc_wiping(root)], "circular wiping (ICSC-HMM)"
    data = make_warped_signals(POSE, 4, 250, random_state=0, amplitude=0.5)
    return list(data.signals), "synthetic warped poses (the demonstration data is not here)"


demos, source = wiping_demonstrations()
print(f"{len(demos)} demonstrations of {source}, {min(map(len, demos))}-"
      f"{max(map(len, demos))} samples")  # fmt: skip

length = max(len(d) for d in demos)
result = align(demos, manifold=POSE, output_length=length, random_state=0)
stats = aligned_statistics(result, reg=1e-8)
print("tangent coordinates per time:", stats.dim, "; covariance", stats.covariance.shape)

# %%
# The mean and its spread
# -----------------------
# At every output time the covariance of the aligned poses around the mean, in the six
# tangent coordinates (three of position, three of rotation): the band is the 95 %
# interval of each coordinate, and ``stats.tube(0.95)`` gives the principal axes of the
# joint ellipsoid.

phase = np.linspace(0, 1, length)
std = np.sqrt(np.diagonal(stats.covariance, axis1=1, axis2=2))
fig, axes = plt.subplots(2, 3, figsize=(11, 5), sharex=True)
titles = ["x offset [m]", "y offset [m]", "z offset [m]",
          "rotation x [deg]", "rotation y [deg]", "rotation z [deg]"]  # fmt: skip
for i, ax in enumerate(axes.flat):
    scale = 1.0 if i < 3 else np.degrees(1.0)
    ax.plot(phase, stats.coordinates[:, :, i].T * scale, lw=0.8, alpha=0.7)
    ax.fill_between(phase, -1.96 * std[:, i] * scale, 1.96 * std[:, i] * scale,
                    color="0.8", label="95 % band")  # fmt: skip
    ax.set_title(titles[i])
axes[1, 0].set_xlabel("phase")
axes[0, 0].legend(loc="upper right", fontsize=8)
fig.suptitle("Aligned demonstrations in the tangent spaces at their mean")
fig.tight_layout()

# %%
# One model on raw and on aligned demonstrations
# ----------------------------------------------
# "Raw" resamples every demonstration to the same length (naive interpolation). The same
# GMR (8 components) is learned from both sets and reproduced over the phase.


def gmr_reproduction(prepared):
    prepared_stats = aligned_statistics(aligned=prepared, manifold=POSE, reg=1e-8)
    t = np.linspace(0, 1, prepared.shape[1])
    coordinates = prepared_stats.coordinates.reshape(-1, prepared_stats.dim)
    samples = np.column_stack([np.tile(t, len(prepared)), coordinates])
    gmm = GMM(n_components=8, random_state=0).from_samples(samples)
    coords = gmm.predict(np.array([0]), t[:, None])
    vectors = POSE.from_coordinates(prepared_stats.mean, coords)
    return POSE.continuous(POSE.exp(prepared_stats.mean, vectors))


grid = np.linspace(0, 1, length)
raw = np.stack([d[np.round(grid * (len(d) - 1)).astype(int)] for d in demos])
reproductions = {"raw demonstrations": gmr_reproduction(raw),
                 "RTW-aligned demonstrations": gmr_reproduction(result.aligned)}  # fmt: skip
for name, out in reproductions.items():
    error = np.mean([dtw_distance(out[:, :3], d[:, :3], normalize="path") for d in demos])
    print(f"GMR from {name}: mean position DTW to the demonstrations {error * 1000:.1f} mm")

fig, axes = plt.subplots(1, 2, figsize=(10, 4.5), sharex=True, sharey=True)
for ax, (name, out) in zip(axes, reproductions.items(), strict=True):
    for d in demos:
        ax.plot(d[:, 0], d[:, 1], color="0.75", lw=0.8)
    ax.scatter(out[:, 0], out[:, 1], c=phase, cmap="viridis", s=4)
    ax.set_title(f"GMR from {name}")
    ax.set_xlabel("x [m]")
    ax.set_aspect("equal")
axes[0].set_ylabel("y [m]")
fig.suptitle("Reproductions (colour: phase) over the demonstrations (grey), top view")
fig.tight_layout()
plt.show()
