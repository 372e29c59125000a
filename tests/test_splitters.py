"""The forest's splitter seam: one protocol for every kind of split, the elastic recipe
as a parameter object, a tree usable alone, and a new kind of split as one class."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest
from sklearn.base import clone
from sklearn.model_selection import GridSearchCV
from sklearn.utils.estimator_checks import parametrize_with_checks

from sk_rtw import ElasticSplitter, RTWProximityForest
from sk_rtw.forest import ProximityTree, Split, Splitter

from .test_estimators import EXPECTED_FAILURES
from .test_forest import three_classes, tree_splits


def _expected_failures(estimator):
    return EXPECTED_FAILURES


@parametrize_with_checks(
    [ProximityTree(random_state=0)], expected_failed_checks=_expected_failures
)
def test_a_tree_alone_is_a_scikit_learn_classifier(estimator, check):
    check(estimator)


def _splits(forest):
    """Every split of every tree of ``forest``."""
    return [split for tree in forest.trees_ for split in tree_splits(tree)]


def _measures(forest):
    return [split.measure for split in _splits(forest)]


def _split_kinds(forest):
    return {type(split).__name__ for split in _splits(forest)}


def _bumps(n=80, seed=0):
    """Class 1 has a bump at a random place: a local pattern."""
    rng = np.random.default_rng(seed)
    X = rng.standard_normal((n, 60))
    where = rng.integers(0, 50, size=n)
    y = np.arange(n) % 2
    for i in np.flatnonzero(y):
        X[i, where[i] : where[i] + 8] += np.hanning(8) * 6
    return X, y


def test_the_default_splitters_written_out_are_the_default_forest():
    """The default forest draws elastic and shapelet candidates with these recipes; the
    elastic splitter alone is another forest."""
    from sk_rtw.forest import ShapeletSplitter

    X, y = _bumps()
    default = RTWProximityForest(n_trees=6, random_state=0).fit(X[:40], y[:40])
    written = [
        ElasticSplitter(
            n_candidates=5, representation="auto", exemplars="series",
            exponents=(0.5, 1.0, 2.0), measures=("dtw", "adtw"), max_window=0.25,
            penalty_steps=100, penalty_exponent=5, penalty_pairs=50, mean_subset=10,
            mean_iterations=5,
        ),
        ShapeletSplitter(
            n_candidates=5, representation="auto", lengths=None, normalised_fraction=0.5,
            threshold_percentiles=(5.0, 10.0), features=("min", "argmin", "count"),
        ),
    ]  # fmt: skip
    explicit = RTWProximityForest(n_trees=6, splitters=written, random_state=0)
    explicit.fit(X[:40], y[:40])
    np.testing.assert_array_equal(default.predict_proba(X[40:]), explicit.predict_proba(X[40:]))
    assert [s.get_params() for s in default.splitters_] == [s.get_params() for s in written]
    assert _split_kinds(default) == {"NearestExemplarSplit", "ShapeletSplit"}
    elastic = RTWProximityForest(n_trees=6, splitters=written[:1], random_state=0)
    elastic.fit(X[:40], y[:40])
    assert _split_kinds(elastic) == {"NearestExemplarSplit"}
    assert not np.array_equal(elastic.predict_proba(X[40:]), default.predict_proba(X[40:]))


def test_the_recipe_decides_the_measures_drawn():
    X, y = three_classes()
    squared = RTWProximityForest(
        n_trees=4, splitters=[ElasticSplitter(exponents=(2.0,), measures=("dtw",),
                                              max_window=0.1)], random_state=0,
    ).fit(X, y)  # fmt: skip
    measures = _measures(squared)
    assert {m.exponent for m in measures} == {2.0}
    assert {m.warp_penalty for m in measures} == {0.0}
    assert all(0.0 <= m.window <= 0.1 for m in measures)
    amerced = RTWProximityForest(
        n_trees=4, splitters=[ElasticSplitter(measures=("adtw",), penalty_steps=1)],
        random_state=0,
    ).fit(X, y)  # fmt: skip
    assert {(m.window, m.warp_penalty) for m in _measures(amerced)} == {(None, 0.0)}


def test_a_splitter_takes_the_forests_values_where_it_sets_none():
    X, y = three_classes()
    forest = RTWProximityForest(n_trees=3, representation="velocity", n_candidates=2,
                                random_state=0).fit(X, y)  # fmt: skip
    assert len(forest.splitters_) == 2
    for resolved in forest.splitters_:
        assert (resolved.representation, resolved.n_candidates) == ("velocity", 2)
    raw = [ElasticSplitter(representation="raw")]
    own = RTWProximityForest(n_trees=3, representation="velocity", random_state=0,
                             splitters=raw).fit(X, y)  # fmt: skip
    assert own.representations_ == ("raw",)
    assert {m.representation for m in _measures(own)} == {"raw"}


@dataclass(frozen=True, eq=False)
class _LevelSplit:
    """Series whose mean value is below a threshold go left."""

    threshold: float

    @property
    def n_branches(self) -> int:
        return 2

    def route(self, series):
        raw = series["raw"]
        means = np.array([raw.data[i, : raw.lengths[i]].mean() for i in range(raw.n_series)])
        return (means >= self.threshold).astype(np.int64)


class _LevelSplitter(Splitter):
    """A kind of split written outside the package: a threshold on the series' mean,
    drawn between two of the node's series (counts its draws)."""

    def __init__(self, n_candidates=None, representation=None):
        self.n_candidates = n_candidates
        self.representation = representation

    def resolved(self, defaults):
        return _LevelSplitter(self.n_candidates or defaults["n_candidates"], "raw")

    @property
    def representations(self):
        return ("raw",)

    def draw(self, node, rng):
        raw = node.series["raw"]
        a, b = rng.choice(raw.n_series, size=2, replace=False)
        means = [raw.data[i, : raw.lengths[i]].mean() for i in (a, b)]
        _LevelSplitter.draws += 1
        return _LevelSplit(float(np.mean(means)))

    draws = 0


