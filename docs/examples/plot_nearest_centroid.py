"""
Nearest-centroid classification with RTW centroids
==================================================

``RTWNearestCentroid`` predicts the class whose centroid is nearest in DTW. By default it
chooses the DTW band and the number of RTW centroids per class from the training data;
with ``n_centroids=1, dtw_window=None`` it is the paper's classifier, one RTW mean per
class. It is a scikit-learn classifier: here on ItalyPowerDemand (UCR archive, shipped
with aeon; 24 hourly power readings per day, winter vs. summer days), with a confusion
matrix of the default's test predictions and its centroids beside the class means.
"""

import matplotlib.pyplot as plt
import numpy as np
from aeon.datasets import load_classification
from sklearn.metrics import ConfusionMatrixDisplay, accuracy_score

from sk_rtw import RTW, RTWNearestCentroid
from sk_rtw.utils import from_aeon

X_train, y_train = load_classification("ItalyPowerDemand", split="train")
X_test, y_test = load_classification("ItalyPowerDemand", split="test")
X_train, X_test = from_aeon(X_train), from_aeon(X_test)  # (n, 1, T) -> (n, T)

clf = RTWNearestCentroid(method=RTW(n_epochs=64), random_state=0).fit(X_train, y_train)
one_mean = RTWNearestCentroid(method=RTW(n_epochs=64), n_centroids=1, dtw_window=None,
                              random_state=0).fit(X_train, y_train)  # fmt: skip
y_pred = clf.predict(X_test)
print(f"default: band {clf.dtw_window_}, {clf.n_centroids_} centroids per class, test "
      f"accuracy {accuracy_score(y_test, y_pred):.3f} on {len(y_test)} days")  # fmt: skip
print(f"one mean per class: test accuracy {one_mean.score(X_test, y_test):.3f}")

# %%
fig, axes = plt.subplots(1, 3, figsize=(15, 4))
ConfusionMatrixDisplay.from_predictions(y_test, y_pred, ax=axes[0], colorbar=False)
axes[0].set_title("test predictions (default)")
colours = {}
for label, mean in zip(one_mean.classes_, one_mean.means_, strict=True):
    members = X_train[y_train == label]
    line = axes[1].plot(np.linspace(0, 23, len(mean)), mean[:, 0], lw=2.2, label=f"class {label}")
    axes[1].plot(np.arange(24), members.T, color=line[0].get_color(), alpha=0.12, lw=0.7)
    colours[label] = line[0].get_color()
axes[1].set_title("one mean per class (training days behind)")
for owner, centroid in zip(clf.centroid_classes_, clf.means_, strict=True):
    label = clf.classes_[owner]
    axes[2].plot(np.linspace(0, 23, len(centroid)), centroid[:, 0], color=colours[label], lw=1.2)
axes[2].set_title(f"the default's {len(clf.means_)} centroids, coloured by class")
for ax in axes[1:]:
    ax.set_xlabel("hour")
axes[1].legend()
fig.tight_layout()
plt.show()
