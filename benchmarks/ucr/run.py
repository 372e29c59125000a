"""UCR benchmark: DTW averaging and nearest-centroid classification, RTW vs TTW vs NTW.

The paper's section V-A as a rerunnable tool. For each dataset, each method learns one mean
per class from the training split; the script scores the averaging (DTW of every warped
training series to its class mean) and the classification of the test split (nearest
class mean by DTW), runs paired t-tests between the methods, and summarises them across
datasets in the layout of the paper's Table II, with a scatter plot like its Fig. 3.

Examples::

    python benchmarks/ucr/run.py                       # aeon's bundled datasets, offline
    python benchmarks/ucr/run.py --data-dir ../shared/ucr --all --jobs 2 --resume
    python benchmarks/ucr/run.py --data-dir ../shared/ucr --datasets CBF Coffee --methods rtw dba
    python benchmarks/ucr/run.py --methods rtw rtw-paper dba --epochs 64 -v
    python benchmarks/ucr/run.py --all --jobs 8 --backend dask --scheduler tcp://host:8786
    python benchmarks/ucr/run.py --data-dir ../shared/ucr --half A --resamples 10 --jobs 2 \
        --methods rtw-default rtw-prototype 1nn-dtw minirocket --resume

Nothing is downloaded: a dataset must be in --data-dir (aeon's local layout,
<dir>/<name>/<name>_TRAIN.ts) or bundled with aeon (ArrowHead, GunPoint,
ItalyPowerDemand). Unavailable datasets are reported and skipped. Every command-line
value is checked before any work (a --data-dir that does not exist, an --out that
cannot be written, --epochs -1, ... exit with a message). The exit status is 1 when no
dataset could be run, or when every fit of a method failed; 0 otherwise.

On a dask cluster (``--backend dask --scheduler ADDRESS``) the scheduler and workers need
sk_rtw with its aeon extra installed; the script sends its own code to them and checks
every node before the first dataset.

Results (``--out``, default ``results/ucr``)::

    datasets/<name>.json    one file per dataset, written atomically when it finishes:
                            configuration, per-method accuracy, fit time, per-training-
                            series averaging values, per-test-series predictions,
                            probabilities and distances, paired t-tests, errors
    resamples/<name>/resample<r>.json
                            the same for resample r >= 1 (--resamples)
    summary.md              the tables printed at the end (of the archive's split; with
                            --resamples also the means over resamples and paired tests)
    accuracy_scatter.png    RTW against TTW/NTW/DBA accuracy per dataset
    critical_difference.png aeon's critical-difference diagram of the accuracies
    tsml/<Classifier>/Predictions/<name>/testResample<r>.csv
                            tsml-format predictions with per-case probabilities, read by
                            aeon's and tsml-eval's evaluation (benchmarks/ucr/_tsml.py)
    tsml/classification/<measure>/<Classifier>_<measure>.csv
                            a row per dataset, a column per resample: the layout aeon's
                            get_estimator_results(path=...) reads

A dataset's file is written again after each of its methods. ``--resume`` keeps every
method already there that was computed with the same settings (the seed-free 1-NN rows
whatever the seed, so ``cp -r`` of one seed's results and ``--resume --seed 1`` computes
only what depends on the seed), and skips datasets with nothing left: an interrupted run
loses at most the method in progress. A dataset (or a method) that fails is recorded with
its error and the run goes on.
"""

from __future__ import annotations

import argparse
import os
import platform
import shlex
import sys
import time
from dataclasses import replace
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository; then _shared

from benchmarks._shared import (
    check_writable,
    existing_directory,
    job_count,
    non_negative_int,
    output_length,
    positive_float,
    positive_int,
    published_file,
)
from benchmarks.ucr._cluster import connect
from benchmarks.ucr._data import (
    AEON_BUNDLED,
    ENV_DATA_DIR,
    DatasetUnavailable,
    available_datasets,
    check_available,
    default_data_dir,
)
from benchmarks.ucr._protocol import (
    ALL_METHODS,
    DEFAULT_METHODS,
    RunConfig,
    process_dataset,
    read_record,
    record_path,
    reusable,
)
from benchmarks.ucr._published import default_published, published_markdown, read_published
from benchmarks.ucr._resamples import load_resample_records, resamples_markdown
from benchmarks.ucr._summary import (
    FIXED_HALVES,
    critical_difference_plot,
    load_records,
    markdown,
    scatter_plot,
    verdict,
)
from benchmarks.ucr._tsml import export as export_tsml
from sk_rtw.align import PRESETS, check_device


