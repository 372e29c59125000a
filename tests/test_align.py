"""The alignment engine: interpolation, warps, losses, and alignment that must work."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
import torch

from sk_rtw.align import align, tangent_sinc_interpolate
from sk_rtw.align._loss import monotonicity_penalty, window_weights
from sk_rtw.align._training import Trainer
from sk_rtw.align._warps import (
    HouseholderBasis,
    NeuralWarps,
    SineWarps,
    resample_linear,
    unit_time,
)
from sk_rtw.datasets import make_warped_signals
from sk_rtw.manifolds import SPD, Euclidean, Quaternion, Sphere
from sk_rtw.metrics import alignment_quality, barycenter_loss, restoration_accuracy

from .conftest import CURVED, MANIFOLDS


@dataclass(frozen=True)
class CurvedLookingEuclidean(Euclidean):
    """Euclidean geometry that does not declare itself flat: forces the general path."""

    is_flat = False


def reference_windowed_sinc(x, positions, window):
    """Normalised windowed sinc with clamped indices, written with plain loops."""
    out = []
    T = len(x)
    for tau in positions:
        base = math.floor(tau)
        num, den = 0.0, 0.0
        for k in range(-window, window + 1):
            m = min(max(base + k, 0), T - 1)
            s = np.sinc(base + k - tau)
            num, den = num + s * x[m], den + s
        out.append(num / den)
    return np.array(out)


def interpolate(manifold, x, warps, window=10, refinements=0):
    data = torch.as_tensor(np.asarray(x))[None]
    w = torch.as_tensor(np.asarray(warps), dtype=torch.float64)[None]
    return tangent_sinc_interpolate(
        manifold, data, torch.tensor([len(x)]), w, window, refinements
    )[0].numpy()


# ------------------------------------------------------------ interpolation
@pytest.mark.parametrize("manifold", MANIFOLDS, ids=repr)
@pytest.mark.parametrize("window", [10, 3, None])
def test_integer_positions_return_the_samples(manifold, window):
    x = make_warped_signals(manifold, 1, 30, 0).original
    warps = np.linspace(0, 1, 30)  # tau = 0, 1, ..., 29
    np.testing.assert_allclose(interpolate(manifold, x, warps, window), x, atol=1e-9)


@pytest.mark.parametrize("window", [10, 2, None])
def test_euclidean_equals_plain_windowed_sinc(window, rng):
    x = rng.standard_normal(40)
    warps = np.sort(rng.uniform(0, 1, 25))
    full = window if window is not None else 40
    expected = reference_windowed_sinc(x, warps * 39, full)
    if window is None:  # full sinc: only real samples, no clamped repeats
        expected = np.array(
            [
                (np.sinc(np.arange(40) - t) @ x) / np.sinc(np.arange(40) - t).sum()
                for t in warps * 39
            ]
        )
    got = interpolate(Euclidean(1), x[:, None], warps, window)[:, 0]
    np.testing.assert_allclose(got, expected, atol=1e-12)


def test_band_limited_signal_is_reconstructed_between_samples():
    t = np.arange(64)
    x = np.sin(2 * np.pi * 3 * t / 64)
    positions = np.linspace(20, 44, 97)  # interior, away from the clamped ends
    got = interpolate(Euclidean(1), x[:, None], positions / 63)[:, 0]
    np.testing.assert_allclose(got, np.sin(2 * np.pi * 3 * positions / 64), atol=5e-3)


def test_manifold_path_equals_euclidean_special_case(rng):
    x = rng.standard_normal((30, 3))
    warps = np.sort(rng.uniform(0, 1, 50))
    flat = interpolate(Euclidean(3), x, warps)
    general = interpolate(CurvedLookingEuclidean(3), x, warps, refinements=3)
    np.testing.assert_allclose(general, flat, atol=1e-12)


# The tangent-point refinement runs without gradient tracking (it is a choice of chart),
# so the autograd derivative is exact for flat spaces and S^1 and within a fraction of a
# percent elsewhere (the refinement contracts by ~100x per step).
@pytest.mark.parametrize("manifold", MANIFOLDS, ids=repr)
def test_interpolation_gradient_matches_finite_differences(manifold):
    rtol = 1e-7 if manifold.is_flat or manifold == Sphere(1) else 1e-2
    x = torch.as_tensor(make_warped_signals(manifold, 1, 25, 1, amplitude=2.0).original)[None]
    # non-integer positions: at integer ones the windowed kernel has a kink (a tap enters
    # the window with zero weight but non-zero slope), so one-sided derivatives differ
    warps = torch.tensor([[0.01, 0.13, 0.371, 0.52, 0.8666, 0.995]], dtype=torch.float64)

    def f(w):
        return tangent_sinc_interpolate(manifold, x, torch.tensor([25]), w, 10, 2)

    jacobian = torch.autograd.functional.jacobian(f, warps)
    finite = torch.zeros_like(jacobian)
    eps = 1e-6
    for z in range(warps.shape[1]):
        step = torch.zeros_like(warps)
        step[0, z] = eps
        finite[..., 0, z] = (f(warps + step) - f(warps - step)) / (2 * eps)
    error = (jacobian - finite).abs().max() / finite.abs().max()
    assert error < rtol, float(error)
    assert finite.abs().max() > 0.1  # the test looks at a real slope


@pytest.mark.parametrize("manifold", CURVED, ids=repr)
def test_interpolated_point_balances_the_weighted_window(manifold):
    """The refined tangent point is the weighted Fréchet mean of the window:
    ``sum_m s_m Log_x(x_m) = 0`` (within the Gauss–Newton tolerance after 2 refinements)."""
    x = make_warped_signals(manifold, 1, 30, 3, amplitude=2.0).original
    w = np.random.default_rng(0).uniform(0.05, 0.95, 40)
    out = interpolate(manifold, x, w, 10, refinements=2)
    tau = w * 29
    base = np.floor(tau)
    k = np.arange(-10, 11)
    idx = np.clip(base[:, None] + k, 0, 29).astype(int)
    s = np.sinc(k - (tau - base)[:, None])
    s /= s.sum(1, keepdims=True)
    residual = (
        s.reshape(*s.shape, *([1] * manifold.point_ndim)) * manifold.log(out[:, None], x[idx])
    ).sum(1)
    assert np.abs(residual).max() < 1e-5


def test_interpolated_sphere_points_stay_on_the_sphere():
    x = make_warped_signals("sphere", 1, 30, 2, dim=2).original
    out = interpolate(Sphere(2), x, np.random.default_rng(0).uniform(0, 1, 200))
    np.testing.assert_allclose(np.linalg.norm(out, axis=-1), 1.0, atol=1e-12)


def test_series_shorter_than_the_window_are_clamped(rng):
    x = rng.standard_normal((4, 1))
    out = interpolate(Euclidean(1), x, np.linspace(0, 1, 13))
    assert np.all(np.isfinite(out))
    np.testing.assert_allclose(out[[0, -1]], x[[0, -1]], atol=1e-12)


# -------------------------------------------------------------------- warps
@pytest.mark.parametrize("n", [2, 3, 7, 30])
def test_householder_basis_is_orthonormal_with_constant_first_vector(n):
    basis = HouseholderBasis(n)
    Q = basis.matrix()
    np.testing.assert_allclose((Q.T @ Q).numpy(), np.eye(n), atol=1e-12)
    np.testing.assert_allclose(Q[:, 0].numpy(), np.full(n, 1 / np.sqrt(n)), atol=1e-12)
    c = torch.randn(5, n - 1, dtype=torch.float64)
    np.testing.assert_allclose(basis.combine(c).numpy(), (c @ Q[:, 1:].T).numpy(), atol=1e-12)


def test_neural_warps_match_the_paper_architecture():
    n = 6
    model = NeuralWarps(n, hidden=512, init="xavier")
    n_params = sum(p.numel() for p in model.parameters())
    assert n_params == 263680 + 1025 * (n - 1) + (n - 1)
    zhat = unit_time(50)
    raw = model(zhat).detach()
    np.testing.assert_array_equal(raw[:, 0].numpy(), 0.0)
    np.testing.assert_array_equal(raw[:, -1].numpy(), 1.0)
    np.testing.assert_allclose(raw.mean(0).numpy(), zhat.numpy(), atol=1e-12)  # mean warp
    assert raw.std(0).max() > 1e-3  # Xavier init breaks the symmetry
    zero = NeuralWarps(n, hidden=512, init="zeros")
    np.testing.assert_array_equal(zero(zhat).detach().numpy(), zhat.expand(n, -1).numpy())


def test_linear_resampling_equals_numpy_interp(rng):
    values = torch.as_tensor(rng.standard_normal((9, 3)))
    times = torch.as_tensor(np.concatenate([[0.0, 1.0], rng.uniform(0, 1, 40)]))
    knots = np.linspace(0, 1, 9)
    expected = np.stack([np.interp(times, knots, values[:, j]) for j in range(3)], axis=1)
    np.testing.assert_allclose(resample_linear(values, times).numpy(), expected, atol=1e-14)


def test_warps_on_knots_interpolate_the_network_between_them():
    torch.manual_seed(0)
    exact = NeuralWarps(5, hidden=32, init="xavier", knots=None)
    knotted = NeuralWarps(5, hidden=32, init="xavier", knots=11)
    knotted.load_state_dict(exact.state_dict())
    zhat = unit_time(101)
    at_knots = unit_time(11)
    # at the knot times both are the same function
    np.testing.assert_allclose(
        knotted.offsets(zhat)[:, ::10].detach().numpy(),
        exact.offsets(at_knots).detach().numpy(),
        atol=1e-14,
    )
    raw = knotted(zhat).detach()
    np.testing.assert_array_equal(raw[:, 0].numpy(), 0.0)  # boundary constraint exact
    np.testing.assert_array_equal(raw[:, -1].numpy(), 1.0)
    np.testing.assert_allclose(raw.mean(0).numpy(), zhat.numpy(), atol=1e-12)
    # at least as many knots as output times: the network at every output time
    full = NeuralWarps(5, hidden=32, init="xavier", knots=200)
    full.load_state_dict(exact.state_dict())
    np.testing.assert_array_equal(full(zhat).detach().numpy(), exact(zhat).detach().numpy())


def test_sine_warps_are_centred_monotone_and_exact_at_the_ends():
    model = SineWarps(5, n_components=4)
    with torch.no_grad():
        model.coefficients.copy_(torch.randn(5, 4, dtype=torch.float64))
    zhat = unit_time(80)
    raw = model(zhat).detach()
    np.testing.assert_allclose(raw.mean(0).numpy(), zhat.numpy(), atol=1e-12)
    warps = model.finalise(raw)
    assert torch.all(warps[:, 1:] >= warps[:, :-1])
    assert torch.all(warps[:, 0] == 0) and torch.all(warps[:, -1] == 1)


# ------------------------------------------------------------------- losses
@pytest.mark.parametrize(("Z", "kappa", "rho"), [(50, 5, 5), (20, 3, 2), (7, 5, 5), (30, 0, 1)])
def test_window_weights_equal_the_literal_window_loss(Z, kappa, rho, rng):
    d = rng.uniform(size=(3, Z))
    sigma = kappa * rho / 3 + 1e-6
    literal = 0.0
    for n in range(3):
        for z in range(Z):
            g = np.array(
                [np.exp(-((k * rho) ** 2) / (2 * sigma**2)) for k in range(-kappa, kappa + 1)]
            )
            for k, gk in zip(range(-kappa, kappa + 1), g / g.sum(), strict=True):
                literal += gk * d[n, min(max(z + k * rho, 0), Z - 1)]
    literal /= 3 * Z
    c = window_weights(Z, kappa, rho).numpy()
    assert (d * c).mean() == pytest.approx(literal, rel=1e-12)
    if kappa == 0:
        np.testing.assert_allclose(c, 1.0)


def test_monotonicity_penalty():
    w = torch.tensor([[0.0, 0.3, 0.2, 0.6, 0.5, 1.0]])
    assert float(monotonicity_penalty(w)) == pytest.approx(0.2)


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


def test_trainer_raises_on_a_non_finite_loss():
    weight = torch.nn.Parameter(torch.ones(3))
    trainer = Trainer(lambda: (weight * 1e308 * 10).sum(), [weight], 5, 0.1)
    with pytest.raises(FloatingPointError, match="epoch 0"):
        trainer.run(lambda done, history: None, 2)


def test_trainer_keeps_the_lowest_loss_parameters():
    weight = torch.nn.Parameter(torch.tensor([3.0]))
    # a loss with its minimum at 1; a large rate makes Adam overshoot and come back
    trainer = Trainer(lambda: (weight - 1.0).abs().sum(), [weight], 30, 1.5)
    (best,) = trainer.run(lambda done, history: None, 10)
    history = trainer.progress.history[:, 0].numpy()
    assert best == int(np.argmin(history))
    assert abs(float(weight.detach()) - 1.0) == pytest.approx(history[best])


def test_trainer_stops_each_group_on_its_own_and_keeps_its_best():
    """Two groups in one loop: the one whose loss stalls stops early, its best frozen;
    the other trains on. Each equals the same group trained alone."""
    start = torch.tensor([[3.0], [3.0]])

    def losses(weight):
        # group 0 reaches its floor (1) quickly and stalls there; group 1 keeps improving
        return torch.stack([(weight[0] - 1.0).abs().sum().clamp_min(0.5),
                            (weight[1] + 50.0).abs().sum()])  # fmt: skip

    def run(groups, n_groups):
        weight = torch.nn.Parameter(start[: len(groups)].clone())

        def loss_fn():
            values = losses(torch.cat([weight, start[len(groups) :]]))[:n_groups]
            return values.sum(), values

        trainer = Trainer(loss_fn, [weight], 200, 0.1, parameter_groups=[groups],
                          n_groups=n_groups, n_iter_no_change=5, tol=1e-4)  # fmt: skip
        best = trainer.run(lambda done, history: None, 50)
        return trainer, best, weight.detach().clone()

    both, best, weight = run(torch.tensor([0, 1]), 2)
    alone, best_alone, weight_alone = run(torch.tensor([0]), 1)
    runs = both.progress.epochs_run.numpy()
    assert runs[0] < runs[1] == 200  # group 0 stopped early, group 1 ran to the end
    assert runs[0] == alone.progress.epochs_run.numpy()[0] and best[0] == best_alone[0]
    torch.testing.assert_close(weight[0], weight_alone[0])
    assert np.isnan(both.progress.history[runs[0] :, 0].numpy()).all()


def test_a_narrowed_trainer_goes_on_as_the_whole_one_would():
    """Pause once a group has stopped, narrow to the running groups (their parameters,
    best iterates, counters, history and Adam moments carried over), finish: the same
    epochs, best epochs, history and final parameters as the uninterrupted run."""
    floors = torch.tensor([1.0, -50.0, 0.0])

    def make(weight, groups):
        def loss_fn():
            values = (weight[:, 0] - floors[groups]).abs().clamp_min(0.5)
            return values.sum(), values

        return Trainer(loss_fn, [weight], 150, 0.1, parameter_groups=[torch.arange(len(groups))],
                       n_groups=len(groups), n_iter_no_change=5, tol=1e-4)  # fmt: skip

    whole_weight = torch.nn.Parameter(torch.full((3, 1), 3.0))
    whole = make(whole_weight, torch.arange(3))
    whole.run(lambda done, history: None, 50)

    weight = torch.nn.Parameter(torch.full((3, 1), 3.0))
    trainer = make(weight, torch.arange(3))
    assert trainer.run(lambda done, history: None, 50, pause=lambda a: not bool(a.all())) is None
    paused_at = trainer.epochs_done
    keep = torch.nonzero(trainer.progress.active).flatten()
    stopped = torch.nonzero(~trainer.progress.active).flatten()
    assert 0 < paused_at < 150 and 0 < len(keep) < 3
    frozen = trainer.best[0][stopped].clone()
    part = torch.nn.Parameter(weight.detach()[keep].clone())
    narrowed = trainer.narrow(keep, make(part, keep).loss_fn, [part], [torch.arange(len(keep))])
    narrowed.run(lambda done, history: None, 50)
    assert narrowed.epochs_done > paused_at
    for name in ("epochs_run", "best_epoch"):
        np.testing.assert_array_equal(getattr(narrowed.progress, name).numpy(),
                                      getattr(whole.progress, name)[keep].numpy())  # fmt: skip
    np.testing.assert_array_equal(narrowed.progress.history.numpy(),
                                  whole.progress.history[:, keep].numpy())  # fmt: skip
    np.testing.assert_array_equal(part.detach().numpy(), whole_weight.detach()[keep].numpy())
    np.testing.assert_array_equal(frozen.numpy(), whole_weight.detach()[stopped].numpy())
    np.testing.assert_array_equal(narrowed.progress.ids, keep.numpy())


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
    align(np.random.default_rng(0).standard_normal((2, 10)), n_epochs=4, verbose=True)
    assert "epoch" in capsys.readouterr().err


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


# ----------------------------------------------------- starts and presets
def test_path_warp_is_the_mean_matched_position():
    from sk_rtw.align._start import path_warp

    path = np.array([[0, 0], [1, 1], [1, 2], [1, 3], [2, 4], [3, 4], [4, 5]])
    expected = np.array([0.0, 2.0, 4.0, 4.0, 5.0]) / 5
    np.testing.assert_allclose(path_warp(path, 5, 6, smoothing=0), expected)


def test_smoothed_path_warps_stay_monotone_from_zero_to_one(rng):
    from sk_rtw.align._start import path_warp

    matched = np.sort(rng.integers(0, 80, 60))  # a staircase with flat and steep parts
    matched[0], matched[-1] = 0, 79
    path = np.stack([np.arange(60), matched], axis=1)
    raw, smooth = path_warp(path, 60, 80, 0), path_warp(path, 60, 80, 2.0)
    assert smooth[0] == 0.0 and smooth[-1] == 1.0
    assert np.all(np.diff(smooth) >= 0)
    assert np.abs(np.diff(smooth, 2)).max() < np.abs(np.diff(raw, 2)).max()  # fewer corners
    assert np.abs(smooth - raw).max() < 5 / 79  # within a few samples of the path
    short = path_warp(np.array([[0, 0], [1, 2], [2, 2], [3, 3], [4, 4]]), 5, 5, 2.0)
    assert short.shape == (5,) and short[0] == 0.0 and short[-1] == 1.0  # radius > length
    assert np.all(np.diff(short) >= 0)


def test_centred_warps_average_to_the_identity(rng):
    from sk_rtw.align._start import centred_warps

    raw = np.sort(rng.uniform(0, 1, (5, 40)), axis=1)
    raw[:, 0], raw[:, -1] = 0.0, 1.0
    warps = centred_warps(raw, 73)
    np.testing.assert_allclose(warps.mean(0), np.linspace(0, 1, 73), atol=1e-6)
    assert np.all(np.diff(warps, axis=1) >= -1e-12)
    # the same common time change for every series: pairwise relations are kept
    grid = np.linspace(0, 1, 40)
    times = np.interp(warps[0], raw[0], grid)  # reference time of every output time
    np.testing.assert_allclose(warps[1], np.interp(times, grid, raw[1]), atol=1e-6)


def test_compose_warps_equals_numpy_interp(rng):
    from sk_rtw.align._warps import compose_warps

    outer = np.sort(rng.uniform(0, 1, (3, 11)), axis=1)
    inner = rng.uniform(0, 1, (3, 30))
    got = compose_warps(torch.as_tensor(outer), torch.as_tensor(inner)).numpy()
    grid = np.linspace(0, 1, 11)
    expected = np.stack([np.interp(i, grid, o) for o, i in zip(outer, inner, strict=True)])
    np.testing.assert_allclose(got, expected, atol=1e-14)


@pytest.mark.parametrize("manifold", ["euclidean", "sphere", "quaternion", "spd"])
def test_dtw_start_aligns_before_any_training(manifold):
    data = make_warped_signals(manifold, 6, 60, 3, strength=0.9)
    M = data.manifold
    start = align(data.signals, manifold=M, warp_start="dtw", n_epochs=0, random_state=0)
    plain = align(data.signals, manifold=M, warp_start="identity", n_epochs=0, random_state=0)
    assert start.config.warp_start == "dtw"
    good = alignment_quality(start.aligned, start.mean, M)
    bad = alignment_quality(plain.aligned, plain.mean, M)
    assert good < bad / 3, (good, bad)
    np.testing.assert_allclose(start.warps.mean(0), np.linspace(0, 1, 240), atol=1e-6)


def test_identical_series_get_identity_starting_warps():
    x = make_warped_signals("sphere", 1, 40, 1).original
    result = align(
        np.stack([x, x, x]), manifold="sphere", n_epochs=0, output_length=40, random_state=0
    )
    np.testing.assert_allclose(result.warps, np.tile(np.linspace(0, 1, 40), (3, 1)), atol=1e-9)
    np.testing.assert_allclose(result.mean, x, atol=1e-9)


def test_given_starting_warps_are_used_and_checked(rng):
    data = make_warped_signals("euclidean", 3, 30, 2)
    warps = np.stack([np.linspace(0, 1, 45) ** p for p in (0.9, 1.0, 1.1)])
    result = align(data.signals, warp_start=warps, n_epochs=0, random_state=0)
    assert result.config.warp_start == "given" and result.config.output_length == 45
    np.testing.assert_allclose(result.warps, warps, atol=1e-12)  # zero-readout: start kept
    with pytest.raises(ValueError, match="shape"):
        align(data.signals, warp_start=warps[:2])
    with pytest.raises(ValueError, match="non-decreasing"):
        align(data.signals, warp_start=warps[:, ::-1])
    with pytest.raises(ValueError, match="from 0 to 1"):
        align(data.signals, warp_start=0.5 * warps)
    with pytest.raises(ValueError, match="output_length"):
        align(data.signals, warp_start=warps, output_length=30)
    with pytest.raises(ValueError, match="warp_start"):
        align(data.signals, warp_start="medoid")


def test_training_from_the_dtw_start_never_ends_above_it():
    data = make_warped_signals("sphere", 5, 50, 4)
    result = align(data.signals, manifold="sphere", n_epochs=40, random_state=0)
    assert result.loss_history[result.best_epoch] <= result.loss_history[0]
    assert np.all(np.diff(result.warps, axis=1) >= -1e-9)  # composition stays monotone


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


def test_zero_readout_init_starts_at_the_identity_with_diverse_hidden_units():
    model = NeuralWarps(4, hidden=16, init="zero-readout")
    zhat = unit_time(30)
    np.testing.assert_array_equal(model(zhat).detach().numpy(), zhat.expand(4, -1).numpy())
    assert model.w2.std() > 0
    weights = torch.randn(4, 30, generator=torch.Generator().manual_seed(0))
    (model(zhat) * weights).sum().backward()
    assert model.w3.grad.abs().sum() > 0


# ------------------------------------------------------------ groups in one batch
def _groups_data():
    a = make_warped_signals("sphere", 5, 40, 1).signals
    b = make_warped_signals("sphere", 3, 30, 2).signals
    return list(a) + list(b), np.array([0] * 5 + [1] * 3)


@pytest.mark.parametrize("method", ["rtw", "ttw", "ntw"])
def test_groups_in_one_batch_equal_separate_fits(method):
    from sk_rtw.align import align_collection, resolve_config
    from sk_rtw.utils import check_series_collection

    series, codes = _groups_data()
    collection = check_series_collection(series, "sphere")
    config = resolve_config(method, "alignment", {"output_length": 50, "n_epochs": 30})
    # align(random_state=s) seeds its one group with the first draw of default_rng(s)
    seeds = [int(np.random.default_rng(s).integers(2**31 - 1)) for s in (11, 22)]
    batch = align_collection(collection, codes, seeds, config)
    for g, seed in enumerate((11, 22)):
        alone = align(
            [s for s, c in zip(series, codes, strict=True) if c == g], manifold="sphere",
            method=method, output_length=50, n_epochs=30, random_state=seed,
        )  # fmt: skip
        assert batch[g].n_iter == alone.n_iter and batch[g].best_epoch == alone.best_epoch
        np.testing.assert_allclose(batch[g].warps, alone.warps, atol=1e-9)
        np.testing.assert_allclose(batch[g].mean, alone.mean, atol=1e-9)
        np.testing.assert_allclose(batch[g].loss_history, alone.loss_history, rtol=1e-9)


@pytest.mark.parametrize(
    ("method", "preset"),
    [("rtw", "class-means"), ("rtw", "alignment"), ("ttw", "class-means"), ("ntw", "alignment")],
)
def test_narrowing_the_batch_to_the_running_groups_changes_no_result(method, preset, monkeypatch):
    """Groups that stop early leave the batch (the engine narrows it once half have
    stopped): every group's result is that of the whole batch run to the end."""
    from sk_rtw.align import _narrowing, _problem, align_collection, resolve_config
    from sk_rtw.utils import check_series_collection

    series, codes = [], []
    for g, (n, length, seed) in enumerate([(5, 40, 1), (3, 30, 2), (4, 36, 3), (2, 44, 4),
                                           (6, 32, 5)]):  # fmt: skip
        series += list(make_warped_signals("sphere", n, length, seed).signals)
        codes += [g] * n
    collection = check_series_collection(series, "sphere")
    config = resolve_config(method, preset, {"output_length": 40, "n_epochs": 60,
                                             "n_iter_no_change": 3, "tol": 1e-2})  # fmt: skip
    seeds = [3, 1, 4, 1, 5]
    subsets = []
    original = _problem.Problem.subset
    monkeypatch.setattr(_problem.Problem, "subset",
                        lambda self, groups: subsets.append(len(groups)) or original(self, groups))
    narrowed = align_collection(collection, codes, seeds, config)
    monkeypatch.setattr(_narrowing, "half_stopped", lambda active: False)
    whole = align_collection(collection, codes, seeds, config)
    assert subsets, "the batch was never narrowed"
    assert len({r.n_iter for r in whole}) > 1  # the groups stopped at different epochs
    for a, b in zip(narrowed, whole, strict=True):
        assert a.n_iter == b.n_iter and a.best_epoch == b.best_epoch
        np.testing.assert_allclose(a.warps, b.warps, rtol=0, atol=1e-12)
        np.testing.assert_allclose(a.mean, b.mean, rtol=0, atol=1e-12)
        np.testing.assert_allclose(a.loss_history, b.loss_history, rtol=1e-12)
        assert a.cost == pytest.approx(b.cost, rel=1e-12)


