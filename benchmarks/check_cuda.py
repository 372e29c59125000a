"""Check every ``device="cuda"`` path against the CPU (needs a CUDA GPU).

Usage::

    python benchmarks/check_cuda.py

For RTW, TTW and NTW on six spaces (R^2, S^1, S^2, quaternions, SPD(3), poses) it runs a
30-epoch alignment on the CPU, on CUDA, and on CUDA with ``cuda_graph=True``, and prints
the relative difference of the first loss and of the loss history, the largest difference
of the warps and the means, and any warning (a failed graph capture falls back to eager
epochs with a warning). Then the estimators on CUDA: fit, score, pickle round trip.
Exit status 1 when a difference exceeds the tolerance (first loss 1e-9; history 1e-6).
"""

from __future__ import annotations

import pickle
import sys
import warnings
from pathlib import Path

import numpy as np
import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository; then _shared

from sk_rtw import (
    NTW,
    RTW,
    TTW,
    NTWNearestCentroid,
    RTWNearestCentroid,
    TTWAverager,
    align,
)
from sk_rtw.datasets import make_warped_signals
from sk_rtw.manifolds import SPD, Euclidean, Product, Quaternion, Sphere

SPACES = [
    Euclidean(2),
    Sphere(1),
    Sphere(2),
    Quaternion(),
    SPD(3),
    Product((Euclidean(3), Quaternion())),
]


def compare(reference, other) -> tuple[float, float, float, float]:
    first = abs(reference.loss_history[0] - other.loss_history[0]) / abs(reference.loss_history[0])
    history = np.max(
        np.abs(reference.loss_history - other.loss_history) / np.abs(reference.loss_history)
    )
    warps = np.abs(reference.warps - other.warps).max()
    mean = np.abs(reference.mean - other.mean).max()
    return first, history, warps, mean


def main() -> int:
    if not torch.cuda.is_available():
        print("no CUDA device: nothing to check")
        return 0
    print(f"torch {torch.__version__}, {torch.cuda.get_device_name(0)}")
    failures = 0
    for manifold in SPACES:
        data = make_warped_signals(manifold, 6, 50, 0).signals
        for method in ("rtw", "ttw", "ntw"):
            options = {"manifold": manifold, "method": method, "n_epochs": 30, "random_state": 0}
            cpu = align(data, **options)
            for graph in (False, True):
                with warnings.catch_warnings(record=True) as caught:
                    warnings.simplefilter("always")
                    gpu = align(data, device="cuda", cuda_graph=graph, **options)
                first, history, warps, mean = compare(cpu, gpu)
                ok = first < 1e-9 and history < 1e-6 and isinstance(gpu.mean, np.ndarray)
                failures += not ok
                notes = "; ".join(str(w.message)[:160] for w in caught)
                print(
                    f"{'ok  ' if ok else 'FAIL'} {manifold!r:48s} {method} "
                    f"{'graph' if graph else 'eager'}: first loss {first:.1e}, history "
                    f"{history:.1e}, warps {warps:.1e}, mean {mean:.1e}"
                    + (f" [{notes}]" if notes else ""),
                    flush=True,
                )
    X = np.concatenate([make_warped_signals(Quaternion(), 8, 40, seed).signals for seed in (1, 2)])
    y = np.repeat([0, 1], 8)
    for estimator in (
        RTWNearestCentroid(
            manifold="quaternion", method=RTW(n_epochs=20), random_state=0, device="cuda"
        ),
        NTWNearestCentroid(
            manifold="quaternion", method=NTW(n_epochs=20), random_state=0, device="cuda"
        ),
    ):
        estimator.fit(X, y)
        restored = pickle.loads(pickle.dumps(estimator))
        same = np.array_equal(restored.predict(X), estimator.predict(X))
        numpy_means = isinstance(restored.means_, np.ndarray)
        failures += not (same and numpy_means)
        print(
            f"{type(estimator).__name__} on cuda: training accuracy "
            f"{estimator.score(X, y):.2f}, pickle round trip predicts the same: {same}, "
            f"means are numpy: {numpy_means}"
        )
    spd = np.concatenate([make_warped_signals(SPD(2), 6, 30, seed).signals for seed in (3, 4)])
    averager = TTWAverager(manifold="spd", method=TTW(n_epochs=10), random_state=0, device="cuda")
    distances = averager.fit(spd, np.repeat([0, 1], 6)).transform(spd)
    print(f"TTWAverager on cuda (SPD(2)): means {averager.means_.shape}, {distances.shape}")
    print("all checks passed" if not failures else f"{failures} check(s) FAILED")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
