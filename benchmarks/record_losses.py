"""Every training group's loss history from any script, recorded with ``start_patience`` off.

Usage::

    python benchmarks/record_losses.py --out results/losses -- benchmarks/paper/pose.py --seed 0
    python benchmarks/record_losses.py --out results/losses -- benchmarks/paper/spd.py --sizes 2
    python benchmarks/start_patience.py --replay results/losses     # the rules replayed

The script after ``--`` runs in this process with its own arguments; every trainer of the
RTW engine it creates (``align``, the estimators, the paper scripts' methods) runs with
``start_patience=None``, so each group trains for as long as the no-change stop lets it,
and each group's losses are kept when its training ends. They are added to
``<out>/histories.json`` under the script's command line, in the format that
``benchmarks/start_patience.py --replay`` reads: the replay then gives the epochs each
group would run under a rule and the loss it would keep (the rules only end a group
early). This is how the paper tables and the poses at full resolution were checked
against the stop's tiers (docs/benchmarks/align_speed.md).
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import json
import runpy
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository; then _shared

from benchmarks._shared import check_writable


@contextlib.contextmanager
def recording_trainers(store: list[list[float]]):
    """Within the block every :class:`Trainer` runs without ``start_patience`` and appends
    each group's losses to ``store`` when the group has stopped (or the run has ended)."""
    training = importlib.import_module("sk_rtw.align._training")
    trainer = training.Trainer
    original_init, original_run = trainer.__init__, trainer.run

    def __init__(self, *args, **kwargs):
        kwargs["start_patience"] = None
        original_init(self, *args, **kwargs)

    def run(self, *args, **kwargs):
        best = original_run(self, *args, **kwargs)
        history = self.progress.history.cpu().numpy()
        epochs = self.progress.epochs_run.cpu().numpy()
        running = self.progress.active.cpu().numpy()
        for group in range(history.shape[1]):
            # a paused run hands its running groups to a narrowed trainer, which records them
            if best is not None or not running[group]:
                store.append(history[: epochs[group], group].tolist())
        return best

    trainer.__init__, trainer.run = __init__, run
    try:
        yield store
    finally:
        trainer.__init__, trainer.run = original_init, original_run


def main(argv=None) -> None:
    argv = sys.argv[1:] if argv is None else argv
    if "--" not in argv:
        raise SystemExit("usage: record_losses.py --out DIR -- SCRIPT [ARGS ...]")
    split = argv.index("--")
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default="results/losses", help="directory of histories.json")
    args = parser.parse_args(argv[:split])
    command = argv[split + 1 :]
    if not command:
        parser.error("name the script to run after --")
    out = Path(args.out)
    check_writable(out, directory=True)
    store: list[list[float]] = []
    saved_argv = sys.argv
    sys.argv = list(command)
    try:
        with recording_trainers(store):
            runpy.run_path(command[0], run_name="__main__")
    finally:
        sys.argv = saved_argv
        out.mkdir(parents=True, exist_ok=True)
        path = out / "histories.json"
        sets = json.loads(path.read_text()) if path.exists() else {}
        sets[" ".join(command)] = store
        path.write_text(json.dumps(sets))
        print(f"{len(store)} loss histories of `{' '.join(command)}` kept in {path}")


if __name__ == "__main__":
    main()