def test_group_layout_sums_and_broadcasts():
    from sk_rtw.align._layout import GroupLayout

    layout = GroupLayout.from_codes([2, 0, 2, 1, 0])
    assert layout.sizes.tolist() == [2, 1, 2] and layout.positions.tolist() == [0, 0, 1, 0, 1]
    values = torch.arange(5.0)
    assert layout.sum(values).tolist() == [1 + 4, 3, 0 + 2]
    assert layout.expand(torch.tensor([10.0, 20.0, 30.0])).tolist() == [30, 10, 30, 20, 10]
    with pytest.raises(ValueError, match="no series"):
        GroupLayout.from_codes([0, 2])


# ------------------------------------------------------------ density-weighted means
def _density(manifold, series, warps):
    from sk_rtw.align._density import density_representatives

    t_max = max(len(s) for s in series)
    padded = [np.concatenate([s, np.repeat(s[-1:], t_max - len(s), 0)]) for s in series]
    data = torch.as_tensor(np.stack(padded))
    lengths = torch.as_tensor([len(s) for s in series])
    warps = torch.as_tensor(warps)
    aligned = tangent_sinc_interpolate(manifold, data, lengths, warps)
    v, w = density_representatives(manifold, data, lengths, warps, aligned)
    return v, w, aligned


