"""
Clustering quaternion demonstrations
====================================

Orientation demonstrations of three different motions, recorded at different speeds and
with the usual ``q`` / ``-q`` sign flips, are mixed together without labels.
:class:`sk_rtw.RTWKMeans` groups them by manifold DTW on S^3 (sign-invariant) and gives
one RTW mean per group: a smooth orientation trajectory that a robot could execute.
tslearn's DTW k-means works on Euclidean data only; here the centres stay unit
quaternions.
"""

import matplotlib.pyplot as plt
import numpy as np
from sklearn.metrics import adjusted_rand_score

from sk_rtw import RTW, RTWKMeans
from sk_rtw.datasets import make_warped_signals
from sk_rtw.manifolds import Quaternion

Q = Quaternion()
rng = np.random.default_rng(0)
demos, motion = [], []
for k in range(3):  # three motions, five demonstrations each, warped in time
    data = make_warped_signals(Q, n_signals=5, length=80, random_state=10 + k, amplitude=1.5)
    demos.append(data.signals)
    motion += [k] * 5
X = np.concatenate(demos)
X = X * np.where(rng.random(X.shape[:2]) < 0.3, -1.0, 1.0)[..., None]  # sign flips
order = rng.permutation(len(X))
X, motion = X[order], np.asarray(motion)[order]

kmeans = RTWKMeans(
    n_clusters=3, manifold="quaternion", method=RTW(n_epochs=64), n_init=2, random_state=0
)
kmeans.fit(X)
print("adjusted Rand index against the motions:", adjusted_rand_score(motion, kmeans.labels_))
print("inertia:", round(kmeans.inertia_, 3), "- iterations:", kmeans.n_iter_)
norms = np.linalg.norm(kmeans.cluster_centers_, axis=-1)
print("centre norms within", f"{np.abs(norms - 1).max():.1e}", "of 1")

# %%
# Each column is a cluster: its demonstrations (thin, shown in the hemisphere of the
# centre) and its RTW centre (thick), component by component.

fig, axes = plt.subplots(4, 3, figsize=(10, 7), sharex=True, sharey=True)
for c in range(3):
    centre = kmeans.cluster_centers_[c]
    t_centre = np.linspace(0, 1, len(centre))
    for x in X[kmeans.labels_ == c]:
        nearest = np.argmin(
            np.abs(np.linspace(0, 1, len(x))[:, None] - t_centre[None]), axis=1
        )  # the centre sample at the same relative time, for the sign choice
        x = x * np.sign((x * centre[nearest]).sum(-1, keepdims=True))
        for j in range(4):
            axes[j, c].plot(np.linspace(0, 1, len(x)), x[:, j], lw=0.8, alpha=0.6)
    for j, name in enumerate("wxyz"):
        axes[j, c].plot(t_centre, centre[:, j], "k", lw=2.5)
        axes[j, 0].set_ylabel(name)
    axes[0, c].set_title(f"cluster {c} ({np.sum(kmeans.labels_ == c)} demos)")
for ax in axes[-1]:
    ax.set_xlabel("relative time")
fig.tight_layout()
plt.show()
