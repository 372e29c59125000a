"""Shapelets on Euclidean series with their windows read in place (the forest's shapelet
candidates): every piece against the numpy path it replaces, bit for bit (windows and
their z-normalisation, the percentiles, the draws, the shapelets and thresholds, the
features, the best Gini threshold), and a series routed alone as in a batch."""

from __future__ import annotations

import numpy as np
import pytest

from sk_rtw import ElasticSplitter, RTWProximityForest
from sk_rtw.dtw import linear_percentiles, numpy_column_sum, read_window
from sk_rtw.forest import ShapeletSplitter
from sk_rtw.manifolds import Euclidean
from sk_rtw.manifolds._euclidean import STD_FLOOR
from sk_rtw.representations import represent
from sk_rtw.shapelets import (
    ShapeletBank,
    draw_site,
    draw_sites,
    feature_in_place,
    features,
    gather_windows,
    reads_in_place,
    take_shapelet,
    take_shapelets,
    window_space,
)
from sk_rtw.utils import check_series_collection

from .test_dtw import random_walk


def _collection(rng, n, q, lengths=None, scale=1.0):
    lengths = lengths if lengths is not None else [int(rng.integers(30, 60)) for _ in range(n)]
    X = [rng.standard_normal((t, q)) * scale + rng.standard_normal(q) * 3 for t in lengths]
    return check_series_collection(X, Euclidean(q))


@pytest.mark.parametrize("q", [1, 3])
@pytest.mark.parametrize("normalise", [False, True])
def test_windows_read_in_place_are_numpys_gathered_windows(q, normalise):
    """One series' windows (numpy sums a contiguous axis pairwise) and a batch's (one term
    after the other), every length up to past numpy's block of 128 terms, dilations,
    a series shorter than the window's span (its padding), constant coordinates."""
    rng = np.random.default_rng(q)
    for length in [*range(1, 20), 33, 129, 300]:
        dilation = int(rng.integers(1, 4))
        span = (length - 1) * dilation + 1
        lengths = [span + int(rng.integers(0, 12)) for _ in range(3)]
        lengths[1] = max(2, span - 3)  # shorter than the span: one padded window
        collection = _collection(rng, 3, q, lengths, scale=10.0 ** rng.uniform(-3, 3))
        collection.data[2, :, 0] = 1.5  # a constant coordinate: only centred
        batch = gather_windows(collection, length, dilation, normalise)
        for i in range(3):
            alone = gather_windows(collection.subset([i]), length, dilation, normalise)
            for t in range(int(batch.counts[i])):
                for pairwise, expected in ((q == 1, alone), (False, batch)):
                    out, scratch = np.empty((length, q)), np.empty((length, q))
                    read_window(collection.data[i], t, length, dilation, normalise,
                                pairwise, STD_FLOOR, out, scratch)  # fmt: skip
                    row = 0 if expected is alone else i
                    np.testing.assert_array_equal(out, expected.points[row, t])


def test_linear_percentiles_are_numpys():
    rng = np.random.default_rng(0)
    for _ in range(300):
        n = int(rng.integers(1, 80))
        values = rng.standard_normal(n + 5) * rng.choice([1e-5, 1.0, 1e7])
        if rng.random() < 0.3:
            values = np.round(values, 1)  # ties
        percentiles = np.array([0.0, 5.0, 10.0, *rng.uniform(0, 100, 3), 99.9, 100.0])
        out = np.empty(len(percentiles))
        linear_percentiles(values, n, percentiles, out)
        np.testing.assert_array_equal(out, np.percentile(values[:n], percentiles))


def test_numpy_column_sum_is_numpys_sum():
    """Lengths across numpy's blocks of 8 and 128 and its halving above them."""
    rng = np.random.default_rng(1)
    for n in [*range(0, 40), 127, 128, 129, 255, 256, 257, 1000, 4097]:
        values = rng.standard_normal(n + 3) * rng.choice([1e-3, 1.0, 1e9], n + 3)
        assert numpy_column_sum(values.reshape(-1, 1), n, 0) == np.sum(values[:n])


def _pool_of(collections, codes, pool, representations):
    shortest = {r: int(collections[r].lengths[pool].min()) for r in representations}
    classmates = {int(c): pool[codes[pool] == c] for c in np.unique(codes[pool])}
    return shortest, classmates


def test_one_drawn_site_is_draw_sites_of_one():
    """The scalar draw takes the same numbers from the generator and computes the same
    site (numpy's log2 and power of a scalar), over nodes, lengths, classes of one."""
    rng = np.random.default_rng(0)
    collection = _collection(rng, 40, 1)
    collections = {"raw": collection, "velocity": represent(collection, "velocity")}
    codes = rng.integers(0, 4, size=40)
    codes[7] = 4  # a class of one series
    for seed in range(300):
        picker = np.random.default_rng(seed)
        pool = np.sort(picker.choice(40, int(picker.integers(2, 40)), replace=False))
        representations = ("raw", "velocity") if seed % 2 else ("velocity",)
        lengths = (3, 9, 11) if seed % 3 else (int(picker.integers(1, 20)),)
        args = (collections, codes, representations, lengths, 0.5)
        expected = draw_sites(np.random.default_rng(seed), 1, *args, candidates=pool)
        got = draw_site(np.random.default_rng(seed), *args, pool,
                        *_pool_of(collections, codes, pool, representations))  # fmt: skip
        for field in ("representation", "length", "dilation", "normalised", "series",
                      "start", "other", "uniform"):  # fmt: skip
            np.testing.assert_array_equal(getattr(got, field), getattr(expected, field))