def test_density_representatives_average_the_samples_each_output_time_covers(rng):
    """Euclidean: every representative is the count-weighted average of its stretch
    (samples inside it, topped up to one sample with the aligned point)."""
    from sk_rtw.align._density import HALF_WIDTH

    E = Euclidean(2)
    series = [rng.standard_normal((37, 2)), rng.standard_normal((23, 2))]
    z = np.linspace(0, 1, 30)
    warps = np.stack([z**1.7, np.sqrt(z)])  # compressed and stretched parts
    v, w, aligned = _density(E, series, warps)
    for n, s in enumerate(series):
        tau = warps[n] * (len(s) - 1)
        bounds = np.concatenate([[-0.5], (tau[:-1] + tau[1:]) / 2, [len(s) - 0.5]])
        for k in range(len(z)):
            lo, hi = bounds[k], bounds[k + 1]
            i = np.arange(len(s))
            mass = np.clip(np.minimum(i + HALF_WIDTH, hi) - np.maximum(i - HALF_WIDTH, lo),
                           0, None) / (2 * HALF_WIDTH)  # fmt: skip
            count = max(mass.sum(), 1.0)
            expected = (mass @ s + (count - mass.sum()) * aligned[n, k].numpy()) / count
            np.testing.assert_allclose(v[n, k].numpy(), expected, atol=1e-12)
            assert w[n, k].item() == pytest.approx(count)
        assert w[n].sum() >= len(s) - 1e-9  # every sample counted once, empty stretches once


