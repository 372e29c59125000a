"""
Aligning trajectories on the sphere S^2
=======================================

Five copies of one smooth path on the unit sphere, each played back with its own random
timing, are aligned by Riemannian Time Warping. Every resampled point and the mean stay
on the sphere: interpolation and averaging happen in tangent spaces.
"""

import matplotlib.pyplot as plt
import numpy as np

from sk_rtw import align, metrics
from sk_rtw.datasets import make_warped_signals
from sk_rtw.manifolds import Sphere

data = make_warped_signals("sphere", n_signals=5, length=80, dim=2, random_state=1)
result = align(data.signals, manifold="sphere", n_epochs=96, random_state=0)

print("points on the sphere:", np.allclose(np.linalg.norm(result.mean, axis=-1), 1.0))
before = metrics.alignment_quality(data.signals, Sphere(2).mean(data.signals), "sphere")
after = metrics.alignment_quality(result.aligned, result.mean, "sphere")
print(f"alignment quality: {before:.3f} (input vs. pointwise mean) -> {after:.3f} (RTW)")

# %%
# The same paths on the sphere. Timing does not change a path's shape, so the warping
# shows in where the series are *at the same moment*: the large markers are every
# series' sample at eight equally spaced moments (one colour per moment). In the input
# they are spread along the path; after alignment each moment is one tight cluster on
# the RTW mean (red).

moments = np.linspace(0.05, 0.95, 8)
colors = plt.cm.viridis(moments)
u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 60), np.linspace(0, np.pi, 30))
sphere = np.stack([np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v)])
centre = data.original.mean(0) / np.linalg.norm(data.original.mean(0))
low, high = data.original.min(0) - 0.05, data.original.max(0) + 0.05
fig = plt.figure(figsize=(11, 5.5))
for k, (title, series) in enumerate((("input", data.signals), ("aligned by RTW", result.aligned))):
    ax = fig.add_subplot(1, 2, k + 1, projection="3d")
    ax.plot_wireframe(*sphere, color="0.88", lw=0.3)
    for s in series:
        ax.plot(*s.T, color="0.55", lw=0.8)
        idx = np.round(moments * (len(s) - 1)).astype(int)
        ax.scatter(*s[idx].T, c=colors, s=45, depthshade=False, edgecolors="k", linewidths=0.3)
    if k == 1:
        ax.plot(*result.mean.T, color="crimson", lw=2, label="RTW mean")
        ax.legend(loc="upper left")
    ax.set_xlim(low[0], high[0])
    ax.set_ylim(low[1], high[1])
    ax.set_zlim(low[2], high[2])
    ax.set_box_aspect(high - low)
    ax.view_init(
        elev=np.degrees(np.arcsin(centre[2])), azim=np.degrees(np.arctan2(centre[1], centre[0]))
    )
    ax.set_title(title)
    ax.set_axis_off()
fig.tight_layout()

# %%
# Coordinates against normalised time, before and after.

fig, axes = plt.subplots(2, 3, figsize=(10, 5), sharex=True, sharey="col")
for row, series in enumerate((data.signals, result.aligned)):
    t = np.linspace(0, 1, series.shape[1])
    for c in range(3):
        axes[row, c].plot(t, series[..., c].T, lw=1, alpha=0.8)
        axes[row, c].set_title(f"{('input', 'aligned')[row]}: coordinate {c}")
    if row == 1:
        for c in range(3):
            axes[row, c].plot(t, result.mean[:, c], "k--", lw=2)
fig.tight_layout()
plt.show()
