"""sk_rtw.align, end to end: alignments that must work, its arguments, presets and
results."""

from __future__ import annotations

import numpy as np
import pytest

from sk_rtw.align import align
from sk_rtw.datasets import make_warped_signals
from sk_rtw.manifolds import SPD, Euclidean, Quaternion, Sphere
from sk_rtw.metrics import alignment_quality, barycenter_loss, restoration_accuracy

from .conftest import CurvedLookingEuclidean, interpolate


# ---------------------------------------------------------------- alignment
def warp_spread(learned, true):
    """Mean over time of the spread across signals of ``true_n(learned_n(z))``.

    If the learned warps undo the true ones, every composite is the same common warp and
    the spread is zero; for identity warps it is the spread of the true warps.
    """
    grid = np.linspace(0, 1, true.shape[1])
    composite = np.stack([np.interp(w, grid, t) for w, t in zip(learned, true, strict=True)])
    return composite.std(0).mean()


CASES = [
    ("S^1", Sphere(1), 90),
    ("S^2", Sphere(2), 90),
    ("quaternion", Quaternion(), 90),
    ("SPD(2)", SPD(2), 60),
    ("R^2", Euclidean(2), 90),
]


@pytest.mark.parametrize(("name", "manifold", "epochs"), CASES, ids=[c[0] for c in CASES])
def test_rtw_undoes_random_warps(name, manifold, epochs):
    """Measured factors (seed 8, N=4, T=40, Z=120, 90 epochs): barycenter loss 1.9-3.3x,
    alignment quality 4.7-10x, warp spread 2.4-17x, banded restoration 1.4-2.3x lower than
    for the unaligned signals."""
    data = make_warped_signals(manifold, 4, 40, 8)
    result = align(
        data.signals, manifold=manifold, n_epochs=epochs, output_length=120, random_state=0
    )
    manifold.validate(result.mean, atol=1e-8)
    manifold.validate(result.aligned, atol=1e-8)
    assert np.all(np.diff(result.warps, axis=1) >= -1e-3)  # monotone within tolerance
    assert result.warps[:, 0].max() == 0 and result.warps[:, -1].min() == 1
    unaligned_mean = manifold.mean(data.signals)
    before = barycenter_loss(data.signals, unaligned_mean, manifold)
    after = barycenter_loss(data.signals, result.mean, manifold)
    assert after < before / 1.5, (before, after)
    quality_before = alignment_quality(data.signals, unaligned_mean, manifold)
    quality_after = alignment_quality(result.aligned, result.mean, manifold)
    assert quality_after < quality_before / 4, (quality_before, quality_after)
    spread_before = warp_spread(np.tile(np.linspace(0, 1, 120), (4, 1)), data.warps)
    assert warp_spread(result.warps, data.warps) < spread_before / 2
    # Unconstrained DTW undoes the warps by itself; a band makes restoration measurable.
    restored_before = restoration_accuracy(data.signals, data.original, manifold, window=0.1)
    restored_after = restoration_accuracy(result.aligned, data.original, manifold, window=0.1)
    assert restored_after < restored_before / 1.3, (restored_before, restored_after)
    assert result.loss_history[result.best_epoch] == np.nanmin(result.loss_history)


@pytest.mark.parametrize("method", ["ttw", "ntw"])
def test_baselines_improve_alignment_too(method):
    data = make_warped_signals("sphere", 4, 40, 8)
    result = align(
        data.signals,
        manifold="sphere",
        method=method,
        n_epochs=90,
        output_length=120,
        random_state=0,
    )
    unaligned_mean = Sphere(1).mean(data.signals)
    assert (
        alignment_quality(result.aligned, result.mean, "sphere")
        < alignment_quality(data.signals, unaligned_mean, "sphere") / 2
    )
    assert result.config.method == method
    assert result.config.loss_window == 0
    assert result.config.sinc_window == (None if method == "ntw" else 10)


def test_first_loss_is_the_papers_loss_at_identity_warps():
    """NTW starts from identity warps (zero init): its first loss must equal the pointwise
    loss computed independently from the interpolated signals and their Fréchet mean."""
    M = Sphere(2)
    data = make_warped_signals(M, 3, 30, 5)
    result = align(
        data.signals, manifold=M, method="ntw", n_epochs=1, output_length=45, mean_iterations=20
    )
    grid = np.linspace(0, 1, 45)
    refinements = result.config.tangent_refinements
    resampled = np.stack([interpolate(M, x, grid, None, refinements) for x in data.signals])
    mean = M.mean(resampled)
    expected = M.dist(resampled, mean[None]).mean()
    assert result.loss_history[0] == pytest.approx(expected, rel=1e-9)


