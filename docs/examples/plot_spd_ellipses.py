"""
SPD(2) sequences drawn as ellipses
==================================

Stiffness or manipulability profiles are sequences of symmetric positive definite
matrices. Each 2 x 2 matrix is drawn as the ellipse ``{x : x^T A^{-1} x = 1}`` along a
time axis. Four differently timed copies of one profile are aligned by RTW under the
affine-invariant metric; the mean stays positive definite.
"""

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Ellipse

from sk_rtw import align, metrics
from sk_rtw.datasets import make_warped_signals
from sk_rtw.manifolds import SPD

M = SPD(2)
data = make_warped_signals(M, n_signals=4, length=40, random_state=2, amplitude=1.5)
result = align(data.signals, manifold=M, n_epochs=96, random_state=0)
M.validate(result.mean)  # raises if any mean matrix were not SPD
print(
    "alignment quality, input:", metrics.alignment_quality(data.signals, M.mean(data.signals), M)
)
print("alignment quality, RTW  :", metrics.alignment_quality(result.aligned, result.mean, M))


def draw(ax, matrices, y, color, step):
    for t in range(0, len(matrices), step):
        values, vectors = np.linalg.eigh(matrices[t])
        angle = np.degrees(np.arctan2(vectors[1, 1], vectors[0, 1]))
        width, height = 2 * np.sqrt(values[::-1]) * 0.35
        x = t / (len(matrices) - 1) * 30
        ax.add_patch(
            Ellipse((x, y), width, height, angle=angle, fc=color, ec="k", lw=0.4, alpha=0.7)
        )


# %%
# Rows: the four input series, then the four aligned series and the RTW mean (black).
# After alignment the ellipses of equal time line up in each column.

colors = plt.cm.tab10(np.arange(4))
fig, axes = plt.subplots(1, 2, figsize=(12, 5.5), sharey=True)
for n in range(4):
    draw(axes[0], data.signals[n], -3 * n, colors[n], step=2)
    draw(axes[1], result.aligned[n], -3 * n, colors[n], step=8)
draw(axes[1], result.mean, -12.5, "0.2", step=8)
for ax, title in zip(axes, ("input", "aligned, and the mean (bottom)"), strict=True):
    ax.set_xlim(-2, 32)
    ax.set_ylim(-15, 2)
    ax.set_aspect("equal")
    ax.set_title(title)
    ax.set_xlabel("normalised time x 30")
    ax.set_yticks([])
fig.tight_layout()

# %%
# The same alignment seen through one number per matrix, the log of its largest
# eigenvalue: the peaks of the four inputs fall at different times, after RTW they
# coincide with the mean's.

fig, axes = plt.subplots(1, 2, figsize=(11, 3.5), sharey=True)
for ax, series, title in ((axes[0], data.signals, "input"), (axes[1], result.aligned, "aligned")):
    t = np.linspace(0, 1, series.shape[1])
    for n in range(4):
        ax.plot(t, np.log(np.linalg.eigvalsh(series[n])[:, -1]), color=colors[n])
    ax.set_title(title)
    ax.set_xlabel("normalised time")
axes[1].plot(
    np.linspace(0, 1, len(result.mean)),
    np.log(np.linalg.eigvalsh(result.mean)[:, -1]),
    "k--",
    lw=2,
    label="RTW mean",
)
axes[1].legend()
axes[0].set_ylabel("log largest eigenvalue")
fig.tight_layout()
plt.show()
