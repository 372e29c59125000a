"""
Prototypes that vote: a linear readout over the distances to every centroid
============================================================================

``RTWPrototypeClassifier`` fits the centroids of ``RTWNearestCentroid`` and reads out
the manifold-DTW distances of a series to *every* centroid, those of the other classes
included, with a linear classifier. The training distances come from centroids that did
not see the series (out of fold), so the readout learns from the distances it will meet
at prediction time. ``readout_weights_`` (class x centroid) says which centroids weigh
for and against each class; the centroids stay series one can plot.

Here on ItalyPowerDemand (UCR archive, shipped with aeon; 24 hourly power readings per
day, winter vs. summer days). ``decision="auto"`` (the default) keeps the nearest
centroid where the readout does not clearly classify the training series better,
cross-validated; ``decision_`` says which one classifies, ``cv_accuracy_`` why.
"""

import matplotlib.pyplot as plt
import numpy as np
from aeon.datasets import load_classification

from sk_rtw import RTW, RTWPrototypeClassifier
from sk_rtw.utils import from_aeon

X_train, y_train = load_classification("ItalyPowerDemand", split="train")
X_test, y_test = load_classification("ItalyPowerDemand", split="test")
X_train, X_test = from_aeon(X_train), from_aeon(X_test)  # (n, 1, T) -> (n, T)

clf = RTWPrototypeClassifier(method=RTW(n_epochs=64), random_state=0).fit(X_train, y_train)
nearest = clf.centroids_  # the nearest-centroid fit whose centroids are the features
scores = clf.cv_accuracy_
print(f"{len(clf.means_)} centroids; decision: {clf.decision_} (cross-validated accuracy "
      f"on the training days: readout {scores['readout']:.3f}, nearest centroid "
      f"{scores['nearest']:.3f}, z = {scores['z']:.2f})")  # fmt: skip
print(f"test accuracy: prototype classifier {clf.score(X_test, y_test):.3f}, "
      f"nearest centroid {nearest.score(X_test, y_test):.3f}")  # fmt: skip

# %%
# For each class, the three centroids whose nearness speaks most for it (the most
# negative weights: a small distance raises the class's score) and the three whose
# nearness speaks most against it.
weights = clf.readout_weights_
hours = np.arange(24)
fig, axes = plt.subplots(len(clf.classes_), 2, figsize=(11, 3.2 * len(clf.classes_)),
                         sharex=True, sharey=True, squeeze=False)  # fmt: skip
for k, label in enumerate(clf.classes_):
    order = np.argsort(weights[k])
    for ax, chosen, title in (
        (axes[k, 0], order[:3], "near it speaks for"),
        (axes[k, 1], order[::-1][:3], "near it speaks against"),
    ):
        for m in chosen:
            owner = clf.classes_[clf.centroid_classes_[m]]
            text = f"centroid {m} (class {owner}), weight {weights[k, m]:+.2f}"
            ax.plot(hours, clf.means_[m][:, 0], lw=1.6, label=text)
        ax.set_title(f"class {label}: {title}")
        ax.legend(fontsize=7)
for ax in axes[-1]:
    ax.set_xlabel("hour")
fig.tight_layout()
plt.show()
