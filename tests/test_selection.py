"""The choice of band and centroids per class: k-medoids, leave-one-out scores, the rule."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy.special import softmax
from sklearn.metrics import log_loss

from sk_rtw import AutoChoice, RTWAverager, RTWNearestCentroid, dtw_pairwise_distance
from sk_rtw.estimators import _selection
from sk_rtw.estimators._choice import mcnemar
from sk_rtw.estimators._classifier import fit_temperature
from sk_rtw.estimators._core import SeriesCentroid
from sk_rtw.estimators._medoids import held_out_distances, kmedoids
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


def reference_held_out(D, k):
    """The leave-one-out rule with plain Python: a non-medoid keeps the class's medoids; a
    medoid's cluster gets the medoid of its other members."""
    medoids, labels = kmedoids(D, k)
    out = np.full(len(D), np.inf)
    for i in range(len(D)):
        chosen = [m for m in medoids if m != i]
        if i in medoids:
            rest = [j for j in np.flatnonzero(labels == labels[i]) if j != i]
            if rest:
                chosen.append(rest[int(np.argmin(D[np.ix_(rest, rest)].sum(1)))])
        if chosen:
            out[i] = D[i, chosen].min()
    return out


@pytest.mark.parametrize("k", [1, 2, 3, 6, 9])
def test_held_out_distances_follow_the_rule(k):
    rng = np.random.default_rng(k)
    D = euclidean_matrix(rng.normal(0.0, 1.0, (9, 2)))
    medoids, labels = kmedoids(D, k)
    got = held_out_distances(D, medoids, labels)
    np.testing.assert_array_equal(got, reference_held_out(D, k))
    if k == len(D):  # every point a medoid: exactly leave-one-out 1-NN
        np.testing.assert_array_equal(got, np.where(np.eye(9, dtype=bool), np.inf, D).min(1))
    if k == 1:  # one medoid: its own replacement is the class's medoid without it
        m = medoids[0]
        rest = [j for j in range(9) if j != m]
        exact = kmedoids(np.ascontiguousarray(D[np.ix_(rest, rest)]), 1)[0][0]
        assert got[m] == D[m, rest[exact]]
    assert np.all(got > 0)  # nobody is its own neighbour
    single = held_out_distances(np.zeros((1, 1)), np.array([0]), np.array([0]))
    assert np.isinf(single[0])


def test_class_counts_follow_the_class_sizes():
    sizes = np.array([1, 7, 8, 264, 58])
    np.testing.assert_array_equal(_selection.class_counts(8, sizes), [1, 7, 8, 8, 8])
    np.testing.assert_array_equal(_selection.class_counts(1, sizes), [1, 1, 1, 1, 1])
    np.testing.assert_array_equal(_selection.class_counts(0.125, sizes), [1, 1, 1, 33, 8])
    np.testing.assert_array_equal(_selection.class_counts(0.5, sizes), [1, 4, 4, 132, 29])
    np.testing.assert_array_equal(_selection.class_counts(1.0, sizes), sizes)
    # an integer is a count, a float a fraction: 1 and 1.0 are different candidates
    assert _selection.candidate_key(0.05, 1) != _selection.candidate_key(0.05, 1.0)


def held_out_reference(X, codes, k, window):
    """Every candidate's held-out distances from the whole DTW matrix, in plain Python."""
    D = dtw_pairwise_distance(X, window=window)
    out = np.full((len(X), codes.max() + 1), np.inf)
    for c in range(codes.max() + 1):
        members = np.flatnonzero(codes == c)
        sub = np.ascontiguousarray(D[np.ix_(members, members)])
        count = int(_selection.class_counts(k, np.array([len(members)]))[0])
        out[members, c] = (
            reference_held_out(sub, count)
            if count < len(members)
            else (np.where(np.eye(len(members), dtype=bool), np.inf, sub).min(1))
        )
        medoids = members if count >= len(members) else members[kmedoids(sub, count)[0]]
        others = np.flatnonzero(codes != c)
        out[others, c] = D[np.ix_(others, medoids)].min(1)
    return out