def parse_args(argv=None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(
        description=__doc__.splitlines()[0],
        epilog=__doc__.split("Examples::")[1],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--data-dir",
        type=existing_directory,
        default=default_data_dir(),
        help=f"archive in aeon's local layout, an existing folder (default: ${ENV_DATA_DIR}, "
        "else aeon's own location with its bundled datasets)",
    )
    which = parser.add_mutually_exclusive_group()
    which.add_argument(
        "--datasets",
        nargs="+",
        metavar="NAME",
        help=f"datasets to run (default: aeon's bundled {', '.join(AEON_BUNDLED)})",
    )
    which.add_argument(
        "--all", action="store_true", help="every dataset in --data-dir plus aeon's bundled ones"
    )
    which.add_argument(
        "--half",
        choices=list(FIXED_HALVES),
        help="the datasets of one fixed half: A or B of the development archive, C1 or C2 "
        "of the large training sets (see --halves)",
    )
    parser.add_argument(
        "--methods",
        nargs="+",
        default=list(DEFAULT_METHODS),
        choices=list(ALL_METHODS),
        help="rows to compute (default: all but rtw-paper, which is slow)",
    )
    parser.add_argument(
        "--epochs",
        type=non_negative_int,
        default=256,
        help="training epochs of RTW, TTW, NTW (default 256)",
    )
    parser.add_argument(
        "--max-series-per-class",
        type=positive_int,
        default=None,
        help="train on a seeded random subset of at most this many series "
        "per class (the test split is always complete)",
    )
    parser.add_argument(
        "--output-length",
        type=output_length,
        default=None,
        help="length Z of the means of RTW, TTW, NTW (default: the preset's rule, "
        f"{PRESETS['class-means'].output_length.formula} of each class for the default "
        "rows; DBA's means keep their medoid's length)",
    )
    parser.add_argument("--device", default="cpu", help="torch device: cpu (default), cuda, ...")
    parser.add_argument(
        "--seed",
        type=non_negative_int,
        default=0,
        help="random_state of every method and of subsampling",
    )
    parser.add_argument(
        "--resamples",
        type=positive_int,
        default=1,
        metavar="K",
        help="resamples 0 .. K-1 of every dataset (default 1): 0 is the archive's split, "
        "the others aeon's and tsml-eval's stratified resamples seeded by their number; "
        "every method keeps --seed on every resample",
    )
    parser.add_argument(
        "--jobs", type=job_count, default=1, help="datasets in parallel (-1: one per core)"
    )
    parser.add_argument(
        "--backend",
        default="loky",
        help="joblib backend: loky, threading, multiprocessing or dask",
    )
    parser.add_argument(
        "--scheduler", default=None, help="dask scheduler address (default: a local dask cluster)"
    )
    parser.add_argument(
        "--time-budget",
        type=positive_float,
        default=None,
        help="seconds per dataset; methods not started by then are skipped",
    )
    parser.add_argument(
        "--out", default="results/ucr", help="results directory (default results/ucr)"
    )
    parser.add_argument(
        "--published",
        type=published_file,
        default=None,
        metavar="FILE",
        help="published split-0 accuracies to print beside this run's (a "
        "published_results.csv; default: the one in --data-dir, if any)",
    )
    parser.add_argument(
        "--halves",
        action="store_true",
        help="also report the two fixed halves of the datasets (alphabetical odd / even "
        "positions): where defaults are chosen, and where they are confirmed",
    )
    parser.add_argument(
        "--resume",
        action="store_true",
        help="keep every method already in a dataset's result file (written after each "
        "method) that was computed with the same settings, and compute the rest; the "
        "1-NN rows are kept across seeds",
    )
    loud = parser.add_mutually_exclusive_group()
    loud.add_argument(
        "--quiet", action="store_true", help="no progress bar and no per-method lines"
    )
    loud.add_argument(
        "-v",
        "--verbose",
        action="count",
        default=0,
        help="-v: a line per class fit; -vv: epoch progress inside each fit",
    )
    args = parser.parse_args(argv)
    if args.backend not in BACKENDS:
        parser.error(f"argument --backend: {args.backend!r} is not one of {', '.join(BACKENDS)}")
    if args.scheduler and args.backend != "dask":
        parser.error("argument --scheduler: only with --backend dask")
    try:
        check_device(args.device)
    except ValueError as exc:
        parser.error(f"argument --device: {exc}")
    return args


#: joblib backends the script can run datasets on.
BACKENDS = ("loky", "threading", "multiprocessing", "dask")


def select_datasets(args) -> list[str]:
    if args.datasets:
        return list(args.datasets)
    if args.all:
        return available_datasets(args.data_dir)
    if args.half:
        return list(FIXED_HALVES[args.half])
    return list(AEON_BUNDLED)


def finished(out: Path, name: str, config: RunConfig) -> bool:
    """Whether ``--resume`` has nothing left to do for a dataset (at the config's
    resample): every requested method is in its result file, computed with this run's
    settings."""
    record = read_record(record_path(out, name, config.resample))
    return set(reusable(record, config)) == set(config.methods)


def progress_bar(n_datasets: int, n_methods: int, enabled: bool):
    """A tqdm bar over dataset x method fits with a time estimate (None without tqdm)."""
    if not enabled:
        return None
    try:
        from tqdm import tqdm
    except ImportError:
        return None
    return tqdm(
        total=n_datasets * n_methods,
        unit="fit",
        desc="datasets x methods",
        file=sys.stderr,
        dynamic_ncols=True,
    )


def run_all(
    tasks: list[tuple[str, RunConfig]], jobs: int, backend: str, scheduler, bar=None,
    resamples: bool = False,
):  # fmt: skip
    """Every (dataset, config) task: in this process for one job, else on joblib."""
    from joblib import Parallel, delayed, parallel_config

    total = len(tasks)

    def position(i: int, config: RunConfig) -> str:
        return f"[{i + 1:>3}/{total}]" + (f" resample {config.resample}" if resamples else "")

    def advance(record: dict) -> dict:
        if bar is not None:
            bar.update(len(record["config"]["methods"]))
            bar.set_postfix_str(record["dataset"], refresh=False)
        return record

    if jobs == 1 and backend != "dask":  # method-level progress in this process
        records = []
        for i, (name, config) in enumerate(tasks):
            if bar is not None:
                bar.set_postfix_str(name)
            tick = (lambda method: bar.update(1)) if bar is not None else None
            records.append(process_dataset(name, config, position(i, config), tick))
        return records
    tasks = [
        delayed(process_dataset)(name, config, position(i, config))
        for i, (name, config) in enumerate(tasks)
    ]
    if backend == "dask":
        client = connect(scheduler, jobs)
        print(f"dask: {client}", file=sys.stderr)
        with client, parallel_config(backend="dask"):
            return [advance(r) for r in Parallel(return_as="generator_unordered")(tasks)]
    with parallel_config(backend=backend, n_jobs=jobs):
        return [advance(r) for r in Parallel(return_as="generator_unordered")(tasks)]


def main(argv=None) -> int:
    args = parse_args(argv)
    out = check_writable(args.out, directory=True)
    names, unavailable = [], []
    for name in select_datasets(args):
        try:
            check_available(name, args.data_dir)
            names.append(name)
        except DatasetUnavailable as exc:
            unavailable.append(name)
            print(f"skipped: {exc}", file=sys.stderr)
    if not names:
        print(
            f"error: none of the requested datasets is available offline "
            f"({', '.join(unavailable)}); nothing was run",
            file=sys.stderr,
        )
        return 1
    config = RunConfig(
        methods=tuple(args.methods),
        data_dir=args.data_dir,
        epochs=args.epochs,
        max_series_per_class=args.max_series_per_class,
        output_length=args.output_length,
        device=args.device,
        seed=args.seed,
        time_budget=args.time_budget,
        out=str(out),
        verbose=0 if args.quiet else 1 + args.verbose,
        resume=args.resume,
    )
    tasks = [
        (name, replace(config, resample=resample))
        for resample in range(args.resamples)
        for name in names
        if not (args.resume and finished(out, name, replace(config, resample=resample)))
    ]
    n_all = len(names) * args.resamples
    what = f"{len(names)} dataset(s)" + (
        f" x {args.resamples} resamples" if args.resamples > 1 else ""
    )
    print(
        f"{what}, {n_all - len(tasks)} already done; methods "
        f"{', '.join(args.methods)}; {args.epochs} epochs; results in {out}",
        file=sys.stderr,
    )
    start = time.perf_counter()
    bar = progress_bar(len(tasks), len(args.methods), enabled=not args.quiet)
    try:
        run_all(tasks, args.jobs, args.backend, args.scheduler, bar, args.resamples > 1)
    finally:
        if bar is not None:
            bar.close()
    records = [r for r in load_records(out) if r["dataset"] in names]
    command = "python benchmarks/ucr/run.py " + " ".join(
        shlex.quote(a) for a in (argv if argv is not None else sys.argv[1:])
    )
    machine = (
        f"{platform.machine()}, {os.cpu_count()} cores, Python "
        f"{platform.python_version()}, device {args.device}; "
        f"{time.perf_counter() - start:.0f} s for {len(tasks)} dataset(s)"
        + (" x resample" if args.resamples > 1 else "")
    )
    text = markdown(records, list(args.methods), command.strip(), machine, halves=args.halves)
    published = args.published or default_published(args.data_dir)
    if published is not None:
        text += "\n" + "\n".join(
            published_markdown(records, list(args.methods), read_published(published))
        )
    every_resample = load_resample_records(out, names, args.resamples)
    if args.resamples > 1:
        text += "\n" + "\n".join(
            resamples_markdown(every_resample, list(args.methods), args.resamples)
        )
    (out / "summary.md").write_text(text)
    written = [out / "summary.md"]
    tsml = export_tsml(every_resample, list(args.methods), out / "tsml", args.resamples)
    if scatter_plot(records, out / "accuracy_scatter.png"):
        written.append(out / "accuracy_scatter.png")
    skipped = critical_difference_plot(
        records, list(args.methods), out / "critical_difference.png"
    )
    if skipped is None:
        written.append(out / "critical_difference.png")
    for path in written:
        path.chmod(0o644)
    print(text)
    print("written: " + ", ".join(str(p) for p in written))
    print(
        f"tsml results: {tsml['predictions']} prediction file(s) and "
        f"{len(tsml['summaries'])} summary file(s) under {out / 'tsml'}"
    )
    if skipped is not None:
        print(f"critical-difference diagram not drawn: {skipped}")
    print("\n".join(verdict(records, list(args.methods))))
    if unavailable:
        print(f"not available offline (skipped): {', '.join(unavailable)}")
    if all(r.get("error") for r in records):
        print("error: every dataset failed (see the result files)", file=sys.stderr)
        return 1
    failed = [m for m in args.methods if method_failed_everywhere(records, m)]
    if failed:
        print(
            f"error: every fit of {', '.join(failed)} failed (see the result files, e.g. "
            f"{first_error(records, failed[0])})",
            file=sys.stderr,
        )
        return 1
    return 0


def method_failed_everywhere(records: list[dict], method: str) -> bool:
    """No dataset has a result of ``method``, and at least one has its error."""
    entries = [r.get("methods", {}).get(method, {}) for r in records if not r.get("error")]
    return bool(entries) and all("error" in e for e in entries)


def first_error(records: list[dict], method: str) -> str:
    for record in records:
        entry = record.get("methods", {}).get(method, {})
        if "error" in entry:
            return f"{record['dataset']}: {entry['error']}"
    return ""


if __name__ == "__main__":
    sys.exit(main())
