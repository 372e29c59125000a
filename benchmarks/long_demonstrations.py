"""Long demonstrations: time, peak memory and quality of RTW and three DBAs as T grows.

Usage::

    python benchmarks/long_demonstrations.py                     # T = 1,000 ... 256,000
    python benchmarks/long_demonstrations.py --lengths 1000 4000 --methods rtw sk_rtw-dba
    python benchmarks/long_demonstrations.py --figure docs/benchmarks/long_demonstrations.png

N = 8 unit-quaternion series of T samples (``make_warped_signals("quaternion", 8, T)``:
one smooth random rotation trajectory under eight random monotone time warps), for T
from 1,000 (one second at 1 kHz) to 256,000 (four minutes). Every (method, T) runs alone
in a fresh process, one thread, until it is done, runs past ``--time-limit`` (30 min) or
would not fit in the memory available (estimated before the start from its T x T
matrices, for aeon's and tslearn's); a method that ran out of time or memory is not
started at longer T.

* ``rtw``: :func:`sk_rtw.align` with its defaults (the "alignment" preset);
* ``sk_rtw-dba``: :func:`sk_rtw.baselines.dba_average` on the quaternion manifold (exact
  DTW with geodesic costs, Fréchet means; medoid start, at most 10 iterations; each DTW
  skips the cells that cannot beat a known path, exact all the same);
* ``aeon-dba``: aeon's ``elastic_barycenter_average(distance="dtw")`` (Petitjean's DBA,
  its defaults: mean start, at most 30 iterations) on the quaternions as 4 channels;
* ``tslearn-dba``: tslearn's ``dtw_barycenter_averaging`` (its defaults, at most 30
  iterations), the same way (skipped when tslearn is not installed).

aeon and tslearn average in R^4; their means are normalised onto S^3 before scoring.
Quality: the path-normalised geodesic DTW distance between the mean and the clean
trajectory the series were warped from (both resampled to 2,000 samples, band 10 %;
lower is better): how well the mean recovers the demonstrated motion. Seconds are the
fit only (each method first runs once on the first 1,100 samples of two series, so that
compiled kernels are loaded, or compiled on a first run); peak memory is the process's
maximum resident set (data and imports included). Results are kept per run in
``--out`` (a rerun skips what is there).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository; then _shared

from benchmarks._shared import check_writable, machine, positive_int

METHODS = ("rtw", "sk_rtw-dba", "aeon-dba", "tslearn-dba")
LENGTHS = (1000, 4000, 16000, 64000, 256000)
#: Bytes per T x T cell the DBAs that fill whole DTW matrices keep at once: aeon the cost
#: matrix, tslearn about 125 (measured: 2.0 GB above the imports at 4,000 samples; killed
#: at 16,000 here). sk_rtw's stores only the cells a path cheaper than the previous
#: iteration's can pass (its memory is not known before the run).
MATRIX_BYTES = {"aeon-dba": 8, "tslearn-dba": 125}

RUN = r"""
import json, resource, sys, time, os
import numpy as np
method, T, n, seed = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
n_jobs = int(sys.argv[5])
os.environ.setdefault("OMP_NUM_THREADS", "1")
import numba
numba.set_num_threads(1)
from sk_rtw.datasets import make_warped_signals
from sk_rtw.manifolds import Quaternion
from sk_rtw import metrics
data = make_warped_signals("quaternion", n, T, random_state=seed)
X = np.asarray(data.signals)
# compiled kernels loaded (or compiled) before the clock starts: long enough for the
# coarse-to-fine DTW of long pairs (over 2**20 cells) to run too
warm = X[:2, : min(T, 1100)]
if method == "rtw":
    import torch
    torch.set_num_threads(1)
    from sk_rtw import align
    align(warm, manifold="quaternion", n_epochs=1)
    start = time.perf_counter()
    result = align(X, manifold="quaternion", random_state=seed, n_jobs=n_jobs)
    seconds, mean, iterations = time.perf_counter() - start, result.mean, result.n_iter
