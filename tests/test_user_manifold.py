"""A new manifold is one file plus its registration: DTW, the search, align and an
estimator take it by name (``tests/_circle_manifold.py``)."""

from __future__ import annotations

import numpy as np
import pytest

from sk_rtw import RTWNearestCentroid, align, dtw_nearest_distance, dtw_pairwise_distance
from sk_rtw.manifolds import (
    ManifoldSpec,
    _registry,
    check_manifold,
    get_manifold,
    register_manifold,
)

from ._circle_manifold import SPEC, CircleAngle


@pytest.fixture
def registered(monkeypatch):
    """The circle registered by name for one test (the registry restored after it)."""
    monkeypatch.setattr(_registry, "_REGISTRY", dict(_registry._REGISTRY))
    register_manifold(SPEC)
    return "circle-angle"


def _wrapped(values):
    return np.angle(np.exp(1j * np.asarray(values)))


def _series(n=6, T=40, seed=0):
    """Angles that cross the cut at +-pi: a Euclidean reading would see jumps of 2 pi."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 1, T)
    return np.stack([_wrapped(np.pi + 1.5 * np.sin(2 * np.pi * (t + rng.uniform(0, 0.2))))
                     for _ in range(n)])  # fmt: skip


def _dtw(a, b):
    """Plain DTW on the wrapped angular differences (an independent reference)."""
    cost = np.abs(_wrapped(a[:, None] - b[None, :]))
    D = np.full((len(a) + 1, len(b) + 1), np.inf)
    D[0, 0] = 0.0
    for i in range(1, len(a) + 1):
        for j in range(1, len(b) + 1):
            D[i, j] = cost[i - 1, j - 1] + min(D[i - 1, j], D[i, j - 1], D[i - 1, j - 1])
    return D[-1, -1]


def test_the_file_passes_the_manifold_checks():
    points = _wrapped(np.linspace(-3, 3, 8))[:, None]
    passed = check_manifold(CircleAngle(), points)
    assert "log inverts exp" in passed


def test_the_name_resolves_after_registration(registered):
    assert get_manifold(registered, point_shape=()) == CircleAngle()
    with pytest.raises(ValueError, match="registered already"):
        register_manifold(SPEC)
    register_manifold(SPEC, replace=True)
    with pytest.raises(ValueError, match="built-in"):
        register_manifold(ManifoldSpec("sphere", SPEC.factory, SPEC.dim_from_point_shape, ""))
    with pytest.raises(TypeError, match="ManifoldSpec"):
        register_manifold("circle")
    with pytest.raises(ValueError, match="lower-case"):
        register_manifold(ManifoldSpec("Circle", SPEC.factory, SPEC.dim_from_point_shape, ""))


def test_dtw_and_the_search_take_it_by_name(registered):
    X = _series()
    D = dtw_pairwise_distance(X, manifold=registered)
    expected = np.array([[_dtw(a, b) for b in X] for a in X])
    np.testing.assert_allclose(D, expected, rtol=1e-10, atol=1e-12)
    assert D.max() < 2 * np.pi * X.shape[1]  # no jump of 2 pi at the cut
    groups = np.array([0, 0, 1, 1, 2, 2])
    nearest = dtw_nearest_distance(X[:3], X, groups, manifold=registered, exclude=np.arange(3))
    for i in range(3):
        for g in range(3):
            members = [m for m in np.flatnonzero(groups == g) if m != i]
            assert nearest[i, g] == pytest.approx(expected[i, members].min(), rel=1e-10)


def test_align_and_an_estimator_take_it_by_name(registered):
    X = _series(n=4)
    result = align(X, manifold=registered, n_epochs=8, random_state=0)
    mean = np.asarray(result.mean)
    assert np.all(np.abs(mean) <= np.pi + 1e-12)  # on the manifold
    # every series stays within 1.5 of pi on the circle, and so does their mean (the
    # mean of the angles as numbers would fall near 0 where they cross the cut)
    assert np.abs(_wrapped(mean - np.pi)).max() <= 1.6  # (interpolation overshoots a little)
    assert np.abs(_wrapped(X.mean(0) - np.pi)).max() > 2.0
    y = np.repeat([0, 1], 6)
    data = np.concatenate([_series(6, seed=1), _wrapped(_series(6, seed=2) + 2.0)])
    clf = RTWNearestCentroid(manifold=registered, method="dba", random_state=0).fit(data, y)
    assert clf.manifold_ == CircleAngle()
    assert clf.score(data, y) == 1.0


def test_the_kernel_layout_is_kept_only_for_frozen_dataclass_manifolds():
    """The library's manifolds (frozen dataclasses) keep their kernel layout per value;
    a subclass that is not itself a frozen dataclass has it worked out at every call,
    so a change of its segments is seen."""
    from sk_rtw.manifolds import SPD, Euclidean
    from sk_rtw.manifolds._point_kernels import _layout

    assert _layout(SPD(3)) is _layout(SPD(3))

    class Settable(Euclidean):
        @property
        def distance_segments(self):
            return self.segments

    space = Settable(2)
    object.__setattr__(space, "segments", ((0, 2, "euclidean"),))
    assert _layout(space) == ((0, 2, 0, 2, 0),)
    object.__setattr__(space, "segments", None)
    assert _layout(space) is None
