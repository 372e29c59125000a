"""The evidence behind ``start_patience``: recorded losses, and the rule replayed on them.

Usage::

    python benchmarks/start_patience.py --data-dir ../shared/ucr --seeds 0 1 2
    python benchmarks/start_patience.py --skip-ucr          # synthetic and long series only
    python benchmarks/start_patience.py --replay results/start_patience   # no fits

Every fit runs with ``start_patience=None`` (training from the DTW start for as long as
the no-change stop lets it) and keeps each group's loss history:

* UCR (``--data-dir``, every dataset there): the benchmark's ``rtw`` row (one mean per
  class) and ``rtw-default`` row (the default classifier's centroids), for each seed;
* synthetic: ``make_warped_signals`` on R^1, S^1, S^3 and SPD(2), N = 4 and 30, T = 100,
  five data seeds, ``align``'s defaults;
* long: 8 unit-quaternion series of 1,000, 4,000 and 16,000 samples (the
  long-demonstrations page's data), three seeds.

The rule is then replayed on every history: after ``patience`` epochs a group whose lowest
loss since the first epoch is more than ``near`` times the first epoch's stops and keeps
the start. A second table adds the rule's early tier to the default (``patience`` 8,
``near`` 2.5): after ``early`` epochs a group still more than ``far`` times the start's
stops too; the trainer's tier is ``EARLY_PATIENCE``, ``FAR_FROM_START``. Because the
rule only ends a group early (the trajectory up to its stop is the recorded one, also
inside a batch), the replay gives exactly the epochs each group would run and the loss it
would keep. Printed per data set and rule: the fraction of epochs run, the groups that
would keep a worse loss than without the rule, and the worst such loss ratio. For the
synthetic sets, whose clean signal is known, a third table scores the
default (``start_patience`` as the preset sets it) and a shorter rule (:data:`CUT`)
against training to the end by the mean's DTW distance to that signal, next to the
spread of training seeds. ``--out`` keeps what was recorded (JSON); ``--replay`` reads an
earlier ``--out`` and prints the tables without fitting.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository; then _shared

import numpy as np

from benchmarks._shared import check_writable
from sk_rtw.align._training import EARLY_PATIENCE, FAR_FROM_START

#: Rules replayed: ``start_patience`` values and multiples of the start's loss.
PATIENCES = (4, 6, 8, 10)
NEARS = (1.5, 2.0, 2.5, 3.0)
#: Early tiers replayed with the default rule: (epochs, multiple of the start's loss).
EARLY_TIERS = (None, (2, 20.0), (3, 5.0), (3, 10.0), (3, 20.0), (3, 50.0), (4, 10.0),
               (4, 20.0))  # fmt: skip
#: The default rule the early tiers are added to.
DEFAULT_RULE = (8, 2.5)


def stop_epoch(
    history: np.ndarray, patience: int, near: float, early: tuple[int, float] | None = None
) -> int:
    """Epochs a group runs under the rule (the whole history where it never fires);
    ``early``: the tier ``(epochs, far)`` that stops a group still more than ``far``
    times the start's loss after ``epochs`` epochs."""
    for epoch in range(1, len(history)):
        low, done = np.nanmin(history[1 : epoch + 1]), epoch + 1
        if done >= patience and low > near * history[0]:
            return done
        if early is not None and done >= early[0] and low > early[1] * history[0]:
            return done
    return len(history)


def replay(
    histories: list[np.ndarray],
    patience: int,
    near: float,
    early: tuple[int, float] | None = None,
) -> tuple[float, int, float]:
    """Fraction of the epochs run, groups keeping a worse loss, the worst loss ratio."""
    run = full = losing = 0
    worst = 1.0
    for history in histories:
        stop = stop_epoch(history, patience, near, early)
        run, full = run + stop, full + len(history)
        kept, best = np.nanmin(history[:stop]), np.nanmin(history)
        if kept > best:
            losing, worst = losing + 1, max(worst, kept / best)
    return run / max(full, 1), losing, worst


def _histories(alignments) -> list[list[float]]:
    return [
        np.asarray(a.loss_history[: a.n_iter], dtype=float).tolist()
        for a in alignments
        if getattr(a, "n_iter", 0) > 1
    ]