@pytest.mark.parametrize(("k", "window"), [(1, 0.1), (0.25, 0.0), (0.5, None), (1.0, 0.1)])
def test_held_out_scores_match_the_whole_matrix(k, window):
    rng = np.random.default_rng(0)
    X = rng.standard_normal((23, 25)).cumsum(1)
    codes = np.repeat([0, 1, 2], [10, 8, 5])
    collection = check_series_collection(X)
    members = [np.flatnonzero(codes == c) for c in range(3)]
    matrices = [dtw_pairwise_distance(X[m], window=window) for m in members]
    expected = held_out_reference(X, codes, k, window)
    partition = _selection.class_partitions(matrices, members, k)
    held_out = _selection.held_out_scores(collection, codes, partition, window)
    np.testing.assert_array_equal(held_out, expected)
    # the cheaper outcome-only scores give the same argmin (the other classes only where
    # nearer than a series' own), with or without the band's shared search first
    limit = partition.own * np.where(np.arange(23) % 2, 1.5, 0.5)  # some series unknown
    nearest = _selection.nearest_other_class(collection, codes, limit, window)
    D = dtw_pairwise_distance(X, window=window)
    others = np.where(codes[:, None] == codes[None], np.inf, D).min(1)  # every other series
    np.testing.assert_array_equal(nearest.distances.min(1),
                                  np.where(others <= limit, others, np.inf))  # fmt: skip
    for shared in (None, nearest):
        quick_scores = _selection.held_out_scores(
            collection, codes, partition, window, every_class=False, nearest_other=shared
        )
        np.testing.assert_array_equal(quick_scores.argmin(1), expected.argmin(1))
        np.testing.assert_array_equal(quick_scores[np.arange(23), codes],
                                      expected[np.arange(23), codes])  # fmt: skip


def test_mcnemar_statistic():
    prior = np.array([1, 1, 0, 0, 1, 0], bool)
    candidate = np.array([1, 0, 1, 1, 1, 1], bool)  # 3 better, 1 worse
    assert mcnemar(candidate, prior) == pytest.approx(2 / np.sqrt(4))
    assert mcnemar(prior, prior) == 0.0


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
    prior = dict(zip(("dtw_window", "n_centroids"), AutoChoice().prior, strict=True))
    assert report["prior"] == prior
    scores = {
        _selection.candidate_key(c["dtw_window"], c["n_centroids"]): c
        for c in report["candidates"]
    }
    assert len(scores) == len(AutoChoice().windows) * len(AutoChoice().centroids)
    best = max(c["z"] for c in scores.values())
    chosen = _selection.candidate_key(clf.dtw_window_, clf.n_centroids_)
    if best < AutoChoice().z_threshold:
        assert chosen == _selection.candidate_key(*AutoChoice().prior)
    else:
        assert scores[chosen]["z"] == best
    # one centroid per class, explicitly: the band is what the data prefer
    one = RTWNearestCentroid(method="dba", n_centroids=1).fit(X, y)
    assert [c["dtw_window"] for c in one.selection_["candidates"]] == list(AutoChoice().windows)
    assert one.dtw_window_ <= 0.1
    X_test, y_test = shifted_bumps(seed=1)
    assert clf.score(X_test, y_test) >= 0.9
    # a band keeps the early and the late bump apart
    banded = RTWNearestCentroid(method="dba", dtw_window=0.05).fit(X, y)
    assert banded.score(X_test, y_test) == 1.0


