"""Speed and memory of ``sk_rtw.align`` on S^1 signals of length T = 100.

Usage::

    python benchmarks/align_speed.py                 # everything below, about 15 min on 2 cores
    python benchmarks/align_speed.py --quick         # fewer epochs, no N = 120 full fits
    python benchmarks/align_speed.py --device cuda   # on a GPU

Prints
1. seconds per epoch and per full fit (256 epochs) for N in {4, 30, 120} and each method,
   at the default output length Z = min(N, 4) T;
2. seconds per epoch of RTW with N = 30 at Z in {T, 4T, 30T} (30T is the paper's N T);
3. peak memory and seconds per epoch of RTW for one class of 2,000 series (default Z),
   measured in a fresh process.
The per-epoch cost should grow linearly in N and Z: the last column divides by N Z.
Full fits are timed end to end (validation, optimisation, final forward); with ``--quick``
or ``--project-large`` the N = 120 fits are projected from the per-epoch time (marked ~).
"""

from __future__ import annotations

import argparse
import json
import platform
import subprocess
import sys
import time

import torch

from sk_rtw.align import align
from sk_rtw.align._engine import _build_warps, _Problem, resolve_config
from sk_rtw.datasets import make_warped_signals
from sk_rtw.utils import check_series_collection

T = 100
PAPER_CPU_SECONDS = {4: 8.4883, 30: 103.1399}  # RTW, AMD Ryzen 5 3500U (paper, Tables III/IV)


def epoch_seconds(signals, method, output_length, device, repeats=5):
    """Mean wall time of one optimisation epoch (forward, backward, Adam step)."""
    collection = check_series_collection(signals, "sphere")
    config = resolve_config(
        method,
        len(signals),
        T,
        output_length=output_length,
        n_epochs=1,
        learning_rate=0.01,
        sinc_window=None,
        loss_window=None,
        loss_step=None,
        penalty=None,
        device=device,
        method_options={},
    )
    model = _build_warps(config, len(signals)).to(device)
    problem = _Problem(collection, config)
    optimiser = torch.optim.Adam(model.parameters(), lr=0.01)

    def step():
        optimiser.zero_grad()
        loss, *_ = problem.forward(model)
        loss.backward()
        optimiser.step()

    step()  # warm-up
    if device != "cpu":
        torch.cuda.synchronize()
    start = time.perf_counter()
    for _ in range(repeats):
        step()
    if device != "cpu":
        torch.cuda.synchronize()
    return (time.perf_counter() - start) / repeats


def memory_probe(n_signals: int, device: str) -> dict:
    """Run one RTW epoch for a large class in a child process; report its peak memory."""
    code = f"""
import json, resource, time, torch
import numpy as np
from sk_rtw.datasets import make_warped_signals
import benchmarks.align_speed as b
signals = make_warped_signals("sphere", {n_signals}, {T}, 0).signals
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
seconds = b.epoch_seconds(signals, "rtw", None, "{device}", repeats=2)
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
gpu = torch.cuda.max_memory_allocated() / 2**20 if "{device}" != "cpu" else 0.0
print(json.dumps({{"seconds": seconds, "peak_mib": peak / 1024, "base_mib": base / 1024,
                  "gpu_mib": gpu}}))
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument(
        "--project-large",
        action="store_true",
        help="project N = 120 full fits from the per-epoch time",
    )
    parser.add_argument("--epochs", type=int, default=256)
    parser.add_argument("--device", default="cpu")
    parser.add_argument("--threads", type=int, default=None)
    args = parser.parse_args(argv)
    if args.threads:
        torch.set_num_threads(args.threads)
    epochs = 32 if args.quick else args.epochs
    project_large = args.quick or args.project_large

    print(
        f"machine: {platform.machine()}, {torch.get_num_threads()} torch threads, "
        f"device {args.device}, torch {torch.__version__}"
    )
    # warm up torch's thread pool and allocator once, so the first row is not penalised
    epoch_seconds(make_warped_signals("sphere", 4, T, 1).signals, "rtw", 4 * T, args.device)
    print(f"\n1. S^1, T = {T}, Z = min(N, 4) T, full fit = {epochs} epochs")
    print(
        f"{'N':>4} {'method':>6} {'Z':>5} {'s/epoch':>9} {'s/fit':>9} "
        f"{'paper s/fit':>11} {'us/(N Z)':>9}"
    )
    for n in (4, 30, 120):
        signals = make_warped_signals("sphere", n, T, 0).signals
        z = min(n, 4) * T
        for method in ("rtw", "ttw", "ntw"):
            per_epoch = epoch_seconds(signals, method, z, args.device)
            if n == 120 and project_large:
                fit = f"~{per_epoch * epochs:.1f}"
            else:
                start = time.perf_counter()
                align(
                    signals,
                    manifold="sphere",
                    method=method,
                    n_epochs=epochs,
                    random_state=0,
                    device=args.device,
                )
                fit = f"{time.perf_counter() - start:.1f}"
            paper = PAPER_CPU_SECONDS.get(n) if method == "rtw" else None
            paper_text = f"{paper:.1f}" if paper else "-"
            print(
                f"{n:>4} {method:>6} {z:>5} {per_epoch:>9.4f} {fit:>9} {paper_text:>11} "
                f"{per_epoch / (n * z) * 1e6:>9.3f}",
                flush=True,
            )

    print("\n2. RTW, N = 30, per epoch against the output length")
    print(f"{'Z':>6} {'s/epoch':>9} {'us/(N Z)':>9}")
    signals = make_warped_signals("sphere", 30, T, 0).signals
    for factor in (1, 4, 30):
        per_epoch = epoch_seconds(signals, "rtw", factor * T, args.device, repeats=3)
        print(
            f"{factor * T:>6} {per_epoch:>9.4f} {per_epoch / (30 * factor * T) * 1e6:>9.3f}",
            flush=True,
        )

    print("\n3. RTW, one class of 2,000 series of length 100 (default Z = 4 T = 400)")
    probe = memory_probe(2000, args.device)
    print(
        f"   peak RSS {probe['peak_mib']:.0f} MiB (process before the fit: "
        f"{probe['base_mib']:.0f} MiB), GPU peak {probe['gpu_mib']:.0f} MiB, "
        f"{probe['seconds']:.2f} s/epoch -> ~{probe['seconds'] * 256 / 60:.1f} min "
        "for 256 epochs"
    )


if __name__ == "__main__":
    main()
