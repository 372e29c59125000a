"""The optimisation: the trainer (best iterates, early stops, narrowing), groups in one
batch, the engine's fused Adam and the torch it needs."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch

from sk_rtw.align import align
from sk_rtw.align._training import Trainer
from sk_rtw.datasets import make_warped_signals


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

# ------------------------------------------------------------ groups in one batch
def _groups_data():
    a = make_warped_signals("sphere", 5, 40, 1).signals
    b = make_warped_signals("sphere", 3, 30, 2).signals
    return list(a) + list(b), np.array([0] * 5 + [1] * 3)


@pytest.mark.parametrize(
    ("method", "dtype"),
    [("rtw", "float64"), ("rtw", "float32"), ("ttw", None), ("ntw", "float64"),
     ("ntw", "float32")],
)  # fmt: skip
def test_groups_in_one_batch_equal_separate_fits(method, dtype):
    """In float64 to rounding; a float32 network's batched products round differently
    from one group's (another blocking of the same sums), within float32's precision."""
    from sk_rtw.align import align_collection, resolve_config
    from sk_rtw.utils import check_series_collection

    series, codes = _groups_data()
    collection = check_series_collection(series, "sphere")
    knobs = {"output_length": 50, "n_epochs": 30, **({"warp_dtype": dtype} if dtype else {})}
    config = resolve_config(method, "alignment", knobs)
    # align(random_state=s) seeds its one group with the first draw of default_rng(s)
    seeds = [int(np.random.default_rng(s).integers(2**31 - 1)) for s in (11, 22)]
    batch = align_collection(collection, codes, seeds, config)
    tol = 1e-4 if dtype == "float32" else 1e-9
    # each epoch's loss carries the float32 warps' rounding differences through the Adam
    # steps before it; how far depends on the CPU's float32 kernels (1.5e-4 relative in
    # one of 30 epochs on one machine, under 1e-4 on another)
    loss_tol = 1e-3 if dtype == "float32" else tol
    for g, seed in enumerate((11, 22)):
        alone = align(
            [s for s, c in zip(series, codes, strict=True) if c == g], manifold="sphere",
            method=method, random_state=seed, **knobs,
        )  # fmt: skip
        assert batch[g].n_iter == alone.n_iter and batch[g].best_epoch == alone.best_epoch
        np.testing.assert_allclose(batch[g].warps, alone.warps, atol=tol)
        np.testing.assert_allclose(batch[g].mean, alone.mean, atol=tol)
        np.testing.assert_allclose(batch[g].loss_history, alone.loss_history, rtol=loss_tol)


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
    # a float32 network's batched products may take another kernel for fewer groups on
    # some CPUs (another blocking of the same sums): its last bits, 1e-9 in the warps
    tol = 1e-7 if config.warp_dtype == "float32" else 1e-12
    for a, b in zip(narrowed, whole, strict=True):
        assert a.n_iter == b.n_iter and a.best_epoch == b.best_epoch
        np.testing.assert_allclose(a.warps, b.warps, rtol=0, atol=tol)
        np.testing.assert_allclose(a.mean, b.mean, rtol=0, atol=tol)
        np.testing.assert_allclose(a.loss_history, b.loss_history, rtol=tol)
        assert a.cost == pytest.approx(b.cost, rel=tol)


def test_group_layout_sums_and_broadcasts():
    from sk_rtw.align._layout import GroupLayout

    layout = GroupLayout.from_codes([2, 0, 2, 1, 0])
    assert layout.sizes.tolist() == [2, 1, 2] and layout.positions.tolist() == [0, 0, 1, 0, 1]
    values = torch.arange(5.0)
    assert layout.sum(values).tolist() == [1 + 4, 3, 0 + 2]
    assert layout.expand(torch.tensor([10.0, 20.0, 30.0])).tolist() == [30, 10, 30, 20, 10]
    with pytest.raises(ValueError, match="no series"):
        GroupLayout.from_codes([0, 2])

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


def _start_rule_reference(history, patience, near=2.5, early=3, far=20.0):
    """Epochs a group runs under ``start_patience`` alone, written from its statement:
    after ``patience`` epochs, stop if the lowest loss since the first epoch is still
    more than ``near`` times the first epoch's; after ``early`` epochs, if it is more
    than ``far`` times it."""
    for epoch in range(1, len(history)):
        low, done = min(history[1 : epoch + 1]), epoch + 1
        if (done >= patience and low > near * history[0]) or (
            done >= early and low > far * history[0]
        ):
            return done
    return len(history)


def test_the_start_rule_constants_are_the_documented_ones():
    from sk_rtw.align._training import EARLY_PATIENCE, FAR_FROM_START, NEAR_START

    assert (NEAR_START, EARLY_PATIENCE, FAR_FROM_START) == (2.5, 3, 20.0)


# scripted losses (relative to the start's): the long demonstrations' far and slowly
# falling climb-down; a short series' return that beats the start at epoch 8; one that
# stays near the start (the no-change stop's case, not this rule's); one beaten at once;
# one thrown far that comes back within 2.5 times the start's loss at epoch 4; one thrown
# very far that is within 20 times the start's after two epochs and beats it at epoch 7
_SCRIPTS = {
    "far, falling": [1.0, 136.5, 26.0, 19.6, 22.3, 12.8, 4.1, 4.3, 2.2, 3.5, 3.1, 2.9, 2.2],
    "very far, back": [1.0, 90.0, 19.0, 6.0, 2.0, 1.3, 1.1, 0.99, 0.98, 0.97, 0.96, 0.96],
    "near, falling back": [1.0, 1.54, 1.06, 1.02, 1.1, 1.06, 1.01, 1.005, 0.97, 0.95, 0.96],
    "near, stalled": [1.0, 1.3, 1.2, 1.25, 1.3, 1.21, 1.22, 1.24, 1.2, 1.23, 1.25, 1.22],
    "beaten": [1.0, 0.9, 1.4, 1.5, 1.6, 1.4, 1.5, 1.45, 1.6, 1.5, 1.55, 1.5, 1.6],
    "back at epoch 4": [1.0, 20.8, 3.2, 3.7, 1.9, 2.4, 1.1, 1.6, 1.3, 1.04, 1.1, 0.98],
}


def run_scripted(losses, start_patience):
    """A trainer whose groups' losses follow the scripts ``losses`` (the no-change stop
    out of the way), run for the shortest script's epochs: ``(trainer, best epochs)``."""
    scripts = [torch.tensor(s, dtype=torch.float64) for s in losses]
    weight = torch.nn.Parameter(torch.zeros(len(scripts), 1, dtype=torch.float64))
    epoch = [0]

    def loss_fn():
        values = torch.stack([s[epoch[0]] for s in scripts]) + 0.0 * weight[:, 0]
        epoch[0] += 1
        return values.sum(), values

    trainer = Trainer(loss_fn, [weight], min(len(s) for s in scripts), 0.1,
                      parameter_groups=[torch.arange(len(scripts))], n_groups=len(scripts),
                      n_iter_no_change=100, tol=1e-3, start_patience=start_patience)  # fmt: skip
    return trainer, trainer.run(lambda done, history: None, 50)