def test_a_class_of_two_shapes_gets_several_centroids():
    X, y = two_shapes_per_class()
    clf = RTWNearestCentroid(method="dba", dtw_window=0.0).fit(X, y)
    scores = {
        _selection.candidate_key(0.0, c["n_centroids"]): c["accuracy"]
        for c in clf.selection_["candidates"]
    }
    assert np.bincount(clf.centroid_classes_).min() >= 2
    assert scores[_selection.candidate_key(0.0, clf.n_centroids_)] > scores[(0.0, False, 1)]
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
    averaged = [a for a in engine.alignments_ if not isinstance(a, SeriesCentroid)]
    assert averaged and {a.config.dtw_window for a in averaged} == {engine.dtw_window_}


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
    # a fraction chosen on the sample applies to the whole classes
    counts = _selection.class_counts(clf.n_centroids_, np.bincount(y))
    np.testing.assert_array_equal(np.bincount(clf.centroid_classes_), counts)
    assert report["class_centroids"] == counts.tolist()
    index = _selection.selection_sample(
        check_series_collection(X), y, AutoChoice().windows, np.random.RandomState(0)
    )
    assert np.all(np.bincount(y[index]) >= 2) and len(np.unique(index)) == len(index)


def test_the_cell_budget_bounds_the_sample():
    X = np.zeros((400, 1000))
    collection = check_series_collection(X)
    codes = np.repeat([0, 1], 200)
    index = _selection.selection_sample(
        collection, codes, AutoChoice().windows, np.random.RandomState(0)
    )
    pair = sum(_selection.band_cells(1000, w) for w in AutoChoice().windows)
    cells = len(index) ** 2 / 2 * pair
    assert cells <= _selection.CELLS_PER_POINT * X.size
    assert len(index) < 400
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
    assert len(clf.means_) > 2  # several centroids per class, some of one training series
    naive = fit_temperature(clf.class_distances(X), y)
    assert clf.temperature_ > 2 * naive
    proba = clf.predict_proba(X_new)
    np.testing.assert_allclose(proba.sum(1), 1.0)
    distances = clf.class_distances(X_new)
    overconfident = softmax(-distances / naive, axis=1)
    assert log_loss(y_new, proba) < log_loss(y_new, overconfident)


# ------------------------------------------------------------------ counts and parts


def test_a_fraction_gives_large_classes_more_centroids():
    """Imbalanced classes: a count per class gives the small class as many centroids as
    the large one; a fraction keeps their ratio."""
    rng = np.random.default_rng(0)
    y = np.repeat([0, 1], [40, 8])
    X = rng.standard_normal((48, 20)).cumsum(1)
    fixed = RTWNearestCentroid(method="dba", n_centroids=6, dtw_window=0.1).fit(X, y)
    np.testing.assert_array_equal(np.bincount(fixed.centroid_classes_), [6, 6])
    share = RTWNearestCentroid(method="dba", n_centroids=0.25, dtw_window=0.1).fit(X, y)
    np.testing.assert_array_equal(np.bincount(share.centroid_classes_), [10, 2])
    assert share.n_centroids_ == 0.25 and isinstance(share.n_centroids_, float)
    np.testing.assert_array_equal(share.centroid_classes_[share.assignments_], y)


def test_every_series_a_centroid_is_1nn_within_the_band():
    rng = np.random.default_rng(1)
    X = rng.standard_normal((20, 30)).cumsum(1)
    y = np.repeat([0, 1], 10)
    clf = RTWNearestCentroid(method=quick(), n_centroids=1.0, dtw_window=0.1).fit(X, y)
    np.testing.assert_array_equal(clf.means_[:, :, 0], X)  # the series themselves
    assert all(isinstance(a, SeriesCentroid) and a.n_iter == 0 for a in clf.alignments_)
    X_new = rng.standard_normal((15, 30)).cumsum(1)
    nearest = dtw_pairwise_distance(X_new, X, window=0.1).argmin(1)
    np.testing.assert_array_equal(clf.predict(X_new), y[nearest])
    one = RTWNearestCentroid(method=quick(), n_centroids=1, dtw_window=0.1).fit(X, y)
    assert len(one.means_) == 2  # the integer 1 is one centroid per class
