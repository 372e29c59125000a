"""TangentVelocity: the function as a transformer, its layouts, and a classifier that
knows no manifold reading quaternion demonstrations in their own world frames."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from sklearn.pipeline import make_pipeline
from sklearn.utils.estimator_checks import parametrize_with_checks

from sk_rtw import TangentVelocity, tangent_velocity
from sk_rtw.datasets import make_warped_signals
from sk_rtw.manifolds import quaternion_product

from .test_estimators import EXPECTED_FAILURES


@parametrize_with_checks([TangentVelocity(output="tabular")],
                         expected_failed_checks=lambda e: EXPECTED_FAILURES)  # fmt: skip
def test_sklearn_compatible(estimator, check):
    check(estimator)


def test_layouts_are_the_functions_velocity():
    Q = make_warped_signals("quaternion", n_signals=3, length=20, random_state=0).signals
    v = tangent_velocity(Q, "quaternion")
    np.testing.assert_array_equal(TangentVelocity("quaternion").fit_transform(Q), v)
    np.testing.assert_array_equal(TangentVelocity("quaternion", output="aeon").fit_transform(Q),
                                  np.swapaxes(v, 1, 2))  # fmt: skip
    tabular = TangentVelocity("quaternion", output="tabular").fit_transform(Q)
    np.testing.assert_array_equal(tabular, v.reshape(3, -1))
    unequal = [Q[0], Q[1, :15]]
    aeon = TangentVelocity("quaternion", output="aeon").fit_transform(unequal)
    assert [a.shape for a in aeon] == [(3, 19), (3, 14)]
    with pytest.raises(ValueError, match="equal length"):
        TangentVelocity("quaternion", output="tabular").fit_transform(unequal)
    with pytest.raises(ValueError, match="output"):
        TangentVelocity(output="coordinates").fit(Q[..., 0])


def test_minirocket_on_the_velocity_does_not_see_the_world_frame():
    """Each demonstration in its own world frame (a random rotation and sign): MiniRocket
    on the quaternion coordinates changes its predictions; on the velocity it does
    not."""
    pytest.importorskip("aeon")
    from aeon.classification.convolution_based import MiniRocketClassifier

    first = make_warped_signals("quaternion", n_signals=10, length=40, random_state=1).signals
    second = make_warped_signals("quaternion", n_signals=10, length=40, random_state=2).signals
    X = np.concatenate([first, second])
    y = np.repeat([0, 1], 10)
    rng = np.random.default_rng(0)
    frames = Rotation.random(len(X), random_state=3).as_quat()[:, [3, 0, 1, 2]]
    moved = np.stack([rng.choice([-1.0, 1.0]) * quaternion_product(g, x)
                      for g, x in zip(frames, X, strict=True)])  # fmt: skip
    train = np.arange(20) % 2 == 0
    pipe = make_pipeline(TangentVelocity("quaternion", output="aeon"),
                         MiniRocketClassifier(random_state=0, n_jobs=1))  # fmt: skip
    pipe.fit(X[train], y[train])
    np.testing.assert_array_equal(pipe.predict(moved[~train]), pipe.predict(X[~train]))
    assert pipe.score(moved[~train], y[~train]) >= 0.9
