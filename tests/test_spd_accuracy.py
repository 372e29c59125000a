"""SPD distances against 50-digit arithmetic, and diagonal points of any spread.

Every route (``SPD(k).dist`` and ``pairwise_dist`` in torch, the DTW kernels' features)
takes each log-eigenvalue of ``p^-1 x`` from the side of the pair that holds it
accurately; diagonal pairs take the maps entry by entry. References: the eigenvalues of
``p^-1 x`` in mpmath at 50 digits, and closed forms.
"""

from __future__ import annotations

import numpy as np
import pytest
import torch
from scipy.stats import special_ortho_group

from sk_rtw import SPD, RTWNearestCentroid, dtw_distance, dtw_pairwise_distance

mpmath = pytest.importorskip("mpmath")


def exact_distance(p, x):
    with mpmath.workdps(50):
        values = mpmath.eig(mpmath.matrix(p.tolist()) ** -1 * mpmath.matrix(x.tolist()),
                            left=False, right=False)  # fmt: skip
        return float(mpmath.sqrt(sum(mpmath.log(mpmath.re(v)) ** 2 for v in values)))


def rotated(eigenvalues, angle):
    c, s = np.cos(angle), np.sin(angle)
    R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    M = R @ np.diag(eigenvalues) @ R.T
    return (M + M.T) / 2


@pytest.mark.parametrize(
    "p, x",
    [
        (rotated([1e5, 1e-5, 1.0], 0.4), rotated([1e-5, 1e5, 1.0], 0.9)),  # was NaN
        (rotated([1e5, 1e-5, 1.0], 0.3), rotated([1e-5, 1e5, 1.0], 1.2)),  # was 13 % off
    ],
)
def test_ill_conditioned_spd3_pairs_match_50_digits(p, x):
    expected = exact_distance(p, x)
    assert SPD(3).dist(p, x) == pytest.approx(expected, rel=1e-7)
    assert dtw_distance(p[None], x[None], "spd") == pytest.approx(expected, rel=1e-7)


@pytest.mark.parametrize("k", [2, 3, 4])
def test_every_route_matches_50_digits_over_eigenvalues_1e_minus_6_to_1e6(k):
    """60 seeded pairs, eigenvalues log-uniform in 1e-6..1e6 (conditions up to 1e12)."""
    rng = np.random.default_rng(k)
    points = []
    for _ in range(120):
        R = special_ortho_group.rvs(k, random_state=rng)
        M = R @ np.diag(10.0 ** rng.uniform(-6, 6, k)) @ R.T
        points.append((M + M.T) / 2)
    P, X = np.array(points[:60]), np.array(points[60:])
    expected = np.array([exact_distance(p, x) for p, x in zip(P, X, strict=True)])
    space = SPD(k)
    np.testing.assert_allclose(space.dist(P, X), expected, rtol=1e-6)
    np.testing.assert_allclose(np.diagonal(space.pairwise_dist(P, X)), expected, rtol=1e-6)
    kernel = np.diagonal(dtw_pairwise_distance(P[:, None], X[:, None], "spd"))
    np.testing.assert_allclose(kernel, expected, rtol=1e-6)


@pytest.mark.parametrize("k", [2, 3, 4])
@pytest.mark.parametrize("exponent", [2, 80, 160, 300])
def test_diagonal_points_of_any_spread_are_exact(k, exponent):
    """diag(10^e, 10^-e, 1, ...) against diag(10^-e, 10^e, 1, ...): sqrt(2) 2 e ln 10.
    These were NaN, inf or 0.0 from 1e+-80 on."""
    big, small = 10.0**exponent, 10.0**-exponent
    p = np.diag([big, small] + [1.0] * (k - 2))
    x = np.diag([small, big] + [1.0] * (k - 2))
    expected = np.sqrt(2.0) * 2 * exponent * np.log(10.0)
    space = SPD(k)
    assert space.dist(p, x) == pytest.approx(expected, rel=1e-13)
    assert space.pairwise_dist(p[None], x[None])[0, 0] == pytest.approx(expected, rel=1e-13)
    assert dtw_distance(p[None], x[None], "spd") == pytest.approx(expected, rel=1e-13)
    # the maps: the tangent vector's entries p_i log(x_i / p_i), and back
    v = space.log(p, x)
    ratios = np.log(np.diag(x)) - np.log(np.diag(p))
    np.testing.assert_allclose(np.diag(v), np.diag(p) * ratios, rtol=1e-13)
    np.testing.assert_allclose(space.exp(p, v), x, rtol=1e-12)


