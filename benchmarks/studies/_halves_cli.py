"""The command line and the record file shared by the per-half UCR studies
(``forest_measures.py``, ``representation_choice.py``): a data directory, fixed halves,
seeds, and JSON lines appended one dataset at a time, so that a rerun skips what is
there."""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.ucr._summary import FIXED_HALVES


def halves_parser(description: str, *, out_required: bool = True) -> argparse.ArgumentParser:
    """``--data-dir``, ``--halves`` (default A and B), ``--seeds`` (default 0), ``--out``."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--data-dir", required=True)
    parser.add_argument("--halves", nargs="+", default=["A", "B"], choices=list(FIXED_HALVES))
    parser.add_argument("--seeds", nargs="+", type=int, default=[0])
    parser.add_argument("--out", type=Path, required=out_required)
    return parser


def read_records(path: Path | None) -> list[dict]:
    """The records already in ``path`` (none if it is None or absent)."""
    if path is None or not path.exists():
        return []
    return [json.loads(line) for line in path.read_text().splitlines()]


def append_record(path: Path | None, record: dict) -> None:
    """Append ``record`` to ``path`` as one JSON line (nothing if it is None)."""
    if path is None:
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("a") as handle:
        handle.write(json.dumps(record) + "\n")


def measure_missing(
    args: argparse.Namespace, records: list[dict], measure: Callable[[str, int, str], dict]
) -> Iterator[dict]:
    """``measure(name, seed, data_dir)`` for every dataset of ``args.halves`` and seed of
    ``args.seeds`` that ``records`` lacks; each new record is added to ``records``,
    appended to ``args.out`` and yielded."""
    done = {(r["dataset"], r["seed"]) for r in records}
    for seed in args.seeds:
        for half in args.halves:
            for name in FIXED_HALVES[half]:
                if (name, seed) in done:
                    continue
                record = measure(name, seed, args.data_dir)
                records.append(record)
                append_record(args.out, record)
                yield record


def print_half_means(records: list[dict], args: argparse.Namespace, columns: list[str]) -> None:
    """A markdown table of the mean of every column, per half and seed of ``args``."""
    print(f"\n| half | seed | sets | {' | '.join(columns)} |\n|{' --- |' * (len(columns) + 3)}")
    for seed in args.seeds:
        for half in args.halves:
            members = FIXED_HALVES[half]
            rows = [r for r in records if r["dataset"] in members and r["seed"] == seed]
            if rows:
                means = " | ".join(f"{np.mean([r[c] for r in rows]):.4f}" for c in columns)
                print(f"| {half} | {seed} | {len(rows)} | {means} |", flush=True)



def score_variants(
    name: str, seed: int, data_dir: str, variants: list[str],
    build: Callable[[str, int], Any], clock: Callable[[], float],
) -> dict:
    """One record: for every variant, ``build(variant, seed)`` fitted on the training
    split of ``name`` and scored on its test split, with its fit and prediction seconds
    (``clock``)."""
    from benchmarks.ucr._data import load_split

    train, test = load_split(name, "train", data_dir), load_split(name, "test", data_dir)
    record: dict = {"dataset": name, "seed": seed}
    for variant in variants:
        model = build(variant, seed)
        start = clock()
        model.fit(train.X, train.y)
        fit = clock() - start
        start = clock()
        record[variant] = float(np.mean(model.predict(test.X) == test.y))
        record[f"{variant}_fit"] = fit
        record[f"{variant}_predict"] = clock() - start
    print(name, seed, {v: round(record[v], 4) for v in variants}, flush=True)
    return record


def run_variants(
    description: str, variants: dict, build: Callable[[str, int], Any],
    clock: Callable[[], float] = time.perf_counter,
) -> None:
    """The command line of a study of named ``variants``: ``--variants`` (default all),
    the records of ``--out`` that hold every variant asked for, :func:`score_variants`
    for the datasets and seeds they lack, the means per half."""
    parser = halves_parser(description, out_required=False)
    parser.add_argument("--variants", nargs="+", default=list(variants), choices=list(variants))
    args = parser.parse_args()
    records = [r for r in read_records(args.out) if all(v in r for v in args.variants)]

    def one(name: str, seed: int, data_dir: str) -> dict:
        return score_variants(name, seed, data_dir, args.variants, build, clock)

    for _ in measure_missing(args, records, one):
        pass
    print_half_means(records, args, args.variants)
