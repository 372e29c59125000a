"""
A proximity forest and the exemplars of a root split
====================================================

``RTWProximityForest`` grows trees that split a node by sending every series to the
nearest of one exemplar per class, under a manifold-DTW measure drawn at random: on the
series or on their tangent velocity (the derivative series), with a band or amerced DTW,
the point cost the geodesic distance to the power 1/2, 1 or 2. Here on GunPoint (UCR
archive, shipped with aeon: the hand's x coordinate while drawing a gun or pointing a
finger) with a small forest; the figure shows the root splits of three trees: the
measure each drew and its exemplars, training series of each class, in the
representation the measure compares.
"""

import matplotlib.pyplot as plt
import numpy as np
from aeon.datasets import load_classification

from sk_rtw import RTWProximityForest, tangent_velocity
from sk_rtw.utils import from_aeon

X_train, y_train = load_classification("GunPoint", split="train")
X_test, y_test = load_classification("GunPoint", split="test")
X_train, X_test = from_aeon(X_train), from_aeon(X_test)  # (n, 1, T) -> (n, T)

forest = RTWProximityForest(n_trees=20, random_state=0).fit(X_train, y_train)
print(f"test accuracy {forest.score(X_test, y_test):.3f} with {len(forest.trees_)} trees, "
      f"{np.mean([tree.n_nodes_ for tree in forest.trees_]):.1f} nodes each")  # fmt: skip

# %%
# Each root split names its measure and, for every class, the training series it drew
# as the exemplar (``split.sources`` says which; the split holds the series). A velocity
# measure compares the first differences, so its exemplars are drawn as such.
velocity = tangent_velocity(X_train)
fig, axes = plt.subplots(1, 3, figsize=(15, 3.8), sharex=True)
for ax, tree in zip(axes, forest.trees_[:3], strict=True):
    split = tree.root_.split
    shown = velocity if split.measure.representation == "velocity" else X_train
    for code, index in zip(split.classes, split.sources, strict=True):
        label = forest.classes_[code]
        ax.plot(shown[index], lw=1.6, label=f"class {label} (series {index})")
    ax.set_title(str(split.measure).replace(", point", ",\npoint"), fontsize=9)
    ax.set_xlabel("time")
    ax.legend(fontsize=8)
fig.suptitle("Root splits of three trees: each class's exemplar under the drawn measure")
fig.tight_layout()
plt.show()