def test_density_mean_from_dtw_runs_is_dbas_update(rng):
    """A DTW path matching every mean sample to its own run of series samples: warps read
    off it (no smoothing) give stretches equal to the runs, and the density-weighted mean
    equals DBA's update, the average of every matched sample."""
    from sk_rtw.align._start import path_warp
    from sk_rtw.manifolds._mean import frechet_mean

    E = Euclidean(3)
    n_mean = 25
    series, paths = [], []
    for _ in range(4):
        # runs of 1 to 5 samples whose neighbours differ by at most one, one at the ends
        walk = np.clip(np.cumsum(rng.integers(-1, 2, n_mean)) + 3, 1, 5)
        edge = np.minimum(np.arange(1, n_mean + 1), np.arange(n_mean, 0, -1))
        runs = np.minimum(walk, edge).tolist()
        starts = np.concatenate([[0], np.cumsum(runs)[:-1]])
        series.append(rng.standard_normal((sum(runs), 3)))
        paths.append(np.array([(m, j) for m, (a, r) in enumerate(zip(starts, runs, strict=True))
                               for j in range(a, a + r)]))  # fmt: skip
    warps = np.stack(
        [path_warp(p, n_mean, len(s), smoothing=0) for p, s in zip(paths, series, strict=True)]
    )
    v, w, _ = _density(E, series, warps)
    mean = frechet_mean(E, v, w)[0].numpy()
    sums, counts = np.zeros((n_mean, 3)), np.zeros(n_mean)
    for p, s in zip(paths, series, strict=True):
        np.add.at(sums, p[:, 0], s[p[:, 1]])
        np.add.at(counts, p[:, 0], 1)
    np.testing.assert_allclose(mean, sums / counts[:, None], atol=1e-12)


