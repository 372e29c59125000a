"""DTW against many references in SIMD lanes: the one-pair kernel's values bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from sk_rtw.dtw import _dtw, _lanes, _point_costs, _pruned, dtw_distance, dtw_pairwise_distance
from sk_rtw.manifolds import Euclidean, Product
from sk_rtw.utils import check_series_collection


def one_pair_kernel(X, Y, manifold, window, squared):
    """Every pair by :func:`_pruned.pairwise_segments`, the kernel the lanes replace."""
    cx = check_series_collection(X, manifold)
    symmetric = Y is None
    cy = cx if symmetric else check_series_collection(Y, cx.manifold)
    return _pruned.pairwise_segments(
        _point_costs.kernel_series(cx), cx.lengths, _point_costs.kernel_series(cy), cy.lengths,
        _point_costs.segment_codes(cx.manifold), squared, _dtw.check_window(window), symmetric,
        np.full((cx.n_series, cy.n_series), np.inf), 0.0,
    )  # fmt: skip


@pytest.fixture
def lane_calls(monkeypatch):
    """Counts the blocks the lane kernels get, so a test knows the lanes ran."""
    counts = {"blocks": 0}
    for name in ("pairwise_wide", "pairwise_narrow"):
        kernel = getattr(_lanes, name)

        def counted(*args, kernel=kernel):
            counts["blocks"] += len(args[7])
            return kernel(*args)

        monkeypatch.setattr(_lanes, name, counted)
    return counts


def series(rng, n, lengths, dim, scale=1.0):
    """``n`` random walks of lengths drawn from ``lengths``, (T,) or (T, dim) each."""
    shape = () if dim == 1 else (dim,)
    return [
        np.cumsum(rng.standard_normal((int(rng.choice(lengths)), *shape)), axis=0) * scale
        for _ in range(n)
    ]


# 45 references of one length: a wide block, a narrow one and a padded narrow one
@pytest.mark.parametrize("dim", [1, 3])
@pytest.mark.parametrize("window", [None, 0.0, 0.1, 0.5])
@pytest.mark.parametrize("squared", [False, True])
def test_lanes_equal_the_one_pair_kernel(dim, window, squared, rng, lane_calls):
    X, Y = series(rng, 7, [40], dim), series(rng, 45, [40], dim)
    manifold = Euclidean(dim)
    got = dtw_pairwise_distance(X, Y, manifold, window=window, squared=squared)
    assert np.array_equal(got, one_pair_kernel(X, Y, manifold, window, squared))
    # the symmetric matrix: blocks that straddle the diagonal
    got = dtw_pairwise_distance(Y, manifold=manifold, window=window, squared=squared)
    assert np.array_equal(got, one_pair_kernel(Y, None, manifold, window, squared))
    assert np.all(np.diag(got) == 0.0) and np.array_equal(got, got.T)
    assert lane_calls["blocks"] > 0


@pytest.mark.parametrize("symmetric", [False, True])
def test_unequal_lengths_mix_lanes_and_single_pairs(symmetric, rng, lane_calls):
    # lengths shared by 40, 9, 3, 2 and 1 series: wide, narrow and one-pair references
    lengths = [20] * 40 + [25] * 9 + [31] * 3 + [12] * 2 + [17]
    Y = [np.cumsum(rng.standard_normal(t)) for t in rng.permutation(lengths)]
    X = None if symmetric else series(rng, 6, [12, 20, 33], 1)
    (wide, narrow), single = _lanes.lane_blocks(np.array([len(y) for y in Y]))
    assert len(wide) == 1 and len(narrow) == 2 + 1 + 1 and len(single) == 3
    for window in (None, 0.2):
        got = dtw_pairwise_distance(Y if symmetric else X, None if symmetric else Y,
                                    window=window)  # fmt: skip
        expected = one_pair_kernel(Y if symmetric else X, None if symmetric else Y,
                                   "euclidean", window, False)  # fmt: skip
        assert np.array_equal(got, expected)
    assert lane_calls["blocks"] > 0


def test_lanes_against_single_distances(rng, lane_calls):
    """An independent check: every entry equals its own :func:`dtw_distance`."""
    X, Y = series(rng, 6, [15, 18], 2), series(rng, 12, [16], 2)
    got = dtw_pairwise_distance(X, Y, window=0.3)
    expected = [[dtw_distance(x, y, window=0.3) for y in Y] for x in X]
    np.testing.assert_allclose(got, expected, rtol=1e-13)
    assert lane_calls["blocks"] > 0


@pytest.mark.parametrize("scale", [1e-170, 1e170], ids=["tiny", "huge"])
def test_extreme_magnitudes_take_the_robust_distance(scale, rng, lane_calls):
    X, Y = series(rng, 7, [12], 2, scale), series(rng, 10, [12], 2, scale)
    Y[4] = X[1].copy()  # coincident points: a zero sum of squares
    got = dtw_pairwise_distance(X, Y, window=0.5)
    assert np.array_equal(got, one_pair_kernel(X, Y, Euclidean(2), 0.5, False))
    others = got[[0, 2, 3]]
    assert np.all(np.isfinite(got)) and np.all(others > 0) and got[1, 4] == 0.0
    # the plain sum of squares would have under- or overflowed
    assert np.all(others / scale < 1e3) and np.all(others / scale > 1e-3)
    assert lane_calls["blocks"] > 0


def test_product_of_euclidean_spaces_sums_segments_in_order(rng, lane_calls):
    manifold = Product([Euclidean(2), Euclidean(3)])
    X, Y = series(rng, 6, [14], 5), series(rng, 11, [14], 5)
    got = dtw_pairwise_distance(X, Y, manifold, window=0.25)
    assert np.array_equal(got, one_pair_kernel(X, Y, manifold, 0.25, False))
    assert lane_calls["blocks"] > 0


def test_threads_give_the_serial_values(rng, lane_calls):
    Y = series(rng, 70, [30], 1)
    serial = dtw_pairwise_distance(Y, window=0.1, n_jobs=1)
    assert np.array_equal(dtw_pairwise_distance(Y, window=0.1, n_jobs=2), serial)
    assert lane_calls["blocks"] > 0


def test_lane_blocks_cover_every_reference_once():
    lengths = np.array([5] * 70 + [6] * 2 + [7] * 13 + [8])
    lengths = lengths[np.random.default_rng(0).permutation(len(lengths))]
    (wide, narrow), single = _lanes.lane_blocks(lengths)
    assert wide.shape[1] == _lanes.WIDE and narrow.shape[1] == _lanes.NARROW
    members = np.concatenate([wide[wide >= 0], narrow[narrow >= 0], single])
    assert np.array_equal(np.sort(members), np.arange(len(lengths)))
    for block in [*wide, *narrow]:
        used = block[block >= 0]
        assert len(set(lengths[used])) == 1 and np.all(np.diff(used) > 0)
        assert np.all(block[len(used) :] == -1)  # padding only at the end
    assert set(lengths[single]) == {6, 8}


def test_other_manifolds_and_few_pairs_keep_the_one_pair_kernel(monkeypatch, rng):
    many = _lanes.MIN_PAIRS
    assert _lanes.lanes_apply(np.array([[0, 1, 0], [1, 4, 0]]), many, 100)
    assert not _lanes.lanes_apply(np.array([[0, 3, 0], [3, 7, 2]]), many, 100)
    assert not _lanes.lanes_apply(np.array([[0, 1, 0]]), many - 1, 100)
    # 60,000 samples of 3 coordinates fit a block; of 100 coordinates they do not
    assert _lanes.lanes_apply(np.array([[0, 3, 0]]), many, 60_000)
    assert not _lanes.lanes_apply(np.array([[0, 100, 0]]), many, 60_000)
    # the pairs counted are those computed: a symmetric matrix of 12 series has 66
    calls = []
    monkeypatch.setattr(_lanes, "lane_distances",
                        lambda *a: calls.append(a) or np.zeros((12, 12)))  # fmt: skip
    dtw_pairwise_distance(series(rng, 12, [20], 1))
    dtw_pairwise_distance(series(rng, 11, [20], 1))  # 55 pairs
    assert len(calls) == 1


@pytest.mark.parametrize("dim", [1, 3])
@pytest.mark.parametrize("window", [None, 0.1])
def test_amerced_lanes_equal_the_one_pair_kernel(dim, window, rng, lane_calls):
    """With a penalty too, bit for bit."""
    X, Y = series(rng, 5, [30], dim), series(rng, 41, [30, 31], dim)
    manifold = Euclidean(dim)
    cx, cy = check_series_collection(X, manifold), check_series_collection(Y, manifold)
    w = _dtw.check_window(window)
    flat_x, flat_y = _point_costs.kernel_series(cx), _point_costs.kernel_series(cy)
    segments = _point_costs.segment_codes(manifold)
    one_pair = _pruned.pairwise_segments(
        flat_x, cx.lengths, flat_y, cy.lengths, segments, False, w, False,
        np.full((5, 41), np.inf), 0.7,
    )  # fmt: skip
    got = _lanes.lane_distances(flat_x, cx.lengths, flat_y, cy.lengths, segments, False, w,
                                False, 0.7)  # fmt: skip
    assert np.array_equal(got, one_pair)
    assert lane_calls["blocks"] > 0
    assert np.array_equal(
        dtw_pairwise_distance(X, Y, manifold, window=window, warp_penalty=0.7), one_pair
    )
