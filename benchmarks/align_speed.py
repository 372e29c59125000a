"""Speed and memory of ``sk_rtw.align`` next to aeon's DBA, on the same data in one run.

Usage::

    python benchmarks/align_speed.py                  # everything, about 10 min on 2 cores
    python benchmarks/align_speed.py --skip-large     # without the 2,000-series class
    python benchmarks/align_speed.py --device cuda    # on a GPU (adds N = 2000 per epoch)
    python benchmarks/align_speed.py --device cuda --cuda-graph   # epochs as CUDA graphs

Prints
1. one full fit (256 epochs, product defaults) of RTW, TTW and NTW on N = 30 Euclidean
   warped signals of length T = 100, and aeon's DBA (``elastic_barycenter_average`` with
   DTW) on the same signals; the ratio to DBA is the number to compare across machines;
2. milliseconds per epoch against N (4, 30, 120) for each method, on Euclidean and on S^1
   data, T = 100, default output length;
3. one class of 2,000 S^1 series of length 100: a full RTW fit (time) and the peak memory of
   an RTW and an NTW fit, each in a fresh process.

Timings are the median of ``--repeats`` runs after a warm-up (this machine's noise is
large: compare ratios, not absolute seconds). Per-epoch times are
``(fit(E) - fit(0)) / E``: a fit's fixed cost (validation, network set-up, final pass) is
left out. Only the public API is used, so the script also measures older versions.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import time

import numpy as np
import torch

from sk_rtw import align
from sk_rtw.datasets import make_warped_signals

T = 100
METHODS = ("rtw", "ttw", "ntw")


def machine(device: str) -> str:
    name = platform.processor() or platform.machine()
    if device.startswith("cuda") and torch.cuda.is_available():
        name += f", GPU {torch.cuda.get_device_name(0)}"
    return (
        f"{name}, {os.cpu_count()} cores, {torch.get_num_threads()} torch threads, "
        f"torch {torch.__version__}, device {device}"
    )


def timed(fn, repeats: int) -> float:
    """Median wall time of ``fn()`` over ``repeats`` runs (after one warm-up run)."""
    fn()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


#: Extra engine options (``--cuda-graph``).
OPTIONS: dict = {}


def fit(X, manifold, method, epochs, device):
    return align(X, manifold=manifold, method=method, n_epochs=epochs, random_state=0,
                 device=device, **OPTIONS)  # fmt: skip


def dba_seconds(X: np.ndarray, repeats: int) -> float:
    from aeon.clustering.averaging import elastic_barycenter_average

    channels_first = np.swapaxes(X, 1, 2)
    return timed(
        lambda: elastic_barycenter_average(channels_first, distance="dtw", random_state=0),
        repeats,
    )


DBA_PROBE = """
import json, statistics, sys, time
import numpy as np
from aeon.clustering.averaging import elastic_barycenter_average
from sk_rtw.datasets import make_warped_signals
X = np.asarray(make_warped_signals("euclidean", 30, 100, random_state=0).signals)
X = np.swapaxes(X, 1, 2)
times = []
for _ in range(int(sys.argv[1]) + 1):
    start = time.perf_counter()
    elastic_barycenter_average(X, distance="dtw", random_state=0)
    times.append(time.perf_counter() - start)