@pytest.mark.parametrize("manifold", CURVED, ids=repr)
def test_density_representatives_on_curved_manifolds(manifold):
    """Curved spaces: a stretch of one sample gives that sample back; a stretch of many
    gives the tangent-space average at the aligned point (an independent loop here), on
    the manifold."""
    data = make_warped_signals(manifold, 2, 30, 3)
    series = list(data.signals)
    z = np.linspace(0, 1, 20)
    warps = np.stack([z**3.0, z])
    v, w, aligned = _density(manifold, series, warps)
    manifold.validate(v.numpy(), atol=1e-8)
    tau = warps[0] * 29
    bounds = np.concatenate([[-0.5], (tau[:-1] + tau[1:]) / 2, [29.5]])
    k = int(np.argmax(w[0].numpy()))  # the compressed end: a stretch of many samples
    inside = np.flatnonzero((np.arange(30) > bounds[k]) & (np.arange(30) < bounds[k + 1]))
    assert len(inside) > 3 and w[0, k].item() == pytest.approx(len(inside))
    anchor = aligned[0, k].numpy()
    logs = np.stack([manifold.log(anchor, series[0][i]) for i in inside])
    np.testing.assert_allclose(v[0, k].numpy(), manifold.exp(anchor, logs.mean(0)), atol=1e-10)
    # the identity warp of a series of 20 samples at 20 output times: one sample each
    same = np.linspace(0, 1, 20)
    v1, w1, _ = _density(manifold, [series[1][:20]], same[None])
    np.testing.assert_allclose(w1.numpy(), 1.0)
    np.testing.assert_allclose(v1[0].numpy(), series[1][:20], atol=1e-10)


