"""SPD series next to R^3 series of the same shape: DTW, alignment and DBA, one run.

Usage::

    python benchmarks/spd_speed.py                       # about 4 minutes on one thread
    python benchmarks/spd_speed.py --sections dtw --repeats 5
    python benchmarks/spd_speed.py --sections rlasa --shared-data ../shared/data
    python benchmarks/spd_speed.py --sections eigh
    python benchmarks/spd_speed.py --sections maps

Prints, on one thread (torch's and numba's), the best of ``--repeats`` wall times (after
a warm-up call) and their ratio to R^3 measured in the same run:

``dtw``
    ``dtw_pairwise_distance`` on 8 series of 200 samples (28 pairs, no band): R^3, SPD(2),
    SPD(3) (closed-form kernel distances), SPD(4) and SPD(8) (compiled Householder-QL
    eigenvalues of each whitened pair; every point's Cholesky factor, its inverse and
    its log-eigenvalues computed once per series, not per cell), with the time a cell.
``align``
    ``sk_rtw.align`` with its defaults and ``dba_average`` on N = 30 series of T = 100
    samples: R^3, SPD(2) (closed-form geometry) and SPD(3) (compiled Jacobi
    eigendecompositions).
``eigh``
    How many LAPACK eigendecompositions (``torch.linalg.eigh`` and ``eigvalsh`` calls and
    the matrices in them) one ``align`` (20 epochs) makes on N = 10 series of T = 100
    samples of SPD(8) and SPD(2), and its wall time (not part of the default run).
``maps``
    The SPD(2) maps one epoch of ``align`` runs -- ``Log``, ``Exp`` and the distance
    between 3,000 matrices (30 series of 100 samples) and one base point per sample
    broadcast over the series -- without and with their gradient: compiled
    (``sk_rtw.manifolds._spd2_kernels``, the CPU float64 path) and as the torch formulas
    (the path on other devices and dtypes, selected through the private switch
    ``_spd2.compiled``), and their ratio (not part of the default run).
``rlasa``
    ``RTWNearestCentroid()`` (defaults) on R-LASA's 30 shapes (``--shared-data``), the
    first 3 demonstrations of each for training and the 4th for prediction, every 5th
    sample (200): its SPD(2) version and its unit-quaternion version, one fit and one
    prediction each (no repeats), and their ratio.

Run it on an earlier commit (``PYTHONPATH`` set to that checkout) to compare before and
after: every number but the ``maps`` section's comes from public calls.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numba
import numpy as np
import torch

# the repository (for benchmarks._shared), after PYTHONPATH: an earlier checkout named
# there is the one measured
sys.path.append(str(Path(__file__).resolve().parents[1]))

from benchmarks._shared import best_time, machine, positive_int, smooth_series
from sk_rtw import RTWNearestCentroid, align, dtw_pairwise_distance
from sk_rtw.baselines import dba_average
from sk_rtw.manifolds import SPD, Euclidean

SECTIONS = ("dtw", "align", "rlasa", "eigh", "maps")


def dtw_rows(repeats: int) -> None:
    print("\ndtw_pairwise_distance, 8 series of 200 samples, no band")
    reference = None
    cells = 28 * 200 * 200
    for manifold in (Euclidean(3), SPD(2), SPD(3), SPD(4), SPD(8)):
        X = smooth_series(manifold, 8, 200)
        seconds = best_time(lambda X=X, m=manifold: dtw_pairwise_distance(X, manifold=m),
                            repeats, warm_up=True)  # fmt: skip
        reference = reference or seconds
        print(f"  {manifold!r:>14}: {seconds * 1e3:8.1f} ms, {seconds / cells * 1e9:7.1f} ns a "
              f"cell, {seconds / reference:6.1f}x R^3", flush=True)  # fmt: skip


def align_rows(repeats: int) -> None:
    print("\nN = 30 series of T = 100 samples")
    for label, fit in (
        ("align (default)", lambda X, m: align(X, manifold=m, random_state=0)),
        ("dba_average", lambda X, m: dba_average(X, manifold=m)),
    ):
        reference = None
        for manifold in (Euclidean(3), SPD(2), SPD(3)):
            X = smooth_series(manifold, 30, 100)
            seconds = best_time(lambda X=X, m=manifold, fit=fit: fit(X, m), repeats, warm_up=True)
            reference = reference or seconds
            print(f"  {label} {manifold!r:>14}: {seconds:7.2f} s, {seconds / reference:6.1f}x "
                  "R^3", flush=True)  # fmt: skip


def rlasa_rows(shared_data: str) -> None:
    from benchmarks.paper._data import data_dir, rlasa_quaternions, rlasa_shapes, rlasa_spd

    root = data_dir(shared_data)
    shapes = rlasa_shapes(root)
    print(f"\nRTWNearestCentroid() on R-LASA: {len(shapes)} shapes, 3 demonstrations each "
          "to fit, the 4th to predict, 200 samples")  # fmt: skip
    seconds = {}
    for name, load in (("quaternion", rlasa_quaternions), ("spd", rlasa_spd)):
        demos = np.stack([load(root, shape)[:, ::5] for shape in shapes])
        X, X_test = demos[:, :3].reshape(-1, *demos.shape[2:]), demos[:, 3]
        y, y_test = np.repeat(np.arange(len(shapes)), 3), np.arange(len(shapes))
        clf = RTWNearestCentroid(manifold=name, random_state=0)
        start = time.perf_counter()
        clf.fit(X, y)
        fit = time.perf_counter() - start
        start = time.perf_counter()
        accuracy = clf.score(X_test, y_test)
        predict = time.perf_counter() - start
        seconds[name] = (fit, predict)
        print(f"  {name:>10}: fit {fit:7.1f} s, prediction {predict:6.2f} s, accuracy "
              f"{accuracy:.3f}", flush=True)  # fmt: skip
    (fit_q, predict_q), (fit_s, predict_s) = seconds["quaternion"], seconds["spd"]
    print(f"  spd / quaternion: fit {fit_s / fit_q:.1f}x, prediction {predict_s / predict_q:.1f}x")


def eigh_rows(n_series: int = 10, length: int = 100, n_epochs: int = 20) -> None:
    print(f"\nalign ({n_epochs} epochs) on N = {n_series} series of T = {length} samples: "
          "LAPACK eigendecompositions")  # fmt: skip
    counts: dict[str, list[int]] = {}
    originals = {name: getattr(torch.linalg, name) for name in ("eigh", "eigvalsh")}

    def counting(name):
        def call(S, *args, **kwargs):
            entry = counts.setdefault(name, [0, 0])
            entry[0] += 1
            entry[1] += S[..., 0, 0].numel()
            return originals[name](S, *args, **kwargs)

        return call

    try:
        for name in originals:
            setattr(torch.linalg, name, counting(name))
        for manifold in (SPD(8), SPD(2)):
            counts.clear()
            X = smooth_series(manifold, n_series, length)
            start = time.perf_counter()
            align(X, manifold=manifold, random_state=0, n_epochs=n_epochs)
            seconds = time.perf_counter() - start
            found = ", ".join(f"{name} {calls} calls on {matrices / 1e6:.2f} million matrices"
                              for name, (calls, matrices) in counts.items()) or "none"  # fmt: skip
            print(f"  {manifold!r:>14}: {seconds:6.1f} s; {found}", flush=True)
    finally:
        for name, original in originals.items():
            setattr(torch.linalg, name, original)


def map_rows(repeats: int, n_series: int = 30, length: int = 100) -> None:
    from benchmarks.manifold_maps import map_rows as manifold_map_rows

    manifold_map_rows("spd2", repeats, n_series, length)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(
        description=__doc__.splitlines()[0],
        epilog=__doc__.split("Usage::")[1].split("Prints")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--sections", nargs="+", choices=SECTIONS, default=list(SECTIONS[:3]))
    parser.add_argument("--repeats", type=positive_int, default=3)
    parser.add_argument("--shared-data", default=None,
                        help="folder holding r_lasa/ (the rlasa section; default: the "
                        "repository's ../shared/data)")  # fmt: skip
    args = parser.parse_args(argv)
    threads = torch.get_num_threads(), numba.get_num_threads()
    torch.set_num_threads(1)
    numba.set_num_threads(1)  # the compiled DTW kernels too
    try:
        print(f"machine: {machine()}, one thread")
        if "dtw" in args.sections:
            dtw_rows(args.repeats)
        if "align" in args.sections:
            align_rows(args.repeats)
        if "rlasa" in args.sections:
            rlasa_rows(args.shared_data)
        if "eigh" in args.sections:
            eigh_rows()
        if "maps" in args.sections:
            map_rows(args.repeats)
    finally:
        torch.set_num_threads(threads[0])
        numba.set_num_threads(threads[1])


if __name__ == "__main__":
    main()
