"""The choice of band and centroids per class: k-medoids, leave-one-out scores, the rule."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy.special import softmax
from sklearn.metrics import log_loss

from sk_rtw import RTWAverager, RTWNearestCentroid
from sk_rtw.estimators import _selection
from sk_rtw.estimators._classifier import fit_temperature
from sk_rtw.estimators._medoids import kmedoids, loo_class_distances
from sk_rtw.utils import check_series_collection

from .conftest import quick


def euclidean_matrix(points):
    return np.sqrt(((points[:, None] - points[None]) ** 2).sum(-1))


def total_cost(D, medoids):
    return D[:, medoids].min(1).sum()


# ------------------------------------------------------------------------ k-medoids


@pytest.mark.parametrize("seed", range(6))
def test_kmedoids_is_a_local_optimum_with_consistent_labels(seed):
    rng = np.random.default_rng(seed)
    D = euclidean_matrix(rng.standard_normal((int(rng.integers(2, 25)), 2)))
    k = int(rng.integers(1, len(D) + 1))
    medoids, labels = kmedoids(D, k)
    assert len(set(medoids.tolist())) == k
    np.testing.assert_array_equal(labels[medoids], np.arange(k))
    # every point is with its nearest medoid, every medoid minimises its cluster's total
    np.testing.assert_allclose(D[np.arange(len(D)), medoids[labels]], D[:, medoids].min(1))
    for m in range(k):
        members = np.flatnonzero(labels == m)
        totals = D[np.ix_(members, members)].sum(1)
        assert D[medoids[m], members].sum() == pytest.approx(totals.min())
    again = kmedoids(D.copy(), k)  # deterministic
    np.testing.assert_array_equal(again[0], medoids)


def test_kmedoids_is_close_to_the_optimum_of_small_problems():
    """Against every subset of medoids (the exact k-medoids optimum): exact for one medoid
    and for well-separated clusters; on structureless points BUILD and alternation (no
    swap phase) stay within 1.3x of the optimum, 3 % on average."""
    rng = np.random.default_rng(3)
    gaps = []
    for _ in range(40):
        D = euclidean_matrix(rng.standard_normal((9, 2)))
        for k in (1, 2, 3):
            medoids, _ = kmedoids(D, k)
            best = min(total_cost(D, list(c)) for c in itertools.combinations(range(9), k))
            gaps.append(total_cost(D, medoids) / best - 1)
            if k == 1:
                assert gaps[-1] == pytest.approx(0.0, abs=1e-12)
    assert min(gaps) >= -1e-12 and max(gaps) < 0.3 and np.mean(gaps) < 0.03
    centres = np.array([[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]])
    points = np.concatenate([c + rng.standard_normal((5, 2)) for c in centres])
    D = euclidean_matrix(points)
    medoids, labels = kmedoids(D, 3)
    best = min(total_cost(D, list(c)) for c in itertools.combinations(range(15), 3))
    assert total_cost(D, medoids) == pytest.approx(best)
    assert sorted(np.bincount(labels).tolist()) == [5, 5, 5]


def test_kmedoids_edge_cases():
    D = euclidean_matrix(np.array([[0.0], [1.0], [5.0], [5.5]]))
    medoids, labels = kmedoids(D, 1)
    assert medoids.tolist() == [int(np.argmin(D.sum(1)))]
    medoids, labels = kmedoids(D, 2)
    assert sorted(labels[[0, 1]]) == [labels[0]] * 2 and labels[2] == labels[3] != labels[0]
    medoids, labels = kmedoids(D, 4)  # every point its own medoid
    assert sorted(medoids.tolist()) == [0, 1, 2, 3]
    duplicates = np.zeros((3, 3))  # identical series: ties go to the lowest index
    medoids, labels = kmedoids(duplicates, 2)
    assert medoids.tolist() == [0, 1] and labels.tolist() == [0, 1, 0]


# ------------------------------------------------------------------ leave-one-out


def reference_loo(D, codes, k):
    """Leave-one-out nearest medoid with explicit deletions (no shared bookkeeping)."""
    classes = np.unique(codes)
    out = np.full((len(codes), len(classes)), np.inf)
    for i in range(len(codes)):
        for c in classes:
            members = [j for j in np.flatnonzero(codes == c) if j != i]
            if not members:
                continue
            sub = np.ascontiguousarray(D[np.ix_(members, members)])
            medoids, _ = kmedoids(sub, min(k, len(members)))
            out[i, c] = D[i, np.asarray(members)[medoids]].min()
    return out


@pytest.mark.parametrize("k", [1, 2, 5])
def test_leave_one_out_distances_match_a_plain_reference(k):
    rng = np.random.default_rng(k)
    points = np.concatenate([rng.normal(c, 1.0, (n, 2)) for c, n in ((0, 7), (2, 5), (4, 1))])
    codes = np.repeat([0, 1, 2], [7, 5, 1])
    D = euclidean_matrix(points)
    got = loo_class_distances(D, codes, 3, k)
    np.testing.assert_allclose(got, reference_loo(D, codes, k))
    assert np.isinf(got[-1, 2])  # alone in its class: nothing left to compare with


def test_mcnemar_statistic():
    prior = np.array([1, 1, 0, 0, 1, 0], bool)
    candidate = np.array([1, 0, 1, 1, 1, 1], bool)  # 3 better, 1 worse
    assert _selection.mcnemar(candidate, prior) == pytest.approx(2 / np.sqrt(4))
    assert _selection.mcnemar(prior, prior) == 0.0


# ------------------------------------------------------------------ the choice


def shifted_bumps(n_per=10, seed=0):
    """An early and a late bump: the band must keep them apart (no band warps them alike)."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 1, 60)
    X = [np.exp(-((t - c - rng.normal(0, 0.02)) ** 2) / 0.003) + 0.05 * rng.standard_normal(60)
         for c in [0.3] * n_per + [0.7] * n_per]  # fmt: skip
    return np.array(X), np.repeat([0, 1], n_per)