def test_density_weighted_alignment_and_its_gradient():
    data = make_warped_signals("sphere", 5, 40, 2)
    result = align(data.signals, manifold="sphere", mean_weights="density", n_epochs=20,
                   random_state=0)  # fmt: skip
    assert result.config.mean_weights == "density"
    Sphere(1).validate(result.mean)
    assert np.nanmin(result.loss_history) <= result.loss_history[0]
    with pytest.raises(ValueError, match="mean_weights"):
        align(data.signals, mean_weights="counts")


def test_the_engines_adam_is_torchs_fused_adam_bit_for_bit():
    from sk_rtw.align._adam import FusedAdam

    torch.manual_seed(0)
    start = [torch.randn(5, 3, dtype=torch.float64), torch.randn(7, dtype=torch.float64)]
    ours = [p.clone().requires_grad_() for p in start]
    theirs = [p.clone().requires_grad_() for p in start]
    mine, reference = FusedAdam(ours, lr=0.01), torch.optim.Adam(theirs, lr=0.01, fused=True)
    for step in range(20):
        for params, optimiser in ((ours, mine), (theirs, reference)):
            optimiser.zero_grad(set_to_none=True)
            loss = (params[0] ** 3).sum() + torch.sin(params[1]).sum() * (step + 1)
            loss.backward()
            optimiser.step()
        for a, b in zip(ours, theirs, strict=True):
            assert torch.equal(a, b), step
    assert not torch.equal(ours[0], start[0])  # it moved