def ucr_histories(data_dir: str, seed: int) -> list[list[float]]:
    from benchmarks.ucr._data import available_datasets, load_split
    from sk_rtw import RTWNearestCentroid
    from sk_rtw.methods import RTW

    out = []
    for name in available_datasets(data_dir):
        train = load_split(name, "train", data_dir)
        method = RTW(n_epochs=256, start_patience=None)
        for extra in ({"n_centroids": 1, "dtw_window": None}, {}):
            model = RTWNearestCentroid(method=method, random_state=seed, **extra)
            out += _histories(model.fit(train.X, train.y).alignments_)
    return out


#: The shorter rule the synthetic table also scores (what a cut at 6 epochs and twice the
#: start's loss would give up).
CUT = (6, 2.0)


def _scored_fit(X, space: str, original, **kwargs) -> tuple[object, dict]:
    """``align`` on ``X``, scored by the mean's DTW distance to the clean signal."""
    from sk_rtw import align, metrics

    result = align(X, manifold=space, **kwargs)
    mean_error = metrics.barycenter_loss([original], result.mean, space, window=0.1)
    row = {"epochs": int(result.n_iter), "loss": float(result.cost),
           "truth": float(mean_error), "seconds": float(result.fit_time)}  # fmt: skip
    return result, row


def synthetic_histories() -> tuple[list[list[float]], list[dict]]:
    """Histories without the rule, and each set's quality under three stops.

    The quality is the one the data can be scored on: the DTW distance of the mean to the
    clean signal the set was warped from (``metrics.barycenter_loss``, band 0.1), for
    training to the end (training seeds 0, 1 and 2: their spread is the yardstick), for
    the default and for :data:`CUT`. A rule that stops a group at epoch ``e`` keeps its
    best iterate of the first ``e`` epochs, which is what ``n_epochs=e`` keeps.
    """
    from sk_rtw.datasets import make_warped_signals

    out, rows = [], []
    for space in ("euclidean", "sphere", "quaternion", "spd"):
        for n in (4, 30):
            for seed in range(5):
                data = make_warped_signals(space, n, 100, random_state=seed)
                problem = (np.asarray(data.signals), space, np.asarray(data.original))
                full, row_full = _scored_fit(*problem, random_state=0, start_patience=None)
                history = _histories([full])
                out += history
                seeds = [_scored_fit(*problem, random_state=r, start_patience=None)[1]
                         for r in (1, 2)]  # fmt: skip
                stop = stop_epoch(np.asarray(history[0]), *CUT) if history else 0
                cut = row_full
                if 0 < stop < row_full["epochs"]:
                    cut = _scored_fit(*problem, random_state=0, start_patience=None,
                                      n_epochs=stop)[1]  # fmt: skip
                rows.append({
                    "space": space, "n": n, "seed": seed, "full": row_full, "cut": cut,
                    "default": _scored_fit(*problem, random_state=0)[1],
                    "seeds": [row_full["truth"]] + [row["truth"] for row in seeds],
                })  # fmt: skip
    return out, rows


def print_truth(rows: list[dict]) -> None:
    """Per space and N: fits each stop ends early, loss and ground-truth changes."""
    print("\nDistance of the mean to the clean signal: change against training to the end "
          "(median, max over 5 data seeds); the training seeds' spread is (max - min) / "
          "median over random_state 0, 1, 2 of training to the end.\n")  # fmt: skip
    cut = f"patience {CUT[0]}, near {CUT[1]:g}"
    print(f"| set | training seeds' spread (median, max) | default: stopped; loss; distance "
          f"| {cut}: stopped; loss; distance | {cut}: fit time ratio |")  # fmt: skip
    print("| --- | --- | --- | --- | --- |")
    for space in dict.fromkeys(r["space"] for r in rows):
        for n in dict.fromkeys(r["n"] for r in rows if r["space"] == space):
            group = [r for r in rows if r["space"] == space and r["n"] == n]
            spread = [(max(r["seeds"]) - min(r["seeds"])) / np.median(r["seeds"]) for r in group]
            cells = [f"{np.median(spread):.2%}, {max(spread):.2%}"]
            for rule in ("default", "cut"):
                stopped = sum(r[rule]["epochs"] < r["full"]["epochs"] for r in group)
                loss = [r[rule]["loss"] / r["full"]["loss"] - 1 for r in group]
                truth = [r[rule]["truth"] / r["full"]["truth"] - 1 for r in group]
                cells.append(
                    f"{stopped} of {len(group)}; {np.median(loss):+.1%}, {max(loss):+.1%}; "
                    f"{np.median(truth):+.2%}, {max(truth):+.2%}"
                )
            time_ratio = [r["cut"]["seconds"] / r["full"]["seconds"] for r in group]
            cells.append(f"{np.median(time_ratio):.2f}")
            print(f"| {space}, N = {n} | " + " | ".join(cells) + " |")


