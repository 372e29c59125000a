"""
Nearest-centroid classification with RTW means
==============================================

``RTWNearestCentroid`` learns one RTW mean per class and predicts the class whose mean
is nearest in DTW. It is a scikit-learn classifier: here on ItalyPowerDemand (UCR
archive, shipped with aeon; 24 hourly power readings per day, winter vs. summer days),
with a confusion matrix of the test predictions and the class means.
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
y_pred = clf.predict(X_test)
print(f"test accuracy: {accuracy_score(y_test, y_pred):.3f} on {len(y_test)} days")

# %%
fig, axes = plt.subplots(1, 2, figsize=(11, 4))
ConfusionMatrixDisplay.from_predictions(y_test, y_pred, ax=axes[0], colorbar=False)
axes[0].set_title("test predictions")
for label, mean in zip(clf.classes_, clf.means_, strict=True):
    members = X_train[y_train == label]
    line = axes[1].plot(np.linspace(0, 23, len(mean)), mean[:, 0], lw=2.2, label=f"class {label}")
    axes[1].plot(np.arange(24), members.T, color=line[0].get_color(), alpha=0.12, lw=0.7)
axes[1].set_xlabel("hour")
axes[1].set_title("class means (training days behind)")
axes[1].legend()
fig.tight_layout()
plt.show()
