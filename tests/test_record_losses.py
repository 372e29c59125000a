"""benchmarks/record_losses.py: every group's losses of a script, the stop off, in the
format the start-patience replay reads."""

from __future__ import annotations

import json
import textwrap

import numpy as np

from benchmarks import record_losses, start_patience
from sk_rtw.align._training import Trainer

SCRIPT = """
import json, sys
import numpy as np
from sk_rtw import RTWAverager, align
from sk_rtw.datasets import make_warped_signals

# long smooth quaternion series: the stop would keep the start after 8 epochs
X = np.asarray(make_warped_signals("quaternion", 4, 600, random_state=0).signals)
result = align(X, manifold="quaternion", random_state=0)
# three classes in one batch that stop at different epochs: the batch is narrowed
walks = np.random.default_rng(0).standard_normal((4, 40)).cumsum(1)
warped = [np.asarray(make_warped_signals("euclidean", 4, 40, random_state=s).signals)[..., 0]
          for s in (1, 2)]
Y = np.concatenate([walks, warped[0], 3 * warped[1]])
model = RTWAverager(n_centroids=1, random_state=0).fit(Y, np.repeat([0, 1, 2], 4))
histories = [list(map(float, a.loss_history[: a.n_iter])) for a in model.alignments_]
histories.insert(0, list(map(float, result.loss_history[: result.n_iter])))
json.dump(histories, open(sys.argv[1], "w"))
"""


def test_every_group_is_recorded_with_the_stop_off_and_replayed(tmp_path, capsys):
    script = tmp_path / "fits.py"
    script.write_text(textwrap.dedent(SCRIPT))
    fitted = tmp_path / "fitted.json"
    original = Trainer.__init__, Trainer.run
    out = tmp_path / "losses"
    record_losses.main(["--out", str(out), "--", str(script), str(fitted)])
    assert (Trainer.__init__, Trainer.run) == original  # the trainer is itself again
    recorded = json.loads((out / "histories.json").read_text())
    (histories,) = recorded.values()
    expected = json.loads(fitted.read_text())
    # the long series trained for the no-change stop's 21 epochs, not the stop's 8; the
    # classes ran different numbers of epochs (their batch was narrowed on the way)
    assert len(expected[0]) == 21 and len({len(h) for h in expected[1:]}) > 1
    assert sorted(map(tuple, histories)) == sorted(map(tuple, expected))
    capsys.readouterr()
    start_patience.main(["--replay", str(out)])
    replayed = capsys.readouterr().out
    stopped = start_patience.stop_epoch(np.asarray(expected[0]), 8, 2.5)
    assert stopped == 8 and "| patience 8, near 2.5 |" in replayed