def long_histories() -> list[list[float]]:
    from sk_rtw import align
    from sk_rtw.datasets import make_warped_signals

    out = []
    for length in (1000, 4000, 16000):
        for seed in range(3):
            X = np.asarray(make_warped_signals("quaternion", 8, length, random_state=seed).signals)
            result = align(X, manifold="quaternion", random_state=seed, start_patience=None)
            out += _histories([result])
    return out


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data-dir", help="UCR archive in aeon's layout (every dataset in it)")
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument("--skip-ucr", action="store_true")
    parser.add_argument("--out", default="results/start_patience", help="histories (JSON)")
    parser.add_argument("--replay", metavar="DIR", help="an earlier --out: replay, no fits")
    args = parser.parse_args(argv)
    if args.replay:
        sets = json.loads((Path(args.replay) / "histories.json").read_text())
        quality = Path(args.replay) / "synthetic_quality.json"
        truth = json.loads(quality.read_text()) if quality.exists() else []
        print(f"replayed from {args.replay}; groups: "
              + ", ".join(f"{k}: {len(v)}" for k, v in sets.items()))  # fmt: skip
    else:
        if not args.skip_ucr and not args.data_dir:
            parser.error("--data-dir is needed for the UCR histories (or --skip-ucr)")
        sets, truth = record(args)
    print_rules(sets)
    if truth:
        print_truth(truth)


def record(args) -> tuple[dict[str, list[list[float]]], list[dict]]:
    """Fit every set with ``start_patience=None``; keep the histories under ``--out``."""
    out = Path(args.out)
    check_writable(out, directory=True)
    import torch

    torch.set_num_threads(1)
    sets: dict[str, list[list[float]]] = {}
    started = time.perf_counter()
    if not args.skip_ucr:
        for seed in args.seeds:
            sets[f"UCR seed {seed}"] = ucr_histories(args.data_dir, seed)
    sets["synthetic (R^1, S^1, S^3, SPD(2))"], truth = synthetic_histories()
    sets["long quaternion series"] = long_histories()
    out.mkdir(parents=True, exist_ok=True)
    (out / "histories.json").write_text(json.dumps(sets))
    (out / "synthetic_quality.json").write_text(json.dumps(truth))
    print(f"recorded in {time.perf_counter() - started:.0f} s; groups: "
          + ", ".join(f"{k}: {len(v)}" for k, v in sets.items()))  # fmt: skip
    return sets, truth


def print_rules(sets: dict[str, list[list[float]]]) -> None:
    """One row per rule replayed, one cell per set of histories."""
    print("\n| rule | " + " | ".join(sets) + " |")
    print("| --- |" + " --- |" * len(sets))
    print("| (cell) |" + " epochs run, groups losing, worst loss ratio |" * len(sets))
    arrays = {k: [np.asarray(h, dtype=float) for h in v] for k, v in sets.items()}
    for patience in PATIENCES:
        for near in NEARS:
            cells = []
            for histories in arrays.values():
                fraction, losing, worst = replay(histories, patience, near)
                cells.append(f"{fraction:.2f}, {losing}, {worst:.3f}")
            print(f"| patience {patience}, near {near:g} | " + " | ".join(cells) + " |")
    patience, near = DEFAULT_RULE
    print(f"\nThe early tier added to patience {patience}, near {near:g} (the trainer's: "
          f"{EARLY_PATIENCE} epochs, {FAR_FROM_START:g} times):\n")  # fmt: skip
    print("| early tier | " + " | ".join(sets) + " |")
    print("| --- |" + " --- |" * len(sets))
    for early in EARLY_TIERS:
        cells = []
        for histories in arrays.values():
            fraction, losing, worst = replay(histories, patience, near, early)
            cells.append(f"{fraction:.2f}, {losing}, {worst:.3f}")
        name = "none" if early is None else f"after {early[0]}, far {early[1]:g}"
        print(f"| {name} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