elif method == "sk_rtw-dba":
    from sk_rtw.baselines import dba_average
    dba_average(warm, manifold="quaternion", max_iter=1)
    start = time.perf_counter()
    result = dba_average(X, manifold="quaternion")
    seconds, mean, iterations = time.perf_counter() - start, result.mean, result.n_iter
elif method == "aeon-dba":
    from aeon.clustering.averaging import elastic_barycenter_average
    channels = np.ascontiguousarray(X.transpose(0, 2, 1))
    elastic_barycenter_average(np.ascontiguousarray(warm.transpose(0, 2, 1)), max_iters=1)
    start = time.perf_counter()
    mean = elastic_barycenter_average(channels, distance="dtw", random_state=seed)
    seconds, iterations = time.perf_counter() - start, -1
    mean = np.asarray(mean).T
else:
    from tslearn.barycenters import dtw_barycenter_averaging
    dtw_barycenter_averaging(warm, max_iter=1)
    start = time.perf_counter()
    mean = dtw_barycenter_averaging(X)
    seconds, iterations = time.perf_counter() - start, -1
mean = np.asarray(mean, dtype=float).reshape(-1, 4)
mean = mean / np.linalg.norm(mean, axis=1, keepdims=True)  # onto S^3 (a no-op for sk_rtw)
def resample(x, length=2000):
    idx = np.linspace(0, len(x) - 1, min(length, len(x))).round().astype(int)
    return x[idx]
quality = metrics.barycenter_loss([resample(data.original)], resample(mean), Quaternion(),
                                  window=0.1)
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
print(json.dumps({"seconds": seconds, "peak_bytes": peak, "quality": float(quality),
                  "iterations": int(iterations), "output_length": len(mean)}))
"""


def available_bytes() -> int:
    """Physical memory available now (what sk_rtw's own memory checks read)."""
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):  # non-POSIX
        return 8 * 2**30


def run_one(method: str, T: int, args) -> dict:
    """One (method, T) in a fresh process: its record (``status`` "ok", "time", "memory",
    "error" or "missing")."""
    if method in MATRIX_BYTES:
        need = MATRIX_BYTES[method] * T * T
        free = available_bytes()
        if need > 0.8 * free:
            return {"status": "memory", "need_bytes": need, "free_bytes": free}
    if method == "tslearn-dba":
        try:
            import tslearn  # noqa: F401
        except ImportError:
            return {"status": "missing", "detail": "pip install tslearn"}
    command = [sys.executable, "-c", RUN, method, str(T), str(args.n_series), str(args.seed),
               str(args.n_jobs)]  # fmt: skip
    start = time.perf_counter()
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=args.time_limit,
                              check=False)  # fmt: skip
    except subprocess.TimeoutExpired:
        return {"status": "time", "seconds_over": args.time_limit}
    if done.returncode != 0:
        memory = done.returncode in (-9, 137) or "MemoryError" in done.stderr
        return {"status": "memory" if memory else "error", "detail": done.stderr[-800:],
                "wall": time.perf_counter() - start}  # fmt: skip
    return {"status": "ok", **json.loads(done.stdout.strip().splitlines()[-1])}


def cell(record: dict | None) -> str:
    if record is None:
        return "–"
    status = record["status"]
    if status == "ok":
        return (f"{record['seconds']:.1f} s, {record['peak_bytes'] / 2**30:.2f} GB, "
                f"{record['quality']:.4f}")  # fmt: skip
    if status == "memory":
        need = record.get("need_bytes")
        return f"does not fit ({need / 2**30:.0f} GB)" if need else "out of memory"
    if status == "time":
        return f"over {record['seconds_over'] / 60:.0f} min"
    if status == "missing":
        return "not installed"
    if status == "skipped":
        return "not started"
    return "error"