def test_a_new_kind_of_split_is_one_class_and_mixes_with_the_elastic_one():
    rng = np.random.default_rng(0)
    X = rng.standard_normal((30, 20)) + np.repeat([0.0, 3.0], 15)[:, None]
    y = np.repeat([0, 1], 15)
    _LevelSplitter.draws = 0
    level = RTWProximityForest(n_trees=3, splitters=[_LevelSplitter(n_candidates=4)],
                               random_state=0).fit(X, y)  # fmt: skip
    assert isinstance(level.trees_[0].root_.split, _LevelSplit)
    assert isinstance(level.trees_[0].root_.split, Split)
    assert _LevelSplitter.draws == 4 * sum(t.n_nodes_ - t.n_leaves_ for t in level.trees_)
    assert level.score(X, y) == 1.0
    mixed = RTWProximityForest(
        n_trees=4, splitters=[ElasticSplitter(n_candidates=1), _LevelSplitter(n_candidates=1)],
        random_state=0,
    ).fit(X, y)  # fmt: skip
    kinds = {type(t.root_.split).__name__ for t in mixed.trees_}
    assert kinds <= {"NearestExemplarSplit", "_LevelSplit"} and kinds
    assert mixed.score(X, y) == 1.0


@pytest.mark.parametrize("params", [{}, {"splitters": [ElasticSplitter()], "exemplars": "mean"}],
                         ids=["default", "mean exemplars"])  # fmt: skip
