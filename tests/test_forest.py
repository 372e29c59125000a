"""RTWProximityForest: scikit-learn conformance, determinism across threads, its splits
against brute force, manifold-valued and unequal-length series, clear errors."""

from __future__ import annotations

import pickle

import numpy as np
import pytest
from sklearn.base import clone
from sklearn.model_selection import GridSearchCV
from sklearn.pipeline import Pipeline
from sklearn.preprocessing import FunctionTransformer
from sklearn.utils.estimator_checks import parametrize_with_checks

from sk_rtw import RTWProximityForest, tangent_velocity
from sk_rtw.dtw import mean_diagonal_cost, nearest_group, prepare_series
from sk_rtw.dtw._kernels import sakoe_chiba_rows
from sk_rtw.forest import (
    ElasticSplitter,
    Measure,
    NearestExemplarSplit,
    NodeSeries,
    ShapeletSplitter,
    TrainingSet,
    gini,
    gini_gain,
)
from sk_rtw.forest._tree import best_split, split_node
from sk_rtw.manifolds import SPD, Product, Quaternion, Sphere
from sk_rtw.representations import represent
from sk_rtw.utils import check_series_collection

from .conftest import rlasa_in_own_frames
from .test_dtw import random_walk
from .test_estimators import EXPECTED_FAILURES, two_shape_classes, znorm


def _expected_failures(estimator):
    return EXPECTED_FAILURES


@parametrize_with_checks(
    [RTWProximityForest(n_trees=3, random_state=0)], expected_failed_checks=_expected_failures
)
def test_sklearn_compatible(estimator, check):
    check(estimator)


def tree_splits(tree):
    """Every split of ``tree``, from the root down."""
    out, stack = [], [tree.root_]
    while stack:
        node = stack.pop()
        if node.split is not None:
            out.append(node.split)
            stack.extend(node.children)
    return out