@pytest.mark.parametrize("q", [1, 3])
def test_shapelets_taken_in_place_and_their_features_are_the_numpy_ones(q):
    """Points, threshold and every feature of a node's series, for raw and velocity
    shapelets, normalised or not, unequal lengths: bit for bit the numpy path's."""
    rng = np.random.default_rng(10 + q)
    collection = _collection(rng, 30, q)
    collections = {"raw": collection, "velocity": represent(collection, "velocity")}
    assert all(reads_in_place(c.manifold) for c in collections.values())
    codes = rng.integers(0, 3, size=30)
    representations = ("raw", "velocity")
    pool = np.arange(30)
    for seed in range(60):
        sites = draw_sites(np.random.default_rng(seed), 1, collections, codes,
                           representations, (4, 11, 20), 0.5, candidates=pool)  # fmt: skip
        (expected,) = take_shapelets(sites, collections, codes, representations, (5.0, 10.0))
        name = representations[int(sites.representation[0])]
        got = take_shapelet(collections[name], name, sites, 0, codes, (5.0, 10.0))
        np.testing.assert_array_equal(got.points, expected.points)
        assert got.threshold == expected.threshold
        assert (got.source, got.label, got.group) == (
            expected.source, expected.label, expected.group)  # fmt: skip
        space = window_space(collections[name].manifold, got.normalised)
        bank = ShapeletBank.build([got], lambda r, normal, space=space: space)
        rows = np.sort(np.random.default_rng(seed).choice(30, 12, replace=False))
        reference = features({name: collections[name].subset(rows)}, bank)[:, 0]
        for k, feature in enumerate(("min", "argmin", "count")):
            values = feature_in_place(collections[name], rows, got, feature)
            np.testing.assert_array_equal(values, reference[:, k])
            # a series alone gets its value in the batch
            alone = feature_in_place(collections[name], rows[:1], got, feature)
            assert alone[0] == values[0]


def _numpy_best_threshold(values, codes, n_classes):
    """The split threshold as numpy computes it (the reference the kernel replaced)."""
    order = np.argsort(values, kind="stable")
    ordered, labels = values[order], codes[order]
    n = len(values)
    cuts = np.flatnonzero(ordered[1:] > ordered[:-1])
    if len(cuts) == 0:
        return float("nan"), 0.0
    counts = np.bincount(labels, minlength=n_classes)
    left = np.cumsum(np.eye(n_classes)[labels], axis=0)[cuts]
    right = counts - left
    n_left = cuts + 1.0
    n_right = n - n_left
    total = counts / n
    parent = 1.0 - total @ total
    impurity = (n_left - (left**2).sum(1) / n_left) + (n_right - (right**2).sum(1) / n_right)
    gains = parent - impurity / n
    best = int(np.argmax(gains))
    return float(0.5 * (ordered[cuts[best]] + ordered[cuts[best] + 1])), float(gains[best])


def test_the_compiled_best_threshold_is_numpys_bit_for_bit():
    from sk_rtw.forest._gini import best_threshold

    rng = np.random.default_rng(0)
    for _ in range(400):
        n, n_classes = int(rng.integers(2, 200)), int(rng.integers(2, 30))
        values = rng.standard_normal(n)
        if rng.random() < 0.5:
            values = np.round(values * 3)  # ties, equal gains
        codes = rng.integers(0, n_classes, size=n)
        got = best_threshold(values, codes, n_classes)
        expected = _numpy_best_threshold(values, codes, n_classes)
        assert got == expected or (np.isnan(got[0]) and np.isnan(expected[0]))


@pytest.mark.parametrize("manifold", ["euclidean", "quaternion"])
def test_a_series_routes_the_same_alone_as_in_a_batch(manifold):
    """Shapelet splits read in place (raw R^1, the velocity of S^3) give each series the
    class probabilities alone that it gets with the others."""
    rng = np.random.default_rng(3)
    if manifold == "euclidean":
        X = rng.standard_normal((40, 50)).cumsum(1)
    else:
        from sk_rtw import Quaternion

        X = np.stack([random_walk(Quaternion(), 40, s, step=0.3) for s in range(40)])
    y = np.arange(40) % 2
    forest = RTWProximityForest(manifold, n_trees=6, random_state=0,
                                splitters=[ElasticSplitter(), ShapeletSplitter()])  # fmt: skip
    forest.fit(X[:30], y[:30])
    batch = forest.predict_proba(X[30:])
    alone = np.concatenate([forest.predict_proba(X[i : i + 1]) for i in range(30, 40)])
    np.testing.assert_array_equal(alone, batch)
