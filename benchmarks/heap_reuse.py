"""What a fresh mmap per large temporary costs: one multiplication of two float64 tensors
of 8 x Z x 4 (RTW's per-epoch temporaries for 8 quaternion series), timed in a fresh
process with glibc's allocator as it is and inside :func:`sk_rtw._heap.heap_for_temporaries`.

Usage::

    python benchmarks/heap_reuse.py                        # Z = 16,000 ... 1,024,000
    python benchmarks/heap_reuse.py --fits 64000 256000    # RTW's epochs, about 8 min

Prints nanoseconds per element and their ratio (as it is / heap kept). One thread.
``--fits T ...``: seconds per epoch of ``sk_rtw.align`` on the long-demonstrations page's
data (8 unit-quaternion series of T samples, ``start_patience=None``, no early stop;
``(fit(4 epochs) - fit(0 epochs)) / 4``) with the heap kept and with glibc's allocator as
it is (the heap switched off by raising :data:`sk_rtw._heap.LARGE_TEMPORARY`), each fit
in a fresh process, with its peak resident memory.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

RUN = r"""
import sys, time, torch
torch.set_num_threads(1)
from sk_rtw._heap import heap_for_temporaries
n, keep = int(sys.argv[1]), sys.argv[2] == "1"
a, b = torch.rand(8, n, 4, dtype=torch.float64), torch.rand(8, n, 4, dtype=torch.float64)
with heap_for_temporaries(a.numel() * 8 if keep else 0):
    for _ in range(3):
        c = a * b
    del c
    start = time.perf_counter()
    for _ in range(20):
        c = a * b
        del c
    seconds = (time.perf_counter() - start) / 20
print(seconds / a.numel() * 1e9)
"""


FIT = r"""
import importlib, json, resource, sys, time
import numpy as np, numba, torch
torch.set_num_threads(1)
numba.set_num_threads(1)
length, epochs, keep = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3] == "1"
if not keep:
    importlib.import_module("sk_rtw._heap").LARGE_TEMPORARY = float("inf")
from sk_rtw import align
from sk_rtw.datasets import make_warped_signals
X = np.asarray(make_warped_signals("quaternion", 8, length, random_state=0).signals)
align(X[:2, :1100], manifold="quaternion", n_epochs=1)
start = time.perf_counter()
align(X, manifold="quaternion", random_state=0, n_epochs=epochs, start_patience=None,
      n_iter_no_change=None)
print(json.dumps({"seconds": time.perf_counter() - start,
                  "peak_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20}))
"""


def fit(length: int, epochs: int, keep: bool) -> dict:
    out = subprocess.run([sys.executable, "-c", FIT, str(length), str(epochs), str(int(keep))],
                         cwd=REPO, capture_output=True, text=True, check=True)  # fmt: skip
    return json.loads(out.stdout.strip().splitlines()[-1])


def fits(lengths: list[int]) -> None:
    print("| T | s per epoch, as it is | heap kept | ratio | peak GB, as it is | heap kept |")
    print("| --- | --- | --- | --- | --- | --- |")
    for length in lengths:
        cells = {}
        for keep in (False, True):
            none, four = fit(length, 0, keep), fit(length, 4, keep)
            cells[keep] = ((four["seconds"] - none["seconds"]) / 4, four["peak_gb"])
        plain, kept = cells[False], cells[True]
        print(f"| {length:,} | {plain[0]:.2f} | {kept[0]:.2f} | {plain[0] / kept[0]:.1f}x | "
              f"{plain[1]:.2f} | {kept[1]:.2f} |")  # fmt: skip


def per_element(n: int, keep: bool) -> float:
    out = subprocess.run([sys.executable, "-c", RUN, str(n), "1" if keep else "0"], cwd=REPO,
                         capture_output=True, text=True, check=True)  # fmt: skip
    return float(out.stdout.strip())


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--fits", type=int, nargs="+", metavar="T",
                        help="time RTW's epochs at these lengths instead")  # fmt: skip
    args = parser.parse_args(argv)
    if args.fits:
        fits(args.fits)
        return
    print("| Z | MB per temporary | as it is, ns/element | heap kept | ratio |")
    print("| --- | --- | --- | --- | --- |")
    for n in (16_000, 64_000, 256_000, 1_024_000):
        plain, kept = per_element(n, False), per_element(n, True)
        print(f"| {n:,} | {8 * n * 4 * 8 / 2**20:.0f} | {plain:.2f} | {kept:.2f} | "
              f"{plain / kept:.1f}x |")  # fmt: skip


if __name__ == "__main__":
    main()
