"""
A geodesic shapelet where it matches, in any world frame
========================================================

:class:`sk_rtw.GeodesicShapeletClassifier` draws short, dilated pieces of training
series (shapelets) and describes every series by how close each comes to it, where,
and how often. Here the series are orientations (unit quaternions) of two families of
motions, and every demonstration is recorded in a world frame of its own: a random
rotation and sign per series, so that its coordinates look nothing alike. A normalised
shapelet compares shape, not position: each window is moved by the inverse of its own
mean orientation, which the world frame does not change.

The figure shows the shapelet the ridge readout weighs most, drawn from one series,
and the window of a series of each class where it matches best (its points marked
every ``dilation`` samples), with the distance profile underneath.
"""

import matplotlib.pyplot as plt
import numpy as np
from scipy.spatial.transform import Rotation

from sk_rtw import GeodesicShapeletClassifier, Quaternion
from sk_rtw.datasets import make_warped_signals
from sk_rtw.manifolds import quaternion_product
from sk_rtw.shapelets import gather_windows, profile
from sk_rtw.utils import check_series_collection

rng = np.random.default_rng(0)
first = make_warped_signals("quaternion", n_signals=12, length=80, random_state=1).signals
second = make_warped_signals("quaternion", n_signals=12, length=80, random_state=2).signals
X = np.concatenate([first, second])
y = np.repeat(["first", "second"], 12)
frames = Rotation.random(len(X), random_state=3).as_quat()[:, [3, 0, 1, 2]]
signs = rng.choice([-1.0, 1.0], size=len(X))
X = np.stack([s * quaternion_product(g, x) for s, g, x in zip(signs, frames, X, strict=True)])

train = np.arange(len(X)) % 3 != 0
clf = GeodesicShapeletClassifier("quaternion", n_shapelets=300, normalised_fraction=1.0,
                                 representation="raw", random_state=0)
clf.fit(X[train], y[train])
print(f"test accuracy {clf.score(X[~train], y[~train]):.3f} on series in their own frames")

# %%
# The shapelet whose smallest distance the readout weighs most, and its best match in
# one test series of each class.
weights = np.abs(clf.readout_[-1].coef_).reshape(-1, len(clf.transform_.shapelets_), 3)
best = int(np.argmax(weights[..., 0].max(0)))
shapelet = clf.transform_.shapelets_[best]
print(f"shapelet {best}: {shapelet.length} points every {shapelet.dilation} samples, "
      f"drawn from training series {shapelet.source[0]}")

tests = np.flatnonzero(~train)
shown = [tests[y[tests] == label][0] for label in ("first", "second")]
fig, axes = plt.subplots(2, 2, figsize=(12, 5.5), sharex=True,
                         gridspec_kw={"height_ratios": [2, 1]})
for column, index in enumerate(shown):
    collection = check_series_collection(X[index][None], Quaternion())
    windows = gather_windows(collection, shapelet.length, shapelet.dilation, True)
    distances = profile(shapelet, windows)
    start = int(np.argmin(distances))
    where = start + shapelet.dilation * np.arange(shapelet.length)
    ax = axes[0, column]
    for k, name in enumerate("wxyz"):
        ax.plot(X[index][:, k], lw=1.2, label=name)
        ax.plot(where, X[index][where, k], "o", color="k", ms=3)
    ax.axvspan(where[0], where[-1], color="0.85", zorder=0)
    ax.set_title(f"class {y[index]} (test series {index}): best match at {start}")
    ax.legend(ncols=4, fontsize=8)
    axes[1, column].plot(distances, color="C4")
    axes[1, column].axhline(shapelet.threshold, color="0.4", ls="--", lw=1)
    axes[1, column].set_ylabel("distance")
    axes[1, column].set_xlabel("window start")
fig.suptitle("A normalised quaternion shapelet and its best match in each class")
fig.tight_layout()
plt.show()
