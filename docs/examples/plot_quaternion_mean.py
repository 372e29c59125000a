"""
Quaternion demonstrations and their mean
========================================

Orientation demonstrations are unit quaternions ``(w, x, y, z)``, and ``q`` and ``-q``
are the same rotation. Recorded data often flips between the two; here half of the
samples of every demonstration are flipped on purpose. The ``Quaternion`` manifold uses
the sign-invariant distance and picks the nearest representative in ``log`` and
``mean``, so RTW aligns and averages the demonstrations as if nothing had happened.
"""

import matplotlib.pyplot as plt
import numpy as np

from sk_rtw import align, metrics
from sk_rtw.datasets import make_warped_signals
from sk_rtw.manifolds import Quaternion

Q = Quaternion()
rng = np.random.default_rng(0)
data = make_warped_signals(Q, n_signals=4, length=100, random_state=4, amplitude=1.2)
flips = np.where(rng.random(data.signals.shape[:2]) < 0.5, -1.0, 1.0)[..., None]
demos = data.signals * flips

result = align(demos, manifold=Q, n_epochs=128, random_state=0)
print("alignment quality, input :", metrics.alignment_quality(demos, Q.mean(demos), Q))
print("alignment quality, RTW   :", metrics.alignment_quality(result.aligned, result.mean, Q))

# %%
# The input components jump wherever the sign flips; the aligned series are shown in
# the hemisphere of the mean, and the mean is smooth.

aligned = result.aligned * np.sign((result.aligned * result.mean).sum(-1, keepdims=True))
fig, axes = plt.subplots(2, 4, figsize=(11, 4.8), sharex=True, sharey=True)
for c, name in enumerate("wxyz"):
    t_in = np.linspace(0, 1, demos.shape[1])
    axes[0, c].plot(t_in, demos[..., c].T, ".", ms=2)
    axes[0, c].set_title(f"input {name} (with sign flips)")
    t_out = np.linspace(0, 1, len(result.mean))
    axes[1, c].plot(t_out, aligned[..., c].T, lw=1, alpha=0.7)
    axes[1, c].plot(t_out, result.mean[:, c], "k--", lw=2)
    axes[1, c].set_title(f"aligned {name} and mean")
    axes[1, c].set_xlabel("normalised time")
fig.tight_layout()
plt.show()