def threads_note(args) -> str:
    return f" (RTW: n_jobs={args.n_jobs})" if args.n_jobs > 1 else ""


def record_name(method: str, T: int, args) -> str:
    """The run's file: RTW's records name ``--n-jobs`` where it is not 1."""
    jobs = f"-jobs{args.n_jobs}" if method == "rtw" and args.n_jobs > 1 else ""
    return f"{method}-{T}-seed{args.seed}{jobs}.json"


def markdown(results: dict, args) -> str:
    lines = [
        "# Long demonstrations",
        "",
        "N = 8 unit-quaternion series of T samples, each (method, T) alone in a fresh "
        f"process on one thread{threads_note(args)}. A cell: fit seconds, peak memory of "
        "the process, quality (path-normalised geodesic DTW of the mean to the clean "
        "trajectory, lower is better; see the script's docstring).",
        "",
        f"Command: `python benchmarks/long_demonstrations.py --seed {args.seed}"
        + (f" --n-jobs {args.n_jobs}" if args.n_jobs > 1 else "")
        + "`  ",
        f"Machine: {machine()}",
        "",
        "| T | " + " | ".join(args.methods) + " |",
        "|" + " --- |" * (len(args.methods) + 1),
    ]
    for T in args.lengths:
        cells = [cell(results.get(f"{m}-{T}")) for m in args.methods]
        lines.append(f"| {T:,} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def figure(results: dict, args, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for method in args.methods:
        done = [(T, results[f"{method}-{T}"]) for T in args.lengths
                if results.get(f"{method}-{T}", {}).get("status") == "ok"]  # fmt: skip
        if not done:
            continue
        lengths = [T for T, _ in done]
        axes[0].loglog(lengths, [r["seconds"] for _, r in done], "o-", label=method)
        axes[1].loglog(lengths, [r["peak_bytes"] / 2**30 for _, r in done], "o-", label=method)
    axes[0].set(xlabel="samples per series T", ylabel="fit seconds (one thread)")
    axes[1].set(xlabel="samples per series T", ylabel="peak memory (GB)")
    axes[1].axhline(available_bytes() / 2**30, color="grey", ls=":", label="memory available")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend()
    fig.suptitle("N = 8 unit-quaternion demonstrations")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--lengths", nargs="+", type=positive_int, default=list(LENGTHS))
    parser.add_argument("--methods", nargs="+", choices=METHODS, default=list(METHODS))
    parser.add_argument("--n-series", type=positive_int, default=8)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--n-jobs", type=positive_int, default=1,
                        help="RTW's n_jobs (threads); the DBAs run on one thread")  # fmt: skip
    parser.add_argument("--time-limit", type=positive_int, default=1800,
                        help="seconds per run (default 30 min)")  # fmt: skip
    parser.add_argument("--out", default="results/long_demonstrations")
    parser.add_argument("--markdown", help="write the table here too")
    parser.add_argument("--figure", help="write the time and memory plot here (PNG)")
    args = parser.parse_args(argv)
    out = check_writable(args.out, directory=True)
    for path in (args.markdown, args.figure):
        if path:
            check_writable(path)
    results: dict = {}
    for method in args.methods:
        stopped = None
        for T in sorted(args.lengths):
            key, file = f"{method}-{T}", out / record_name(method, T, args)
            if file.exists():
                results[key] = json.loads(file.read_text())
            elif stopped is not None:
                results[key] = {"status": "skipped", "after": stopped["status"]}
                continue
            else:
                results[key] = run_one(method, T, args)
                file.write_text(json.dumps(results[key]))
            print(f"{method} T={T}: {cell(results[key])}", file=sys.stderr, flush=True)
            if results[key]["status"] in ("time", "memory", "missing"):
                stopped = results[key]
    table = markdown(results, args)
    print(table)
    if args.markdown:
        Path(args.markdown).write_text(table + "\n")
    if args.figure:
        figure(results, args, Path(args.figure))


if __name__ == "__main__":
    main()