def test_the_torch_floor_is_read_from_the_version():
    from sk_rtw.align._adam import MIN_TORCH, _release

    assert _release("2.13.0+cpu") == (2, 13) and _release("2.4.0a0+git1234") == (2, 4)
    assert _release("2.3.1+cu121") < MIN_TORCH <= _release("2.4.1") <= _release(torch.__version__)
    # the floor is the one pyproject.toml declares
    pyproject = (Path(__file__).parents[1] / "pyproject.toml").read_text()
    assert f'"torch>={MIN_TORCH[0]}.{MIN_TORCH[1]}"' in pyproject


@pytest.mark.parametrize("manifold", ["euclidean", "quaternion", "spd"])
@pytest.mark.parametrize("window", [None, 0.2])
def test_the_dtw_starts_path_warps_are_those_of_each_pairs_path(manifold, window):
    """The DTW start reads the warps of the exact pairs off one compiled pass; they equal,
    value for value, path_warp of each pair's path (multiscale_path without a band,
    path_indices in one), with groups of unequal reference lengths, and the smoothing
    equals np.pad's odd reflection."""
    from sk_rtw.align._start import _path_warps, _smooth_monotone, path_warp
    from sk_rtw.dtw import multiscale_path, path_indices

    data = make_warped_signals(manifold, 5, 50, 3, strength=0.9)
    M, series = data.manifold, [s[: 50 - 3 * n] for n, s in enumerate(data.signals)]
    references = [data.signals[0][:44], data.signals[1][::2]]
    codes = np.array([0, 1, 0, 1, 1])
    stacked = np.zeros((5, 50, int(np.prod(series[0].shape[1:]))))
    for n, s in enumerate(series):
        stacked[n, : len(s)] = s.reshape(len(s), -1)
    lengths = np.array([len(s) for s in series])
    got = _path_warps(references, series, (stacked, lengths), codes, M, window, None)
    for n, s in enumerate(series):
        reference = references[codes[n]]
        if window is None:
            path = multiscale_path(reference, s, M, squared=True)[0]
        else:
            path = path_indices(reference, s, M, window, squared=True)[0]
        np.testing.assert_array_equal(got[n], path_warp(path, len(reference), len(s)))
    warp = np.sort(np.random.default_rng(0).random(9))
    for sigma in (0.7, 2.0, 5.0):  # radius 3, 6 and capped at len - 1
        radius = min(int(np.ceil(3 * sigma)), 8)
        kernel = np.exp(-0.5 * (np.arange(-radius, radius + 1) / sigma) ** 2)
        smooth = np.convolve(np.pad(warp, radius, mode="reflect", reflect_type="odd"),
                             kernel / kernel.sum(), mode="valid")  # fmt: skip
        smooth = np.maximum.accumulate(
            np.clip((smooth - smooth[0]) / (smooth[-1] - smooth[0]), 0.0, 1.0)
        )
        np.testing.assert_array_equal(_smooth_monotone(warp, sigma), smooth)