def two_shapes_per_class(n=12, seed=0):
    rng = np.random.default_rng(seed)
    levels = [1.0, -1.0] * (n // 2) + [0.0] * (n // 2)
    X = np.array([level + 0.1 * rng.standard_normal(30) for level in levels])
    return X, np.repeat([0, 1], [n, n // 2])


def test_the_prior_stays_unless_a_candidate_is_clearly_better():
    X, y = shifted_bumps()
    clf = RTWNearestCentroid(method="dba").fit(X, y)
    report = clf.selection_
    assert report["prior"] == {"dtw_window": 0.05, "n_centroids": 8}
    scores = {(c["dtw_window"], c["n_centroids"]): c for c in report["candidates"]}
    assert len(scores) == len(_selection.WINDOWS) * len(_selection.CENTROIDS)
    best = max(c["z"] for c in scores.values())
    if best < _selection.Z_THRESHOLD:
        assert (clf.dtw_window_, clf.n_centroids_) == (0.05, 8)
    else:
        assert scores[clf.dtw_window_, clf.n_centroids_]["z"] == best
    # one centroid per class, explicitly: the band is what the data prefer
    one = RTWNearestCentroid(method="dba", n_centroids=1).fit(X, y)
    assert [c["dtw_window"] for c in one.selection_["candidates"]] == list(_selection.WINDOWS)
    assert one.dtw_window_ <= 0.1
    X_test, y_test = shifted_bumps(seed=1)
    assert clf.score(X_test, y_test) == 1.0


def test_a_class_of_two_shapes_gets_several_centroids():
    X, y = two_shapes_per_class()
    clf = RTWNearestCentroid(method="dba", dtw_window=0.0).fit(X, y)
    scores = {c["n_centroids"]: c["accuracy"] for c in clf.selection_["candidates"]}
    assert clf.n_centroids_ >= 2 and scores[clf.n_centroids_] > scores[1]
    assert clf.score(X, y) == 1.0
    # the prior is clearly better than one centroid: with the prior at one centroid
    # (n_centroids fixed), the band alone is chosen and one centroid misclassifies
    single = RTWNearestCentroid(method="dba", n_centroids=1, dtw_window=0.0).fit(X, y)
    assert single.score(X, y) < 1.0


def test_the_choice_is_what_the_fit_used_and_does_not_depend_on_the_seed():
    X, y = two_shapes_per_class(seed=1)
    auto = RTWNearestCentroid(method="dba", random_state=0).fit(X, y)
    other_seed = RTWNearestCentroid(method="dba", random_state=7).fit(X, y)
    assert (auto.dtw_window_, auto.n_centroids_) == (
        other_seed.dtw_window_,
        other_seed.n_centroids_,
    )
    assert auto.selection_["candidates"] == other_seed.selection_["candidates"]
    explicit = RTWNearestCentroid(
        method="dba", dtw_window=auto.dtw_window_, n_centroids=auto.n_centroids_
    ).fit(X, y)
    np.testing.assert_array_equal(explicit.assignments_, auto.assignments_)
    np.testing.assert_array_equal(explicit.means_, auto.means_)
    engine = RTWNearestCentroid(method=quick(), random_state=0).fit(X, y)
    assert {a.config.dtw_window for a in engine.alignments_} == {engine.dtw_window_}


def test_the_paper_preset_and_the_averager_keep_one_mean_per_class():
    X, y = shifted_bumps(n_per=5)
    paper = RTWNearestCentroid(method="dba", preset="paper").fit(X, y)
    assert (paper.dtw_window_, paper.n_centroids_, paper.selection_) == (None, 1, {})
    assert len(paper.means_) == 2
    averager = RTWAverager(method="dba").fit(X, y)
    assert (averager.dtw_window_, averager.n_centroids_, averager.selection_) == (None, 1, {})
    chosen = RTWAverager(method="dba", n_centroids="auto", dtw_window="auto").fit(X, y)
    assert chosen.selection_ and chosen.transform(X).shape == (len(X), len(chosen.means_))


def test_a_large_training_set_is_chosen_on_a_stratified_sample(monkeypatch):
    monkeypatch.setattr(_selection, "MAX_SERIES", 12)
    X, y = two_shapes_per_class(n=20)
    clf = RTWNearestCentroid(method="dba", random_state=0).fit(X, y)
    report = clf.selection_
    assert report["sampled"] and report["n_series"] <= 14  # the quota keeps 2 per class
    # every training series belongs to a centroid of its own class, the sampled ones and
    # the others (which join their nearest medoid)
    np.testing.assert_array_equal(clf.centroid_classes_[clf.assignments_], y)
    assert sum(len(a.aligned) for a in clf.alignments_) == len(X)
    assert clf.score(X, y) == 1.0
    index = _selection.selection_sample(
        check_series_collection(X), y, _selection.WINDOWS, np.random.RandomState(0)
    )
    assert np.all(np.bincount(y[index]) >= 2) and len(np.unique(index)) == len(index)


def test_the_cell_budget_bounds_the_sample():
    X = np.zeros((400, 1000))
    collection = check_series_collection(X)
    codes = np.repeat([0, 1], 200)
    index = _selection.selection_sample(
        collection, codes, _selection.WINDOWS, np.random.RandomState(0)
    )
    pair = sum(_selection.band_cells(1000, w) for w in _selection.WINDOWS)
    cells = len(index) ** 2 / 2 * pair
    assert cells <= _selection.CELLS_PER_POINT * X.size
    assert _selection.band_cells(100, None) == 100**2
    assert _selection.band_cells(100, 0.0) == 100
    assert _selection.band_cells(100, 0.1) == 100 * 21


def test_probabilities_are_fitted_on_held_out_distances():
    """Centroids that are training series sit at distance 0 from them, so a temperature
    fitted on the training distances is far too confident. The choice's held-out
    distances give one whose log-loss on new series is lower."""

    def overlapping(n, seed):  # two noisy classes that overlap
        rng = np.random.default_rng(seed)
        y = np.repeat([0, 1], n)
        return np.array([0.25 * c + rng.standard_normal(20) for c in y]), y

    X, y = overlapping(15, 0)
    X_new, y_new = overlapping(100, 1)
    clf = RTWNearestCentroid(method="dba").fit(X, y)
    assert clf.n_centroids_ > 1  # some centroids are single training series
    naive = fit_temperature(clf.class_distances(X), y)
    assert clf.temperature_ > 2 * naive
    proba = clf.predict_proba(X_new)
    np.testing.assert_allclose(proba.sum(1), 1.0)
    distances = clf.class_distances(X_new)
    overconfident = softmax(-distances / naive, axis=1)
    assert log_loss(y_new, proba) < log_loss(y_new, overconfident)