def test_candidates_after_a_perfect_split_are_drawn_not_routed_and_the_forest_is_the_same(
    monkeypatch, params
):
    """Once a candidate splits a node perfectly, the later ones only make their random
    draws (Splitter.skip): the forest is the one grown routing every candidate."""
    from sk_rtw.forest import ShapeletSplitter

    X, y = _bumps(n=40)
    skipped = []
    fast = RTWProximityForest(n_trees=4, random_state=3, **params)
    for kind in (ElasticSplitter, ShapeletSplitter):
        original = kind.skip

        def counted(self, node, rng, original=original):
            skipped.append(type(self).__name__)
            original(self, node, rng)

        monkeypatch.setattr(kind, "skip", counted)
    fast.fit(X, y)
    kinds = {type(s).__name__ for s in fast.splitters_}
    assert kinds <= set(skipped)  # every kind skipped some candidates
    for kind in (ElasticSplitter, ShapeletSplitter):  # the reference: route every one
        monkeypatch.setattr(kind, "skip", lambda self, node, rng: self.candidate(node, rng))
    full = RTWProximityForest(n_trees=4, random_state=3, **params).fit(X, y)
    assert [t.n_nodes_ for t in fast.trees_] == [t.n_nodes_ for t in full.trees_]
    assert [str(s) for s in _splits(fast)] == [str(s) for s in _splits(full)]
    Z, _ = _bumps(n=30, seed=1)
    np.testing.assert_array_equal(fast.predict_proba(Z), full.predict_proba(Z))


@pytest.mark.parametrize(
    ("splitters", "match"),
    [
        ("elastic", "splitters"),
        ([], "splitters"),
        ([ElasticSplitter, ElasticSplitter()], "splitters"),
        ([ElasticSplitter(exponents=(3.0,))], r"exponents.*ElasticSplitter"),
        ([ElasticSplitter(measures=("lcss",))], "measures"),
        ([ElasticSplitter(max_window=1.5)], "max_window"),
        ([ElasticSplitter(penalty_steps=0)], "penalty_steps"),
        ([ElasticSplitter(exemplars="medoid")], "exemplars"),
        ([ElasticSplitter(n_candidates=0)], "n_candidates"),
    ],
)
def test_bad_splitters_are_named(splitters, match):
    X, y = three_classes(n_per_class=3)
    with pytest.raises((ValueError, TypeError), match=match):
        RTWProximityForest(n_trees=1, splitters=splitters).fit(X, y)


def test_splitters_in_a_grid_search_and_through_clone():
    X, y = three_classes(n_per_class=6)
    grid = GridSearchCV(
        RTWProximityForest(n_trees=3, random_state=0),
        {"splitters": [None, (ElasticSplitter(exponents=(1.0,)),)]}, cv=2,
    ).fit(X, y)  # fmt: skip
    assert grid.best_score_ > 0.5
    forest = RTWProximityForest(splitters=(ElasticSplitter(max_window=0.1),))
    copy = clone(forest)
    assert copy.splitters[0] is not forest.splitters[0]
    assert copy.splitters[0].max_window == 0.1


def test_a_tree_alone_and_in_a_forest_grow_from_the_same_seed_the_same_way():
    X, y = three_classes()
    tree = ProximityTree(random_state=7).fit(X, y)
    again = ProximityTree(random_state=7).fit(X, y)
    assert tree.n_nodes_ == again.n_nodes_
    np.testing.assert_array_equal(tree.predict_proba(X), again.predict_proba(X))
    assert tree.score(X, y) == 1.0
    forest = RTWProximityForest(n_trees=2, random_state=0).fit(X, y)
    member = forest.trees_[0]
    assert member.classes_ is forest.classes_ and member.manifold_ == forest.manifold_
    np.testing.assert_array_equal(member.predict(X), y)


# ------------------------------------------------------------- shapelet splits
def test_the_best_threshold_is_the_brute_force_one():
    from sk_rtw.forest import gini_gain
    from sk_rtw.forest._shapelet import best_threshold

    rng = np.random.default_rng(0)
    for _ in range(20):
        values = rng.integers(0, 6, size=15).astype(float)
        codes = rng.integers(0, 3, size=15)
        threshold, gain = best_threshold(values, codes, 3)
        candidates = np.unique(values)
        gains = [gini_gain(codes, (values > c).astype(int), 2, 3) for c in candidates[:-1]]
        assert gain == pytest.approx(max(gains))
        assert gini_gain(codes, (values > threshold).astype(int), 2, 3) == pytest.approx(gain)
    assert np.isnan(best_threshold(np.ones(4), np.array([0, 1, 0, 1]), 2)[0])


