"""Time ``dtw_pairwise_distance`` against aeon's on the same univariate data.

Usage::

    python benchmarks/dtw_speed.py [--n-series 200] [--length 256] [--jobs 1 2] [--repeats 3]
                                   [--windows none 0.1]

Prints, for 200 x 200 pairs of series of length 256 (by default), with no band and with
a Sakoe-Chiba band of radius 0.1, the best-of-``repeats`` wall time of sk_rtw (Euclidean
manifold, squared point cost as in aeon, so the values are identical) and of aeon, their
ratio (target: sk_rtw / aeon <= 1.5), and the time of the same call with the geodesic
(unsquared) cost and on the S^1 manifold for reference.
"""

from __future__ import annotations

import argparse
import platform
import sys
from pathlib import Path

import numpy as np
from aeon.distances import dtw_pairwise_distance as aeon_pairwise

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository; then _shared

from benchmarks._shared import best_time
from sk_rtw.dtw import dtw_pairwise_distance


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n-series", type=int, default=200)
    parser.add_argument("--length", type=int, default=256)
    parser.add_argument("--jobs", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--windows", nargs="+", default=["none", "0.1"],
                        help="Sakoe-Chiba radii ('none': no band)")  # fmt: skip
    args = parser.parse_args(argv)

    rng = np.random.default_rng(0)
    X = rng.standard_normal((args.n_series, args.length))
    Y = rng.standard_normal((args.n_series, args.length))
    angles = np.cumsum(0.1 * rng.standard_normal((2, args.n_series, args.length)), axis=-1)
    circle = np.stack([np.cos(angles), np.sin(angles)], axis=-1)

    # compile both before timing
    dtw_pairwise_distance(X[:2], Y[:2], squared=True)
    dtw_pairwise_distance(circle[0, :2], circle[1, :2], "sphere")
    aeon_pairwise(X[:2], Y[:2])
    np.testing.assert_allclose(
        dtw_pairwise_distance(X[:5], Y[:5], squared=True), aeon_pairwise(X[:5], Y[:5]), rtol=1e-12
    )

    machine = platform.processor() or platform.machine()
    print(f"machine: {machine}, python {platform.python_version()}")
    print(
        f"{args.n_series} x {args.n_series} pairs, univariate, length {args.length}, "
        f"best of {args.repeats}"
    )
    print(
        f"{'window':>6} {'n_jobs':>6} {'sk_rtw [s]':>11} {'aeon [s]':>9} {'ratio':>6} "
        f"{'geodesic [s]':>13} {'S^1 [s]':>8}"
    )
    for text in args.windows:
        w = None if text.lower() == "none" else float(text)
        for n_jobs in args.jobs:

            def ours_call(j=n_jobs, w=w):
                return dtw_pairwise_distance(X, Y, squared=True, window=w, n_jobs=j)

            ours = best_time(ours_call, args.repeats)
            theirs = best_time(
                lambda j=n_jobs, w=w: aeon_pairwise(X, Y, window=w, n_jobs=j), args.repeats
            )
            geodesic = best_time(
                lambda j=n_jobs, w=w: dtw_pairwise_distance(X, Y, window=w, n_jobs=j), 1
            )
            sphere = best_time(
                lambda j=n_jobs, w=w: dtw_pairwise_distance(
                    circle[0], circle[1], "sphere", window=w, n_jobs=j
                ),
                1,
            )
            print(
                f"{text:>6} {n_jobs:>6} {ours:>11.3f} {theirs:>9.3f} {ours / theirs:>6.2f} "
                f"{geodesic:>13.3f} {sphere:>8.3f}"
            )


if __name__ == "__main__":
    main()
