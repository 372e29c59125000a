"""
A proximity forest: an elastic split and a shapelet split
=========================================================

``RTWProximityForest`` grows trees whose nodes keep the best of two kinds of candidate
split. An elastic candidate sends every series to the nearest of one exemplar per
class, under a manifold-DTW measure drawn at random: on the series or on their tangent
velocity (the derivative series), with a band or amerced DTW, the point cost the
geodesic distance to the power 1/2, 1 or 2. A shapelet candidate takes a short dilated
piece of one training series and sends a series left or right by one feature of it:
the least sliding distance to the series, where that lies, or how many windows come
within a threshold. Here on GunPoint (UCR archive, shipped with aeon: the hand's x
coordinate while drawing a gun or pointing a finger) with a small forest; the figure
shows one split of each kind: the measure and its exemplars, and the shapelet where it
was taken from.
"""

import matplotlib.pyplot as plt
import numpy as np
from aeon.datasets import load_classification

from sk_rtw import RTWProximityForest, tangent_velocity
from sk_rtw.forest import NearestExemplarSplit, ShapeletSplit
from sk_rtw.utils import from_aeon

X_train, y_train = load_classification("GunPoint", split="train")
X_test, y_test = load_classification("GunPoint", split="test")
X_train, X_test = from_aeon(X_train), from_aeon(X_test)  # (n, 1, T) -> (n, T)

forest = RTWProximityForest(n_trees=20, random_state=0).fit(X_train, y_train)
print(f"test accuracy {forest.score(X_test, y_test):.3f} with {len(forest.trees_)} trees, "
      f"{np.mean([tree.n_nodes_ for tree in forest.trees_]):.1f} nodes each")  # fmt: skip


def splits(tree):
    """Every split of a tree, root first."""
    stack = [tree.root_]
    while stack:
        node = stack.pop(0)
        if node.split is not None:
            yield node.split
            stack.extend(node.children)


every = [split for tree in forest.trees_ for split in splits(tree)]
print(f"{sum(isinstance(s, ShapeletSplit) for s in every)} shapelet splits and "
      f"{sum(isinstance(s, NearestExemplarSplit) for s in every)} elastic splits")  # fmt: skip

# %%
# An elastic split names its measure and, for every class, the training series it drew
# as the exemplar (``split.sources`` says which; the split holds the series). A
# velocity measure compares the first differences, so its exemplars are drawn as such.
# A shapelet split holds its shapelet (``split.shapelet``: points, dilation, the series
# and position it was taken from), the feature and the threshold.
velocity = tangent_velocity(X_train)
elastic = next(s for s in every if isinstance(s, NearestExemplarSplit))
shapelet_split = next(s for s in every if isinstance(s, ShapeletSplit))
fig, (left, right) = plt.subplots(1, 2, figsize=(13, 4), sharex=True)
shown = velocity if elastic.measure.representation == "velocity" else X_train
for code, index in zip(elastic.classes, elastic.sources, strict=True):
    left.plot(shown[index], lw=1.6, label=f"class {forest.classes_[code]} (series {index})")
left.set_title("elastic: " + str(elastic.measure).replace(", point", ",\npoint"), fontsize=9)
left.legend(fontsize=8)

shapelet = shapelet_split.shapelet
series, start = shapelet.source
shown = velocity if shapelet.representation == "velocity" else X_train
where = start + shapelet.dilation * np.arange(shapelet.length)
right.plot(shown[series], color="0.6", lw=1.2,
           label=f"series {series}, class {forest.classes_[shapelet.label]}")  # fmt: skip
taken = f"its shapelet: {shapelet.length} points, dilation {shapelet.dilation}"
right.plot(where, shown[series][where], "o-", color="C3", lw=2, label=taken)
right.set_title("shapelet: " + str(shapelet_split).replace(" on the", "\non the"), fontsize=9)
right.legend(fontsize=8)
for ax in (left, right):
    ax.set_xlabel("time")
fig.suptitle("One split of each kind in a forest of 20 trees")
fig.tight_layout()
plt.show()