def test_a_shapelet_split_routes_new_series_as_it_split_the_node():
    from sk_rtw.forest import (
        NodeSeries,
        SeriesSet,
        SeriesView,
        ShapeletSplit,
        ShapeletSplitter,
        TrainingSet,
    )
    from sk_rtw.utils import check_series_collection

    X, y = three_classes()
    codes = np.searchsorted(np.unique(y), y)
    collection = check_series_collection(X)
    training = TrainingSet.build(collection, ("raw", "velocity"), codes, 3)
    splitter = ShapeletSplitter().resolved({"n_candidates": 1, "representation": "auto"})
    indices = np.arange(3, 24)
    for seed in range(8):
        node = NodeSeries(training, indices, codes[indices])
        split, branches = splitter.candidate(node, np.random.default_rng(seed))
        assert isinstance(split, ShapeletSplit)
        np.testing.assert_array_equal(split.route(node.series), branches)
        again = SeriesView(SeriesSet.build(collection, ("raw", "velocity")), indices)
        np.testing.assert_array_equal(split.route(again), branches)
        assert split.shapelet.source[0] in indices  # drawn from the node's series
        assert str(split).split()[0] in ("min", "argmin", "count")


def test_shapelet_splits_find_a_local_pattern():
    """A bump at a random place marks class 1: shapelet splits alone find it, and mixed
    with the elastic ones they are kept where they split best."""
    from sk_rtw.forest import ShapeletSplitter

    X, y = _bumps()
    alone = RTWProximityForest(n_trees=20, random_state=0, splitters=[ShapeletSplitter()])
    assert alone.fit(X[:40], y[:40]).score(X[40:], y[40:]) >= 0.8
    mixed = RTWProximityForest(n_trees=20, random_state=0,
                               splitters=[ElasticSplitter(), ShapeletSplitter()])  # fmt: skip
    assert mixed.fit(X[:40], y[:40]).score(X[40:], y[40:]) >= 0.9
    kinds = {type(t.root_.split).__name__ for t in mixed.trees_}
    assert "ShapeletSplit" in kinds
    with pytest.raises(ValueError, match="lengths"):
        RTWProximityForest(n_trees=1, splitters=[ShapeletSplitter(lengths=(99,))]).fit(X, y)
    with pytest.raises(ValueError, match="features"):
        RTWProximityForest(n_trees=1, splitters=[ShapeletSplitter(features=("max",))]).fit(X, y)


def test_one_representation_vocabulary_and_both_deprecated():
    """"auto" means chosen from the training data everywhere; the forest's former
    "both" is the same draw, with a FutureWarning."""
    X, y = three_classes(n_per_class=4)
    auto = RTWProximityForest(n_trees=3, random_state=0).fit(X, y)
    assert auto.get_params()["representation"] == "auto"
    with pytest.warns(FutureWarning, match='representation="both" is now'):
        both = RTWProximityForest(n_trees=3, representation="both", random_state=0).fit(X, y)
    np.testing.assert_array_equal(both.predict_proba(X), auto.predict_proba(X))
    assert both.representations_ == auto.representations_ == ("raw", "velocity")


def test_shapelet_splits_route_series_shorter_than_their_span():
    """GesturePebbleZ1's test set holds series shorter than any training series: a
    shapelet split reads them as padded with their last point."""
    from sk_rtw.forest import ShapeletSplitter

    rng = np.random.default_rng(0)
    X = [rng.standard_normal(int(n)) + (i % 2) * 2 for i, n in enumerate(rng.integers(40, 60, 12))]
    y = np.arange(12) % 2
    raw = [ShapeletSplitter(representation="raw")]
    forest = RTWProximityForest(n_trees=4, random_state=0, splitters=raw).fit(X, y)
    short = [x[:5] for x in X]
    proba = forest.predict_proba(short)
    assert proba.shape == (12, 2) and np.allclose(proba.sum(1), 1.0)
