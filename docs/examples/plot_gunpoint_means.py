"""
A class mean of GunPoint: RTW, DBA and the arithmetic mean
==========================================================

GunPoint (UCR archive, shipped with aeon) records the hand's x-position while an actor
draws a gun, points and puts it back. The demonstrations of one class share a shape but
not a timing, so the arithmetic mean smears the peaks. DTW barycenter averaging (DBA)
and RTW both average after alignment; RTW's mean is the mean of smoothly warped,
interpolated series, on a finer time grid.
"""

import matplotlib.pyplot as plt
import numpy as np
from aeon.datasets import load_classification

from sk_rtw import align, metrics
from sk_rtw.baselines import dba_average
from sk_rtw.utils import from_aeon

X, y = load_classification("GunPoint", split="train")  # aeon: (n, 1, T), channels first
series = from_aeon(X)[y == "1"]  # (n, T): univariate, time-major
print(series.shape)

rtw = align(series, output_length=300, n_epochs=64, random_state=0)
dba = dba_average(series)
arithmetic = series.mean(0)

# %%
# Barycenter loss: the summed, path-normalised DTW distance of the class's series to
# the mean (lower: the mean represents the class better).
for name, mean in (("arithmetic", arithmetic), ("DBA", dba.mean), ("RTW", rtw.mean)):
    print(f"{name:>10}: {metrics.barycenter_loss(series, mean):.3f}")

# %%
fig, axes = plt.subplots(1, 3, figsize=(13, 3.8), sharey=True)
t = np.linspace(0, 1, series.shape[1])
for ax, name, mean in zip(
    axes,
    ("arithmetic mean", "DBA mean", "RTW mean (aligned series behind)"),
    (arithmetic, dba.mean[:, 0], rtw.mean[:, 0]),
    strict=True,
):
    background = rtw.aligned[..., 0] if name.startswith("RTW") else series
    ax.plot(np.linspace(0, 1, background.shape[1]), background.T, color="0.8", lw=0.7)
    ax.plot(np.linspace(0, 1, len(mean)), mean, color="crimson", lw=2.2)
    ax.set_title(name)
    ax.set_xlabel("normalised time")
axes[0].set_ylabel("hand x-position")
fig.tight_layout()
plt.show()