print(json.dumps({"seconds": statistics.median(times[1:])}))
"""


def dba_fresh_process_seconds(repeats: int) -> float:
    """aeon's DBA in a fresh process on numba's default threading layer (OpenMP here)."""
    env = {**os.environ, "NUMBA_THREADING_LAYER": "default"}  # sk_rtw then keeps it
    out = subprocess.run(
        [sys.executable, "-c", DBA_PROBE, str(repeats)],
        capture_output=True, text=True, check=True, env=env,
    )  # fmt: skip
    return json.loads(out.stdout.strip().splitlines()[-1])["seconds"]


def section_fits(device: str, repeats: int) -> None:
    X = np.asarray(make_warped_signals("euclidean", 30, T, random_state=0).signals)
    dba = dba_seconds(X, repeats)
    alone = dba_fresh_process_seconds(repeats)
    print(f"\n1. Full fits, N = 30 Euclidean series, T = {T}, 256 epochs, defaults")
    print(f"{'method':>8} {'seconds':>9} {'x DBA':>7} {'x DBA alone':>12}")
    print(f"{'aeon DBA':>8} {dba:>9.3f} {1.0:>7.1f} {dba / alone:>12.1f}")
    for method in METHODS:
        seconds = timed(lambda m=method: fit(X, "euclidean", m, 256, device), repeats)
        print(f"{method:>8} {seconds:>9.3f} {seconds / dba:>7.1f} {seconds / alone:>12.1f}",
              flush=True)  # fmt: skip
    print(
        f"   x DBA: aeon's DBA in this process ({dba:.3f} s); x DBA alone: in a fresh process "
        f"on numba's default threading layer ({alone:.3f} s; see docs/benchmarks/align_speed)"
    )


def per_epoch_ms(X, manifold, method, device, epochs, repeats) -> float:
    full = timed(lambda: fit(X, manifold, method, epochs, device), repeats)
    setup = timed(lambda: fit(X, manifold, method, 0, device), repeats)
    return max(full - setup, 0.0) / epochs * 1e3


def section_epochs(device: str, repeats: int, sizes) -> None:
    print(f"\n2. Milliseconds per epoch, T = {T}, default Z = min(N, 4) T")
    print(f"{'space':>9} {'N':>5} " + " ".join(f"{m:>8}" for m in METHODS))
    for manifold in ("euclidean", "sphere"):
        for n in sizes:
            X = np.asarray(make_warped_signals(manifold, n, T, random_state=0).signals)
            epochs = 16 if n >= 1000 else 32
            row = [per_epoch_ms(X, manifold, m, device, epochs, repeats) for m in METHODS]
            name = "S^1" if manifold == "sphere" else manifold
            print(f"{name:>9} {n:>5} " + " ".join(f"{v:>8.2f}" for v in row), flush=True)


PROBE = """
import json, resource, sys, time, torch
import numpy as np
from sk_rtw import align
from sk_rtw.datasets import make_warped_signals
method, n, epochs, device = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
X = np.asarray(make_warped_signals("sphere", n, 100, random_state=0).signals)
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
start = time.perf_counter()
align(X, manifold="sphere", method=method, n_epochs=epochs, random_state=0, device=device)
seconds = time.perf_counter() - start
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
gpu = torch.cuda.max_memory_allocated() / 2**20 if device.startswith("cuda") else 0.0
print(json.dumps({"seconds": seconds, "peak_mib": peak, "before_mib": before, "gpu_mib": gpu}))
"""


def probe(method: str, n: int, epochs: int, device: str) -> dict:
    """One fit in a fresh process: seconds and peak resident (and GPU) memory."""
    out = subprocess.run(
        [sys.executable, "-c", PROBE, method, str(n), str(epochs), device],
        capture_output=True,
        text=True,
        check=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def section_large(device: str) -> None:
    n = 2000
    print(f"\n3. One class of {n} S^1 series, T = {T}, Z = {4 * T}, each in a fresh process")
    for method, epochs in (("rtw", 256), ("ntw", 4)):
        result = probe(method, n, epochs, device)
        gpu = f", GPU peak {result['gpu_mib']:.0f} MiB" if result["gpu_mib"] else ""
        what = "full fit" if epochs == 256 else f"{epochs} epochs (memory)"
        print(
            f"   {method}: {what} {result['seconds']:.1f} s, peak resident memory "
            f"{result['peak_mib']:.0f} MiB ({result['before_mib']:.0f} MiB before the fit)"
            f"{gpu}",
            flush=True,
        )


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(
        description=__doc__.splitlines()[0],
        epilog=__doc__.split("Usage::")[1].split("Prints")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--device", default="cpu", help="torch device, e.g. cuda")
    parser.add_argument("--threads", type=int, default=2, help="torch threads (default 2)")
    parser.add_argument("--repeats", type=int, default=3, help="timed runs per number")
    parser.add_argument("--skip-large", action="store_true", help="skip the 2,000-series class")
    parser.add_argument(
        "--cuda-graph", action="store_true", help="capture epochs in CUDA graphs (GPU only)"
    )
    args = parser.parse_args(argv)
    if args.cuda_graph:
        OPTIONS["cuda_graph"] = True
    torch.set_num_threads(args.threads)
    print(f"machine: {machine(args.device)}" + (", CUDA graphs" if args.cuda_graph else ""))
    section_fits(args.device, args.repeats)
    sizes = (4, 30, 120, 2000) if args.device.startswith("cuda") else (4, 30, 120)
    section_epochs(args.device, args.repeats, sizes)
    if not args.skip_large:
        section_large(args.device)


if __name__ == "__main__":
    main()
