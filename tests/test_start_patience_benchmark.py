"""The start-patience benchmark's replay: the trainer's rule, and its tables from a file."""

from __future__ import annotations

import json

import numpy as np
import pytest

from benchmarks import start_patience as bench
from sk_rtw.align._training import EARLY_PATIENCE, FAR_FROM_START, NEAR_START

from .test_training import run_scripted

# a fall back within 2.5 times at epoch 3; one far until epoch 9 (20 times the start's
# after two epochs: not beyond the early tier); one that beats the start; one beyond the
# early tier after two epochs
_HISTORIES = [
    [1.0, 9.0, 4.0, 2.2, 1.5, 1.2, 1.1, 0.98, 0.97, 0.96, 0.95, 0.95],
    [1.0, 40.0, 20.0, 9.0, 6.0, 5.0, 4.0, 3.5, 3.0, 0.9, 0.8, 0.7],
    [1.0, 0.9, 0.8, 0.85, 0.9, 0.95, 1.0, 1.1, 1.2, 1.3, 1.4, 1.5],
    [1.0, 300.0, 21.0, 19.0, 9.0, 5.0, 4.0, 3.0, 2.0, 1.5, 1.2, 1.1],
]


def _trainer_epochs(histories, patience):
    """Epochs each group runs in the trainer fed the scripted losses."""
    trainer, _ = run_scripted(histories, patience)
    return list(trainer.progress.epochs_run.numpy())


@pytest.mark.parametrize("patience", [2, 4, 8])
def test_the_replay_stops_where_the_trainer_stops(patience):
    histories = [np.asarray(h) for h in _HISTORIES]
    tier = (EARLY_PATIENCE, FAR_FROM_START)
    replayed = [bench.stop_epoch(h, patience, NEAR_START, tier) for h in histories]
    trainer = _trainer_epochs(_HISTORIES, patience)
    assert replayed == trainer
    # the last history is stopped by the early tier, after three epochs (patience > 3)
    assert trainer[3] == min(patience, 3)
    assert bench.stop_epoch(histories[3], patience, NEAR_START) == patience


def test_replay_counts_epochs_and_losing_groups():
    histories = [np.asarray(h) for h in _HISTORIES[:3]]
    # patience 8: the far group stops at epoch 8 keeping the start (1.0) where training
    # would have reached 0.7; the others run to the end
    fraction, losing, worst = bench.replay(histories, 8, 2.5)
    assert (fraction, losing) == ((8 + 12 + 12) / 36, 1) and worst == pytest.approx(1 / 0.7)
    # patience 10: nobody stops early
    assert bench.replay(histories, 10, 2.5) == (1.0, 0, 1.0)
    # an early tier after 2 epochs at 30 times stops the far one at epoch 2 instead of 8
    fraction, losing, worst = bench.replay(histories, 8, 2.5, (2, 30.0))
    assert (fraction, losing) == ((2 + 12 + 12) / 36, 1) and worst == pytest.approx(1 / 0.7)


def test_replay_prints_the_tables_of_an_earlier_run(tmp_path, capsys):
    (tmp_path / "histories.json").write_text(json.dumps({"scripted": _HISTORIES[:3]}))
    quality = {"epochs": 12, "loss": 1.0, "truth": 0.5, "seconds": 1.0}
    rows = [{"space": "euclidean", "n": 4, "seed": 0, "full": quality, "cut": quality,
             "default": quality, "seeds": [0.5, 0.51, 0.49]}]  # fmt: skip
    (tmp_path / "synthetic_quality.json").write_text(json.dumps(rows))
    bench.main(["--replay", str(tmp_path)])
    out = capsys.readouterr().out
    assert "| patience 8, near 2.5 | 0.89, 1, 1.429 |" in out
    assert "| none | 0.89, 1, 1.429 |" in out and "| after 2, far 20 | 0.72, 1, 1.429 |" in out
    assert "| euclidean, N = 4 | 4.00%, 4.00% | 0 of 1; +0.0%, +0.0%; +0.00%, +0.00% |" in out