def test_same_random_state_same_result_and_different_otherwise():
    data = make_warped_signals("sphere", 3, 30, 3)
    a = align(data.signals, manifold="sphere", n_epochs=15, random_state=5)
    b = align(data.signals, manifold="sphere", n_epochs=15, random_state=5)
    c = align(data.signals, manifold="sphere", n_epochs=15, random_state=6)
    np.testing.assert_array_equal(a.warps, b.warps)
    np.testing.assert_array_equal(a.mean, b.mean)
    assert not np.array_equal(a.warps, c.warps)


def test_euclidean_alignment_through_the_general_path_equals_the_flat_one():
    data = make_warped_signals("euclidean", 3, 30, 4)
    # identity start: DTW paths break ties differently on 1e-12 differences of the means
    options = {"n_epochs": 10, "random_state": 1, "mean_iterations": 8, "warp_start": "identity"}
    flat = align(data.signals, manifold=Euclidean(1), **options)
    general = align(data.signals, manifold=CurvedLookingEuclidean(1), **options)
    np.testing.assert_allclose(general.loss_history, flat.loss_history, rtol=1e-9)
    np.testing.assert_allclose(general.mean, flat.mean, atol=1e-9)


def test_single_signal_is_returned_unchanged():
    x = make_warped_signals("sphere", 1, 25, 0).original
    result = align(x[None], manifold="sphere")
    np.testing.assert_allclose(result.aligned[0], x, atol=1e-12)
    np.testing.assert_allclose(result.mean, x, atol=1e-12)
    np.testing.assert_allclose(result.warps[0], np.linspace(0, 1, 25))
    assert result.best_epoch == -1


def test_two_signals_unequal_lengths_and_univariate_input(rng):
    t = np.linspace(0, 1, 60)
    X = [np.sin(2 * np.pi * t**1.3), np.sin(2 * np.pi * np.linspace(0, 1, 45) ** 0.8)]
    result = align(X, n_epochs=40, random_state=0)  # Z = min(N, 4) T_max
    assert result.mean.shape == (120, 1) and result.aligned.shape == (2, 120, 1)
    paper = align(X, n_epochs=2, preset="paper")  # Z = N T_max
    assert paper.mean.shape == (120, 1)
    result = align(
        np.stack([np.sin(2 * np.pi * t), np.sin(2 * np.pi * t**1.2)]),
        n_epochs=5,
        output_length=70,
        random_state=0,
    )
    assert result.warps.shape == (2, 70)


def test_very_short_series_work():
    X = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    result = align(X, n_epochs=5, random_state=0)
    assert np.all(np.isfinite(result.mean))


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"method": "dtw"}, ValueError, "method"),
        ({"n_epochs": -1}, ValueError, "n_epochs"),
        ({"output_length": 1}, ValueError, "output_length"),
        ({"learning_rate": 0.0}, ValueError, "learning_rate"),
        ({"sinc_window": -2}, ValueError, "sinc_window"),
        ({"loss_step": 0}, ValueError, "loss_step"),
        ({"penalty": -1.0}, ValueError, "penalty"),
        ({"method": "ttw", "n_components": 0}, ValueError, "n_components"),
        ({"n_components": 4}, TypeError, "n_components is not a setting of RTW"),
        ({"method": "ttw", "hidden_size": 8}, TypeError, "it sets RTW, NTW"),
        ({"sinc_window": "full"}, ValueError, r"None \(the full sinc\)"),
        ({"warp_knots": 1}, ValueError, "warp_knots"),
        ({"tangent_refinements": -1}, ValueError, "tangent_refinements"),
        ({"bogus": 1}, TypeError, "bogus"),
    ],
)
def test_bad_arguments(kwargs, error, match):
    with pytest.raises(error, match=match):
        align(np.zeros((2, 10)), **kwargs)