def three_classes(n_per_class=8, length=30, seed=0):
    """Univariate three-class data: warped sine, bump and ramp shapes with noise."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 1, length)
    shapes = (
        lambda u: np.sin(2 * np.pi * u),
        lambda u: np.exp(-((u - 0.5) ** 2) / 0.01),
        lambda u: 2 * u - 1,
    )
    X, y = [], []
    for label, shape in enumerate(shapes):
        for _ in range(n_per_class):
            X.append(shape(t ** np.exp(rng.normal(0, 0.3))) + 0.1 * rng.standard_normal(length))
            y.append(f"c{label}")
    return np.array(X), np.array(y)


def test_the_same_seed_gives_the_same_forest_for_any_n_jobs():
    X, y = three_classes()
    one = RTWProximityForest(n_trees=12, random_state=3, n_jobs=1).fit(X, y)
    two = RTWProximityForest(n_trees=12, random_state=3, n_jobs=2).fit(X, y)
    test, _ = three_classes(seed=5)
    np.testing.assert_array_equal(one.predict_proba(test), two.predict_proba(test))
    for a, b in zip(one.trees_, two.trees_, strict=True):
        assert a.n_nodes_ == b.n_nodes_ and a.root_.split.measure == b.root_.split.measure
    other = RTWProximityForest(n_trees=12, random_state=4).fit(X, y)
    assert [t.root_.split.measure for t in other.trees_] != [
        t.root_.split.measure for t in one.trees_
    ]


def test_training_series_reach_their_own_pure_leaves():
    """Prediction retraces the splits of the fit: every training series reaches the leaf
    it was grown into, and every leaf is pure, so each tree classifies the training set
    perfectly."""
    X, y = three_classes()
    forest = RTWProximityForest(n_trees=5, random_state=0).fit(X, y)
    codes = np.searchsorted(forest.classes_, y)
    for tree in forest.trees_:
        np.testing.assert_array_equal(tree.predict_proba(X), np.eye(3)[codes])
        np.testing.assert_array_equal(tree.predict(X), y)
    assert forest.score(X, y) == 1.0


def test_predict_proba_is_the_mean_of_the_trees_leaves():
    X, y = three_classes()
    test, test_y = three_classes(seed=9)
    forest = RTWProximityForest(n_trees=7, random_state=1).fit(X, y)
    votes = np.mean([tree.predict_proba(test) for tree in forest.trees_], 0)
    np.testing.assert_allclose(forest.predict_proba(test), votes, atol=1e-15)
    np.testing.assert_allclose(forest.predict_proba(test).sum(1), 1.0)
    assert np.array_equal(forest.predict(test), forest.classes_[votes.argmax(1)])
    assert forest.score(test, test_y) >= 0.9


def reference_adtw(x, y, manifold, penalty, window, exponent):
    """Textbook amerced DTW in a Sakoe-Chiba band, point cost the distance to
    ``exponent``, with Python loops (the band from the package's own row ranges)."""
    nx, ny = len(x), len(y)
    lo, hi = sakoe_chiba_rows(nx, ny, -1.0 if window is None else window)
    D = np.full((nx + 1, ny + 1), np.inf)
    D[0, 0] = 0.0
    for i in range(nx):
        for j in range(lo[i], hi[i]):
            c = float(manifold.dist(x[i], y[j])) ** exponent
            D[i + 1, j + 1] = c + min(D[i, j], D[i, j + 1] + penalty, D[i + 1, j] + penalty)
    return D[nx, ny]


def _brute_force_branches(series, exemplars, measure, manifold):
    def distance(x, y):
        return reference_adtw(x, y, manifold, measure.warp_penalty, measure.window,
                              measure.exponent)  # fmt: skip

    return np.array([[distance(s, e) for e in exemplars] for s in series]).argmin(1)


@pytest.mark.parametrize("manifold", [Sphere(2), SPD(2), Product((Sphere(1), SPD(2)))], ids=repr)
def test_every_candidate_sends_each_series_to_its_nearest_exemplar(manifold):
    """The branches of the kept split are the brute-force argmin of the drawn measure's
    distances (manifold DTW of the drawn representation), for every representation."""
    X = np.stack([random_walk(manifold, 12, s, step=0.3) for s in range(14)])
    codes = np.repeat([0, 1], 7)
    training = TrainingSet.build(check_series_collection(X, manifold), ("raw", "velocity"),
                                 codes, 2)  # fmt: skip
    splitters = (ElasticSplitter().resolved(
        {"n_candidates": 3, "representation": "auto", "exemplars": "series"}),)  # fmt: skip
    indices = np.arange(2, 14)
    for seed in range(6):
        node = NodeSeries(training, indices, codes[indices])
        split, gain, branches = best_split(node, splitters, np.random.default_rng(seed))
        measure = split.measure
        space = training.collections[measure.representation]
        expected = _brute_force_branches(
            [space.series(i) for i in indices],
            [space.series(i) for i in split.sources],
            measure, space.manifold,
        )  # fmt: skip
        np.testing.assert_array_equal(branches, expected)
        assert gain == pytest.approx(gini_gain(codes[indices], branches, 2, 2))
        assert set(codes[split.sources]) == {0, 1}  # one exemplar of each class
        # the split routes any series by the exemplars it holds: the same branches
        rest = {r: training.prepared[r].take(indices) for r in ("raw", "velocity")}
        np.testing.assert_array_equal(split.route(rest), branches)


def test_gini_and_its_gain_by_hand():
    codes = np.array([0, 0, 1, 1, 1, 2])
    assert gini(codes, 3) == pytest.approx(1 - (4 + 9 + 1) / 36)
    branches = np.array([0, 0, 1, 1, 1, 1])  # a pure branch and one of (1, 1, 1, 2)
    children = (4 / 6) * (1 - (9 + 1) / 16)
    assert gini_gain(codes, branches, 2, 3) == pytest.approx(gini(codes, 3) - children)
    assert gini_gain(codes, np.zeros(6, dtype=int), 2, 3) == pytest.approx(0.0)


def _numpy_gini_gain(codes, branches, n_branches, n_classes):
    """The gain as first written, in numpy: what the compiled one must equal bit for bit
    (a different last bit can change which candidate of equal gains a node keeps)."""
    table = np.zeros((n_branches, n_classes))
    np.add.at(table, (branches, codes), 1.0)
    sizes = table.sum(1)
    filled = sizes > 0
    children = sizes[filled] - (table[filled] ** 2).sum(1) / sizes[filled]
    return gini(codes, n_classes) - float(children.sum()) / len(codes)


@pytest.mark.parametrize("n_branches", [2, 3, 7, 8, 9, 17, 24, 60, 130, 300])
def test_the_compiled_gini_gain_is_the_numpy_formula_bit_for_bit(n_branches):
    rng = np.random.default_rng(n_branches)
    for n in (1, 2, 5, 40, 333, 4000):
        n_classes = int(rng.integers(2, n_branches + 2))
        codes = rng.integers(0, n_classes, n)
        branches = rng.integers(0, min(n_branches, int(rng.integers(1, n_branches + 1))), n)
        expected = _numpy_gini_gain(codes, branches, n_branches, n_classes)
        assert gini_gain(codes, branches, n_branches, n_classes) == expected
        impurity = gini(codes, n_classes)
        assert gini_gain(codes, branches, n_branches, n_classes, impurity) == expected


def test_a_gini_gain_of_branches_out_of_range_is_a_clear_error():
    codes = np.array([0, 1, 1, 0])
    with pytest.raises(ValueError, match=r"branch outside 0\.\.1"):
        gini_gain(codes, np.array([0, 2, 1, 0]), 2, 2)
    with pytest.raises(ValueError, match="class code outside"):
        gini_gain(np.array([0, 1, 3, 0]), np.array([0, 1, 1, 0]), 2, 2)
    with pytest.raises(ValueError, match="3 branches for 4 class codes"):
        gini_gain(codes, np.array([0, 1, 1]), 2, 2)


def test_the_penalty_scale_is_the_mean_direct_alignment_cost(rng):
    X = [rng.standard_normal(n) for n in (20, 20, 26)]
    prepared = prepare_series(check_series_collection(X))
    got = mean_diagonal_cost(prepared, np.array([0, 2]), np.array([1, 0]), 2.0)
    t = np.arange(26)
    unequal = ((X[2] - X[0][t * 20 // 26]) ** 2).sum()  # the longer series steps
    assert got == pytest.approx((((X[0] - X[1]) ** 2).sum() + unequal) / 2, rel=1e-12)
    # the same on a manifold without compiled costs (its own distance)
    M = Product((Sphere(2), SPD(13)))
    Y = [random_walk(M, n, s) for s, n in enumerate((5, 7))]
    prepared = prepare_series(check_series_collection(Y, M))
    assert prepared.segments is None
    step = np.arange(7) * 5 // 7
    assert mean_diagonal_cost(prepared, np.array([0]), np.array([1]), 1.0) == pytest.approx(
        float(M.dist(Y[0][step], Y[1]).sum()), rel=1e-12
    )
    root = mean_diagonal_cost(prepare_series(check_series_collection(X)), np.array([0]),
                              np.array([1]), 0.5)  # fmt: skip
    assert root == pytest.approx(np.sqrt(np.abs(X[0] - X[1])).sum(), rel=1e-12)


def test_nearest_group_on_a_manifold_without_compiled_costs_matches_the_kernels():
    M = Product((Sphere(2), SPD(13)))
    X = np.stack([random_walk(M, 6, s) for s in range(5)])
    prepared = prepare_series(check_series_collection(X, M))
    for exponent in (0.5, 1.0, 2.0):
        got = nearest_group(prepared.take([0, 1, 2]), prepared.take([3, 4]), np.array([0, 1]),
                            2, 0.2, exponent, 0.1)  # fmt: skip
        expected = _brute_force_branches(X[:3], X[3:], Measure("raw", 0.2, exponent, 0.1), M)
        np.testing.assert_array_equal(got, expected)


@pytest.mark.parametrize(
    ("manifold", "step"), [(Quaternion(), 0.2), (SPD(2), 0.3), (Sphere(2), 0.2)], ids=repr
)
def test_manifold_valued_and_unequal_length_series(manifold, step):
    """Two classes of random walks whose steps differ in size: the velocity tells them
    apart; lists of unequal lengths are accepted at fit and prediction."""
    rng = np.random.default_rng(0)
    X = [random_walk(manifold, int(rng.integers(15, 25)), s, step=step * (1 + (s % 2)))
         for s in range(16)]  # fmt: skip
    y = np.arange(16) % 2
    forest = RTWProximityForest(manifold, n_trees=10, random_state=0).fit(X[:12], y[:12])
    assert forest.manifold_ == manifold
    assert forest.predict_proba(X[12:]).shape == (4, 2)
    assert forest.score(X[:12], y[:12]) == 1.0


def test_multivariate_euclidean_series_and_the_velocity_alone():
    X, y = three_classes()
    X3 = np.stack([X, X**2, -X], axis=-1)
    forest = RTWProximityForest(n_trees=5, representation="velocity", random_state=0)
    forest.fit(X3, y)
    assert forest.representations_ == ("velocity",)
    assert {t.root_.split.measure.representation for t in forest.trees_} == {"velocity"}
    raw = RTWProximityForest(n_trees=5, representation="raw", random_state=0).fit(X3, y)
    assert {t.root_.split.measure.representation for t in raw.trees_} == {"raw"}


def test_a_split_holds_its_exemplar_series_not_the_training_set():
    X, y = three_classes()
    forest = RTWProximityForest(n_trees=3, representation="raw", random_state=2).fit(X, y)
    root = forest.trees_[0].root_
    classes = forest.classes_[root.split.classes]
    assert list(y[root.split.sources]) == list(classes)
    np.testing.assert_array_equal(root.split.exemplars.data[..., 0], X[root.split.sources])
    assert len(root.children) == len(classes) == 3
    assert str(root.split.measure).startswith(("DTW", "ADTW"))
    assert not [name for name in vars(forest) if "train" in name]


def test_a_forest_keeps_the_exemplars_of_its_splits_and_no_other_candidates():
    """Every tree's store holds exactly the training series its elastic splits hold (not
    the exemplars of candidates drawn and dropped), and the forest's shared array is
    their union."""
    X, y = three_classes(n_per_class=10)
    forest = RTWProximityForest(n_trees=4, random_state=0).fit(X, y)
    union = set()
    for tree in forest.trees_:
        held = {r: set() for r in tree._stores}
        for split in tree_splits(tree):
            if hasattr(split, "sources"):
                held[split.measure.representation].update(split.sources.tolist())
        for representation, store in tree._stores.items():
            assert set(store.used.tolist()) == held[representation]
            union |= {(representation, r) for r in held[representation]}
    assert union  # elastic splits were kept
    shared = {(r, int(row)) for r in forest.trees_[0]._stores
              for row in forest.trees_[0]._stores[r]._rows}  # fmt: skip
    assert shared == {(r, row) for r, row in union if r in forest.trees_[0]._stores}


def test_mean_exemplars_are_averages_with_randomness_of_their_own():
    X, y = three_classes(n_per_class=9)
    forest = RTWProximityForest(n_trees=4, exemplars="mean", random_state=0).fit(X, y)
    root = forest.trees_[0].root_
    assert (root.split.sources == -1).all()  # 9 series per class: subsets of 3 averaged
    assert root.split.exemplars.n_series == 3
    again = RTWProximityForest(n_trees=4, exemplars="mean", random_state=0).fit(X, y)
    np.testing.assert_array_equal(forest.predict_proba(X), again.predict_proba(X))
    assert forest.score(X, y) == 1.0


def test_max_depth_stops_the_trees():
    X, y = three_classes()
    forest = RTWProximityForest(n_trees=4, max_depth=1, random_state=0).fit(X, y)
    assert max(tree.depth_ for tree in forest.trees_) == 1
    assert np.allclose(forest.predict_proba(X).sum(1), 1.0)


def test_a_scoring_sample_of_the_node_or_more_grows_the_same_forest():
    """Nodes no larger than ``scoring_sample`` draw nothing more: the forest is the one
    every series scores (None) bit for bit (a sample of 24 leaves the 24-series root
    alone; of 23 not)."""
    X, y = three_classes()
    test, _ = three_classes(seed=5)
    default = RTWProximityForest(n_trees=6, random_state=2, scoring_sample=None).fit(X, y)
    same = RTWProximityForest(n_trees=6, random_state=2, scoring_sample=24).fit(X, y)

    def splits(forest):
        return [(str(s), getattr(s, "sources", np.zeros(0)).tolist())
                for tree in forest.trees_ for s in tree_splits(tree)]  # fmt: skip

    np.testing.assert_array_equal(same.predict_proba(test), default.predict_proba(test))
    assert splits(same) == splits(default)
    sampled = RTWProximityForest(n_trees=6, random_state=2, scoring_sample=23).fit(X, y)
    assert splits(sampled) != splits(default)


def test_a_large_node_keeps_the_best_candidate_of_its_sample_and_routes_every_series():
    """Above ``scoring_sample`` series, the node's split is :func:`best_split` of a
    uniform sample of that many (drawn first, from the same generator), and that split
    routes every series of the node; its gain is the Gini gain over the whole node."""
    X, _ = three_classes(n_per_class=12)
    codes = np.repeat([0, 1, 2], 12)
    training = TrainingSet.build(check_series_collection(X, "euclidean"), ("raw", "velocity"),
                                 codes, 3)  # fmt: skip
    splitters = tuple(s.resolved({"n_candidates": 3, "representation": "auto",
                                  "exemplars": "series"})
                      for s in (ElasticSplitter(), ShapeletSplitter()))  # fmt: skip
    indices = np.arange(1, 36)
    for seed in range(4):
        node = NodeSeries(training, indices, codes[indices])
        split, gain, branches = split_node(node, splitters, np.random.default_rng(seed), 10)
        rng = np.random.default_rng(seed)
        picked = rng.choice(len(indices), size=10, replace=False)
        assert set(codes[indices[picked]]) == {0, 1, 2}  # no class to add: the draw alone
        picked = np.sort(picked)
        sample = NodeSeries(training, indices[picked], codes[indices[picked]])
        expected, _, _ = best_split(sample, splitters, rng)
        assert type(split) is type(expected) and str(split) == str(expected)
        if isinstance(split, NearestExemplarSplit):
            assert set(split.sources) <= set(indices[picked])  # exemplars from the sample
            np.testing.assert_array_equal(split.sources, expected.sources)
        rest = {r: training.prepared[r].take(indices) for r in ("raw", "velocity")}
        np.testing.assert_array_equal(branches, split.route(rest))
        assert len(branches) == len(indices)
        assert gain == gini_gain(codes[indices], branches, split.n_branches, 3)
        # nodes of at most the sample size: the plain best split, the same draws
        small = NodeSeries(training, indices[:10], codes[indices[:10]])
        plain = best_split(small, splitters, np.random.default_rng(seed))
        kept = split_node(small, splitters, np.random.default_rng(seed), 10)
        assert str(kept[0]) == str(plain[0]) and kept[1] == plain[1]


def test_a_class_the_sample_misses_is_added_to_it_and_told_apart():
    """One series of a second class among 40: a sample of 8 seldom draws it, so one of
    its series joins every sample that misses it, and every tree still separates the
    training set into pure leaves (without that, most trees would stop at the root)."""
    rng = np.random.default_rng(0)
    X = rng.standard_normal((41, 20)).cumsum(1)
    y = np.array([0] * 40 + [1])
    forest = RTWProximityForest(n_trees=10, random_state=0, scoring_sample=8).fit(X, y)
    assert all(tree.n_nodes_ > 1 for tree in forest.trees_)
    for tree in forest.trees_:
        np.testing.assert_array_equal(tree.predict(X), y)
    training = TrainingSet.build(check_series_collection(X, "euclidean"), ("raw", "velocity"),
                                 y, 2)  # fmt: skip
    splitters = (ElasticSplitter().resolved(
        {"n_candidates": 2, "representation": "auto", "exemplars": "series"}),)  # fmt: skip
    node = NodeSeries(training, np.arange(41), y)
    for seed in range(5):
        split, _, branches = split_node(node, splitters, np.random.default_rng(seed), 8)
        assert split.n_branches == 2 and 40 in split.sources  # the rare class's exemplar
        assert branches[40] == np.flatnonzero(split.classes == 1)[0]


def test_series_no_measure_tells_apart_make_a_leaf():
    """Identical series of two classes: every exemplar ties with the other class's, so
    the node cannot be split and keeps both classes' proportions."""
    X = np.tile(np.linspace(0, 1, 10), (6, 1))
    y = [0, 1, 0, 1, 0, 1]
    forest = RTWProximityForest(n_trees=3, random_state=0).fit(X, y)
    assert all(tree.n_nodes_ == 1 for tree in forest.trees_)
    np.testing.assert_allclose(forest.predict_proba(X[:2]), 0.5)


def test_pipeline_gridsearch_clone_pickle():
    X, y = two_shape_classes()
    pipe = Pipeline([("scale", FunctionTransformer(znorm)),
                     ("forest", RTWProximityForest(n_trees=5, random_state=0))])  # fmt: skip
    assert pipe.fit(X, y).score(X, y) == 1.0
    grid = GridSearchCV(RTWProximityForest(n_trees=3, random_state=0),
                        {"representation": ["raw", "velocity"], "n_candidates": [1, 3]}, cv=2)
    grid.fit(X, y)  # fmt: skip
    assert grid.best_params_["representation"] in ("raw", "velocity")
    forest = RTWProximityForest(n_trees=4, random_state=0).fit(X, y)
    clone(forest)
    restored = pickle.loads(pickle.dumps(forest))
    np.testing.assert_array_equal(restored.predict_proba(X), forest.predict_proba(X))


def test_random_states_of_every_accepted_type():
    X, y = three_classes(n_per_class=4)
    for state in (np.random.RandomState(0), np.random.default_rng(0), None, 7):
        RTWProximityForest(n_trees=2, random_state=state).fit(X, y)


def test_verbose_reports_every_tree(capsys):
    X, y = three_classes(n_per_class=4)
    RTWProximityForest(n_trees=3, verbose=1, random_state=0).fit(X, y)
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 3 and "tree 3/3" in lines[-1] and "nodes" in lines[-1]


@pytest.mark.parametrize(
    ("params", "match"),
    [
        ({"n_trees": 0}, "n_trees"),
        ({"n_candidates": 1.5}, "n_candidates"),
        ({"representation": "derivative"}, "representation"),
        ({"exemplars": "medoid"}, "exemplars"),
        ({"max_depth": 0}, "max_depth"),
        ({"scoring_sample": 1}, "scoring_sample"),
        ({"scoring_sample": 10.5}, "scoring_sample"),
        ({"n_jobs": 0}, "n_jobs"),
        ({"random_state": "a"}, "random_state"),
    ],
)
def test_bad_parameters_are_named(params, match):
    X, y = three_classes(n_per_class=3)
    with pytest.raises((ValueError, TypeError), match=match):
        RTWProximityForest(**params).fit(X, y)


def test_bad_data_get_clear_errors():
    X, y = three_classes(n_per_class=3)
    with pytest.raises(ValueError, match="2 classes"):
        RTWProximityForest().fit(X, ["a"] * len(X))
    with pytest.raises(ValueError, match="time points"):
        RTWProximityForest().fit([np.arange(5.0), np.array([1.0])], [0, 1])
    RTWProximityForest(n_trees=2, representation="raw").fit(
        [np.arange(5.0), np.array([1.0])], [0, 1]
    )  # one sample is a series when only the raw series are compared
    with pytest.raises(ValueError, match="NaN"):
        RTWProximityForest().fit(np.where(X > 0.5, np.nan, X), y)
    with pytest.raises(ValueError, match="not a point"):
        RTWProximityForest("sphere").fit(np.ones((4, 6, 3)), [0, 1, 0, 1])
    forest = RTWProximityForest(n_trees=2, random_state=0).fit(X, y)
    with pytest.raises(ValueError, match=r"expected|shape"):
        forest.predict(np.ones((2, 5, 3)))


def test_the_velocity_representation_is_the_tangent_velocity():
    X, _ = three_classes(n_per_class=2)
    collection = check_series_collection(X)
    np.testing.assert_array_equal(represent(collection, "velocity").data[..., 0],
                                  tangent_velocity(X))  # fmt: skip


def test_pickled_nodes_and_splits_keep_their_values_and_types():
    """Nodes, measures and elastic splits pickle in a compact form of their own and come
    back equal, arrays of the same dtype (series and mean exemplars)."""
    X, y = three_classes(n_per_class=4)
    for exemplars in ("series", "mean"):
        forest = RTWProximityForest(n_trees=3, exemplars=exemplars, random_state=0).fit(X, y)
        restored = pickle.loads(pickle.dumps(forest))
        pairs = [(a.root_, b.root_) for a, b in zip(forest.trees_, restored.trees_, strict=True)]
        while pairs:
            node, copy = pairs.pop()
            assert copy.distribution.dtype == np.float64
            np.testing.assert_array_equal(copy.distribution, node.distribution)
            assert (copy.n_series, copy.depth, copy.gain) == (node.n_series, node.depth,
                                                              node.gain)  # fmt: skip
            assert (copy.split is None) == (node.split is None)
            if node.split is not None:
                assert copy.split.measure == node.split.measure
                for name in ("classes", "sources"):
                    assert getattr(copy.split, name).dtype == np.int64
                    np.testing.assert_array_equal(getattr(copy.split, name),
                                                  getattr(node.split, name))  # fmt: skip
                np.testing.assert_array_equal(copy.split.exemplars.data,
                                              node.split.exemplars.data)  # fmt: skip
            pairs += list(zip(node.children, copy.children, strict=True))
        np.testing.assert_array_equal(restored.predict_proba(X), forest.predict_proba(X))


def test_the_exemplar_draw_is_one_uniform_draw_per_class_in_turn():
    """The splitter draws every class's exemplar in one call (``rng.integers`` of the class
    sizes): the same numbers, in the same order, as one draw per class (the forest's
    results rest on it), each exemplar a series of its class of the node."""
    for seed in range(200):
        sizes = np.random.default_rng(seed).integers(1, (3, 40, 5000, 2**33)[seed % 4],
                                                     size=1 + seed % 25)  # fmt: skip
        one_call = np.random.default_rng(seed + 1000)
        in_turn = np.random.default_rng(seed + 1000)
        assert one_call.integers(sizes).tolist() == [int(in_turn.integers(n)) for n in sizes]
        assert one_call.random() == in_turn.random()  # the stream goes on the same
    X, y = three_classes(n_per_class=9)
    codes = np.unique(y, return_inverse=True)[1]
    training = TrainingSet.build(check_series_collection(X), ("raw",), codes, 3)
    splitter = ElasticSplitter().resolved(
        {"n_candidates": 1, "representation": "raw", "exemplars": "series"})  # fmt: skip
    indices = np.array([0, 2, 3, 9, 10, 11, 14, 20, 26])
    members = NodeSeries(training, indices, codes[indices]).members
    for seed in range(20):
        split = splitter.draw(NodeSeries(training, indices, codes[indices]),
                              np.random.default_rng(seed))  # fmt: skip
        rng = np.random.default_rng(seed)  # the measure's draws, then one per class
        splitter.draw_measure(NodeSeries(training, indices, codes[indices]), rng)
        assert split.sources.tolist() == [m[rng.integers(len(m))] for m in members]
        assert [codes[s] for s in split.sources] == [0, 1, 2]


@pytest.mark.parametrize("space", ["quaternion", "spd"])
def test_rlasa_demonstrations_in_their_own_frames_get_the_same_velocity_forest(space):
    """R-LASA handwriting (8 shapes, leave demonstration 0 out), every demonstration in a
    world frame of its own (a rotation and sign per quaternion series, a congruence by a
    rotation per SPD series): the forest on the tangent velocity (body frame; the SPD
    step in the eigenbasis of each point) predicts the same classes, and fitted on the
    moved demonstrations it gives the same probabilities. The SPD velocity in world axes
    does not: its forest changes its predictions."""
    demos, shapes, moved = rlasa_in_own_frames(space, every=4)
    X_train = demos[:, 1:].reshape(-1, *demos.shape[2:])
    y_train = np.repeat(shapes, 3)
    forest = RTWProximityForest(space, representation="velocity", n_trees=10, random_state=0)
    forest.fit(X_train, y_train)
    assert forest.score(demos[:, 0], shapes) >= 0.75
    np.testing.assert_array_equal(forest.predict(moved[:, 0]), forest.predict(demos[:, 0]))
    refit = clone(forest).fit(moved[:, 1:].reshape(-1, *demos.shape[2:]), y_train)
    np.testing.assert_allclose(refit.predict_proba(moved[:, 0]),
                               forest.predict_proba(demos[:, 0]), atol=1e-12)  # fmt: skip
    if space == "spd":
        world = clone(forest).set_params(manifold=SPD(2, velocity_frame="world"))
        world.fit(X_train, y_train)
        assert not np.allclose(world.predict_proba(moved[:, 0]), world.predict_proba(demos[:, 0]))


def _rlasa_accuracy(forest, demos, shapes):
    """Leave one demonstration out over the four folds: the fraction of test series
    classified right."""
    hits = 0
    for fold in range(demos.shape[1]):
        train = [d for d in range(demos.shape[1]) if d != fold]
        fitted = clone(forest).fit(demos[:, train].reshape(-1, *demos.shape[2:]),
                                   np.repeat(shapes, len(train)))  # fmt: skip
        hits += int((fitted.predict(demos[:, fold]) == shapes).sum())
    return hits / (demos.shape[1] * len(shapes))


@pytest.mark.parametrize("space", ["quaternion", "spd"])
def test_the_default_forest_holds_on_rlasa_demonstrations_in_their_own_frames(space):
    """R-LASA (10 shapes, 4 folds), every demonstration in a world frame of its own: the
    default forest (series and velocity drawn) loses at most two test series of 40; with
    the SPD velocity in world axes it falls by more than a fifth (what it did before)."""
    demos, shapes, moved = rlasa_in_own_frames(space, every=3)
    forest = RTWProximityForest(space, n_trees=20, random_state=0)
    same = _rlasa_accuracy(forest, demos, shapes)
    assert same >= 0.9
    assert _rlasa_accuracy(forest, moved, shapes) >= same - 0.05
    if space == "spd":
        world = forest.set_params(manifold=SPD(2, velocity_frame="world"))
        assert _rlasa_accuracy(world, moved, shapes) < _rlasa_accuracy(world, demos, shapes) - 0.2
