"""What a fresh mmap per large temporary costs: one multiplication of two float64 tensors
of 8 x Z x 4 (RTW's per-epoch temporaries for 8 quaternion series), timed in a fresh
process with glibc's allocator as it is and inside :func:`sk_rtw._heap.heap_for_temporaries`.

Usage::

    python benchmarks/heap_reuse.py              # Z = 16,000 ... 1,024,000

Prints nanoseconds per element and their ratio (as it is / heap kept). One thread.
"""

from __future__ import annotations

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


def per_element(n: int, keep: bool) -> float:
    out = subprocess.run([sys.executable, "-c", RUN, str(n), "1" if keep else "0"], cwd=REPO,
                         capture_output=True, text=True, check=True)  # fmt: skip
    return float(out.stdout.strip())


def main() -> None:
    print("| Z | MB per temporary | as it is, ns/element | heap kept | ratio |")
    print("| --- | --- | --- | --- | --- |")
    for n in (16_000, 64_000, 256_000, 1_024_000):
        plain, kept = per_element(n, False), per_element(n, True)
        print(f"| {n:,} | {8 * n * 4 * 8 / 2**20:.0f} | {plain:.2f} | {kept:.2f} | "
              f"{plain / kept:.1f}x |")  # fmt: skip


if __name__ == "__main__":
    main()