def test_bad_data():
    with pytest.raises(ValueError, match="NaN"):
        align(np.array([[0.0, np.nan, 1.0], [0.0, 1.0, 2.0]]))
    with pytest.raises(ValueError, match="not a point"):
        align(np.ones((2, 5, 3)), manifold="sphere")


def test_returned_warps_are_those_of_the_best_epoch():
    """The final pass runs with the parameters of the lowest recorded loss."""
    data = make_warped_signals("sphere", 4, 40, 2)
    result = align(
        data.signals, manifold="sphere", n_epochs=40, n_iter_no_change=None, random_state=0
    )
    again = align(
        data.signals,
        manifold="sphere",
        n_epochs=result.best_epoch + 1,
        n_iter_no_change=None,
        random_state=0,
    )  # the same trajectory, stopped right after the best epoch was recorded
    np.testing.assert_allclose(again.warps, result.warps, atol=1e-12)
    assert result.loss_history[result.best_epoch] == result.loss_history.min()

def test_early_stopping_saves_epochs_and_keeps_the_best():
    data = make_warped_signals("euclidean", 6, 40, 1)
    full = align(data.signals, n_iter_no_change=None, n_epochs=120, random_state=0)
    early = align(data.signals, n_iter_no_change=5, tol=1e-2, n_epochs=120, random_state=0)
    assert full.n_iter == 120 and early.n_iter < 120
    ran = early.loss_history[: early.n_iter]
    assert np.isfinite(ran).all() and np.isnan(early.loss_history[early.n_iter :]).all()
    # the same trajectory as the full run up to the stop
    np.testing.assert_allclose(ran, full.loss_history[: early.n_iter], rtol=1e-10)
    assert early.best_epoch == int(np.argmin(ran))
    with pytest.raises(ValueError, match="n_iter_no_change"):
        align(data.signals, n_iter_no_change=0)


def test_verbose_reports_progress(capsys):
    """Epochs, and the DTW start's medoid and rounds (on long series the start can take
    longer than training); nothing without ``verbose``."""
    X = np.random.default_rng(0).standard_normal((3, 10)).cumsum(1)
    align(X, n_epochs=4, verbose=True, dtw_rounds=2)
    err = capsys.readouterr().err
    assert "epoch" in err and "[rtw] DTW start: 1 medoid(s) in" in err
    assert "[rtw] DTW start: round 1/2, 3 paths in" in err
    assert "[rtw] DTW start: round 2/2, 3 paths in" in err
    align(X, n_epochs=4, dtw_rounds=2)
    assert capsys.readouterr().err == ""


def test_top_level_align_is_the_function_even_after_submodule_imports():
    import importlib

    import sk_rtw

    importlib.import_module("sk_rtw.align._loss")
    from sk_rtw import align as top_level

    assert callable(top_level) and top_level is sk_rtw.align


def test_quaternion_mean_and_aligned_series_have_no_sign_flips():
    data = make_warped_signals("quaternion", 3, 40, 0, amplitude=1.2)
    rng = np.random.default_rng(1)
    flipped = data.signals * np.where(rng.random((3, 40)) < 0.5, -1.0, 1.0)[..., None]
    result = align(flipped, manifold="quaternion", n_epochs=2, random_state=0)
    assert np.all((result.mean[1:] * result.mean[:-1]).sum(-1) > 0)
    assert np.all((result.aligned[:, 1:] * result.aligned[:, :-1]).sum(-1) > 0)

def test_presets():
    X = make_warped_signals("euclidean", 3, 20, 0).signals
    default = align(X, n_epochs=1, random_state=0).config
    paper = align(X, n_epochs=1, random_state=0, preset="paper").config
    assert (default.output_length, default.warp_knots, default.tangent_refinements) == (60, 64, 0)
    assert (default.warp_start, default.init) == ("dtw", "zero-readout")
    assert (paper.output_length, paper.warp_knots, paper.tangent_refinements) == (60, None, 2)
    assert (paper.warp_start, paper.init) == ("identity", "xavier")
    for method in ("ttw", "ntw"):  # the baselines keep their published start
        assert align(X, method=method, n_epochs=1).config.warp_start == "identity"
    explicit = align(X, preset="paper", n_epochs=1, warp_knots=8, output_length=25).config
    assert (explicit.warp_knots, explicit.output_length) == (8, 25)
    with pytest.raises(ValueError, match="preset"):
        align(X, preset="fast")