@pytest.mark.parametrize("patience", [2, 3, 6, 8])
def test_start_patience_stops_each_group_as_the_rule_says(patience):
    """Five groups in one loop, each following a scripted loss: each runs the epochs
    the rule's plain statement gives it (no-change patience out of the way), keeps the
    start where it stopped, and its losses equal the script's."""
    scripts = [torch.tensor(s, dtype=torch.float64) for s in _SCRIPTS.values()]
    n_epochs = min(len(s) for s in scripts)
    trainer, best = run_scripted(scripts, patience)
    runs = trainer.progress.epochs_run.numpy()
    expected = [_start_rule_reference(s[:n_epochs].numpy(), patience) for s in scripts]
    assert list(runs) == expected
    for g, script in enumerate(scripts):
        np.testing.assert_array_equal(trainer.progress.history[: runs[g], g], script[: runs[g]])
        assert best[g] == int(np.argmin(script[: runs[g]]))
    far, very_far_back, back, stalled, beaten, back_at_4 = runs
    # 26 times the start's after two epochs: the early tier stops it at the third
    assert far == min(patience, 3) and back == stalled == beaten == n_epochs
    assert back_at_4 == (patience if patience <= 4 else n_epochs)
    # 19 times after two epochs is not far enough for the early tier
    assert very_far_back == (patience if patience <= 4 else n_epochs)
    if patience >= 6:  # what the rule is for: only the far group stops, keeping the start
        assert best[0] == 0 and list(runs[1:]) == [n_epochs] * 5
        assert best[1] == int(np.argmin(scripts[1][:n_epochs]))  # beat the start


def test_the_start_rule_returns_the_start_where_training_cannot_beat_it():
    """Long smooth quaternion series: Adam's first step from the DTW start raises the
    loss a hundredfold and training never beats the start. With the rule the same start
    is returned after start_patience epochs instead of n_iter_no_change: the same warps
    bit for bit, the same mean to rounding (its Gauss–Newton starts from the last
    epoch's mean, which differs)."""
    X = np.asarray(make_warped_signals("quaternion", 4, 600, random_state=0).signals)
    kept = align(X, manifold="quaternion", random_state=0)
    full = align(X, manifold="quaternion", random_state=0, start_patience=None)
    assert full.best_epoch == kept.best_epoch == 0
    assert kept.n_iter == kept.config.start_patience == 8 and full.n_iter == 21
    np.testing.assert_array_equal(kept.warps, full.warps)
    np.testing.assert_allclose(kept.mean, full.mean, rtol=0, atol=1e-13)


def test_the_early_tier_returns_the_start_after_three_epochs_on_long_series(capsys):
    """2,000 quaternion samples: two epochs after the start the loss is still more than
    20 times the start's (long demonstrations: 23-2,200 times); the early tier returns
    the same start after 3 epochs, and says which rule stopped the fit."""
    from sk_rtw.align._training import EARLY_PATIENCE, FAR_FROM_START

    X = np.asarray(make_warped_signals("quaternion", 4, 2000, random_state=0).signals)
    kept = align(X, manifold="quaternion", random_state=0, verbose=True)
    err = capsys.readouterr().err
    full = align(X, manifold="quaternion", random_state=0, start_patience=None)
    history = np.asarray(full.loss_history[: full.n_iter])
    assert history[1:EARLY_PATIENCE].min() > FAR_FROM_START * history[0]
    assert full.best_epoch == kept.best_epoch == 0
    assert kept.n_iter == EARLY_PATIENCE < kept.config.start_patience
    np.testing.assert_array_equal(kept.warps, full.warps)
    np.testing.assert_allclose(kept.mean, full.mean, rtol=0, atol=1e-13)
    assert (
        "stopped early after 3 of 256 epochs: after 3 epochs the loss was still more "
        "than 20 times the start's" in err
    )