def test_gradients_at_diagonal_pairs_are_the_general_routes():
    """The entry-by-entry route of diagonal pairs has the gradient of the general one
    (the distance is even in an off-diagonal entry there): gradcheck at a diagonal pair,
    finite at a pair of spread 1e+-100."""
    space = SPD(3)
    p = torch.diag(torch.tensor([5.0, 0.2, 1.0], dtype=torch.float64))
    x = torch.diag(torch.tensor([0.3, 4.0, 2.0], dtype=torch.float64)).requires_grad_(True)
    assert torch.autograd.gradcheck(lambda x: space.dist(p, x), (x,))
    wide = torch.diag(torch.tensor([1e100, 1e-100, 1.0], dtype=torch.float64))
    y = torch.diag(torch.tensor([1e-100, 1e100, 1.0], dtype=torch.float64)).requires_grad_(True)
    space.dist(wide, y).backward()
    assert torch.isfinite(y.grad).all()


def test_class_means_of_widely_spread_diagonal_series_stay_finite():
    """DBA class means of diagonal SPD(2) series with entries 1e+-60..90 (their
    distances were inf)."""
    rng = np.random.default_rng(0)
    X, y = [], []
    for label in (0, 1):
        for _ in range(4):
            e = rng.uniform(60, 90, size=20) * (1 if label else -1)
            series = np.zeros((20, 2, 2))
            series[:, 0, 0], series[:, 1, 1] = 10.0**e, 10.0**-e
            X.append(series)
            y.append(label)
    X = np.array(X)
    clf = RTWNearestCentroid(manifold="spd", method="dba", random_state=0).fit(X, y)
    assert np.isfinite(clf.class_distances(X)).all()
    assert clf.score(X, y) == 1.0


@pytest.mark.parametrize("k", [2, 3])
@pytest.mark.parametrize("scale", [1e50, 1e100, 1e160, 1e300])
def test_points_of_far_apart_scales(k, scale):
    """s A against B / s: the log-eigenvalues of A^-1 B shifted by -2 log s. The closed
    forms' products overflowed from about 1e+-75 (SPD(2) gave NaN): each point is now
    taken at a power of two near its scale, the log of the ratio added back; Log, Exp and
    the norm the same way."""
    rng = np.random.default_rng(k)
    A, B = (
        R @ np.diag(np.arange(1.0, k + 1.0) ** sign) @ R.T
        for R, sign in ((special_ortho_group.rvs(k, random_state=rng), s) for s in (1, -1))
    )
    logs = np.log(np.linalg.eigvals(np.linalg.solve(A, B)).real) - 2 * np.log(scale)
    expected = np.sqrt(np.sum(logs**2))
    space, P, X = SPD(k), scale * A, B / scale
    assert space.dist(P, X) == pytest.approx(expected, rel=1e-12)
    v = space.log(P, X)
    assert space.norm(P, v) == pytest.approx(expected, rel=1e-12)
    np.testing.assert_allclose(space.exp(P, v), X, rtol=1e-11, atol=1e-11 * np.abs(X).max())


def test_the_kernels_name_entries_beyond_their_range():
    """A valid non-diagonal point with entries 1e160 leaves the kernels' range (they
    square entries): the message says so and how to rescale, not "no Cholesky factor"."""
    rng = np.random.default_rng(0)
    R = special_ortho_group.rvs(2, random_state=rng)
    P = 1e160 * (R @ np.diag([1.0, 2.0]) @ R.T)
    with pytest.raises(ValueError, match=r"entries of magnitude \d.*e\+160.*rescale the series"):
        dtw_distance(P[None], np.eye(2)[None], "spd")
