"""Inverted time warping on S^1 (paper, section V-B, Tables III and IV): RTW, TTW, NTW.

Usage::

    python benchmarks/paper/inverted_s1.py --n-signals 4 30 --trials 5
    python benchmarks/paper/inverted_s1.py --quick
    python benchmarks/paper/inverted_s1.py --n-signals 30 --output-lengths 100 400 1000 3000

For each trial a random smooth S^1 signal of length T = 100 is warped by N random monotone
warps (``sk_rtw.datasets.make_warped_signals``); each method re-aligns the N signals and is
scored by restoration accuracy, barycenter loss and alignment quality (paper eqs. 20a-c,
sums over the N signals of path-normalised geodesic DTW), the banded restoration accuracy
(DTW with a 10 % Sakoe–Chiba band, which DTW cannot use to undo large warps itself), the
warp spread (mean over time of the spread across signals of ``true_n(learned_n(z))``; zero
when the warps are undone exactly) and the fit time. Prints mean ± std over trials beside
the paper's numbers (which use the unpublished normalisation of their DTW, so compare the
ranking, not the values).
"""

from __future__ import annotations

import argparse
import platform
import time

import numpy as np
import torch

from sk_rtw import align, metrics
from sk_rtw.datasets import make_warped_signals
from sk_rtw.manifolds import Sphere

PAPER = {  # Tables III (N = 4) and IV (N = 30): RA, BL, AQ, CPU seconds
    4: {
        "ttw": (0.1712, 0.1801, 0.0878, 3.37),
        "ntw": (0.0200, 0.0229, 0.0243, 10.72),
        "rtw": (0.0197, 0.0206, 0.0215, 8.49),
    },
    30: {
        "ttw": (0.6458, 0.7049, 0.4332, 18.88),
        "ntw": (0.0254, 0.2954, 0.3043, 226.97),
        "rtw": (0.0293, 0.0689, 0.0749, 103.14),
    },
}
COLUMNS = ("RA", "BL", "AQ", "RA band", "warp spread", "seconds")


def warp_spread(learned: np.ndarray, true: np.ndarray) -> float:
    grid = np.linspace(0.0, 1.0, true.shape[1])
    composite = np.stack([np.interp(w, grid, t) for w, t in zip(learned, true, strict=True)])
    return float(composite.std(0).mean())


def score(data, aligned, mean, warps, seconds) -> list[float]:
    M = data.manifold
    return [
        metrics.restoration_accuracy(aligned, data.original, M),
        metrics.barycenter_loss(data.signals, mean, M),
        metrics.alignment_quality(aligned, mean, M),
        metrics.restoration_accuracy(aligned, data.original, M, window=0.1),
        warp_spread(warps, data.warps),
        seconds,
    ]


def run(n_signals, methods, trials, epochs, output_length, device, seed) -> dict:
    results = {m: [] for m in ("unaligned", *methods)}
    for trial in range(trials):
        data = make_warped_signals(Sphere(1), n_signals, 100, seed + trial)
        mean = Sphere(1).mean(data.signals)
        identity = np.tile(np.linspace(0, 1, 100), (n_signals, 1))
        results["unaligned"].append(score(data, data.signals, mean, identity, 0.0))
        for method in methods:
            start = time.perf_counter()
            result = align(
                data.signals,
                manifold="sphere",
                method=method,
                n_epochs=epochs,
                output_length=output_length,
                random_state=trial,
                device=device,
            )
            seconds = time.perf_counter() - start
            results[method].append(score(data, result.aligned, result.mean, result.warps, seconds))
    return {m: np.array(v) for m, v in results.items()}


def print_table(n_signals, results, output_length):
    z = output_length or min(n_signals, 4) * 100
    print(
        f"\nS^1, N = {n_signals}, T = 100, Z = {z}, {len(next(iter(results.values())))} "
        "trial(s); mean ± std"
    )
    print(f"{'method':>10} " + " ".join(f"{c:>17}" for c in COLUMNS) + "   paper RA/BL/AQ/s")
    for method, values in results.items():
        cells = " ".join(
            f"{m:>8.4f} ± {s:<6.4f}" for m, s in zip(values.mean(0), values.std(0), strict=True)
        )
        paper = PAPER.get(n_signals, {}).get(method)
        paper_text = " / ".join(f"{v:g}" for v in paper) if paper else ""
        print(f"{method:>10} {cells}   {paper_text}", flush=True)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n-signals", type=int, nargs="+", default=[4, 30])
    parser.add_argument("--methods", nargs="+", default=["ttw", "ntw", "rtw"])
    parser.add_argument("--trials", type=int, default=100)
    parser.add_argument("--epochs", type=int, default=256)
    parser.add_argument("--output-lengths", type=int, nargs="+", default=[None])
    parser.add_argument("--device", default="cpu")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--quick", action="store_true", help="2 trials, 64 epochs")
    args = parser.parse_args(argv)
    if args.quick:
        args.trials, args.epochs = 2, 64
    print(
        f"machine: {platform.machine()}, {torch.get_num_threads()} torch threads, "
        f"device {args.device}; {args.epochs} epochs"
    )
    for n_signals in args.n_signals:
        for output_length in args.output_lengths:
            results = run(
                n_signals,
                args.methods,
                args.trials,
                args.epochs,
                output_length,
                args.device,
                args.seed,
            )
            print_table(n_signals, results, output_length)


if __name__ == "__main__":
    main()
