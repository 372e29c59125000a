"""The compiled manifold maps against the torch formulas they compile, one run.

Usage::

    python benchmarks/manifold_maps.py                      # every manifold, seconds
    python benchmarks/manifold_maps.py --manifolds quaternion --repeats 5

The maps one epoch of ``align`` runs -- ``Log``, ``Exp`` and the distance between the
samples of 30 smooth series of 100 samples and one base point per sample broadcast over
the series -- without and with their gradient, on one thread, through the manifolds'
public maps: compiled (the CPU float64 path of spheres, unit quaternions and SPD(2)) and
as the torch formulas (the path on other devices and dtypes, selected on the CPU with
:func:`sk_rtw.manifolds.compiled_maps`), and their ratio (best of ``--repeats`` x 10
calls after a warm-up).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numba
import torch

sys.path.append(str(Path(__file__).resolve().parents[1]))

from benchmarks._shared import best_time, machine, positive_int, smooth_series
from sk_rtw.manifolds import SPD, Quaternion, Sphere, compiled_maps

#: The manifold of every name.
SPACES = {"sphere": Sphere(2), "quaternion": Quaternion(), "spd2": SPD(2)}


MANIFOLDS = ("sphere", "quaternion", "spd2")


def map_rows(name: str, repeats: int, n_series: int = 30, length: int = 100) -> None:
    """Print the compiled and torch times of one manifold's maps."""
    manifold = SPACES[name]
    log, exp, dist = manifold.log, manifold.exp, manifold.dist
    print(f"\n{manifold!r} maps on {n_series} x {length} points, base points broadcast over "
          "the series: compiled / torch formulas")  # fmt: skip
    X = torch.as_tensor(smooth_series(manifold, n_series, length))
    P = X[0:1].expand(n_series, *X.shape[1:])
    with torch.no_grad():
        V = log(P, X)
    for label, function, argument in (("log", log, X), ("exp", exp, V), ("dist", dist, X)):
        seconds = {}
        for path in ("compiled", "torch"):
            leaf = argument.clone().requires_grad_()

            def value(f=function, argument=argument):
                with torch.no_grad():
                    f(P, argument)

            def gradient(f=function, leaf=leaf):
                f(P, leaf).sum().backward()

            with compiled_maps(path == "compiled"):
                seconds[path] = [best_time(call, repeats * 10, warm_up=True)
                                 for call in (value, gradient)]  # fmt: skip
        (value_c, grad_c), (value_t, grad_t) = seconds["compiled"], seconds["torch"]
        print(f"  {label:>4}: value {value_c * 1e6:6.0f} / {value_t * 1e6:6.0f} us "
              f"({value_t / value_c:.1f}x faster), with its gradient {grad_c * 1e6:6.0f} / "
              f"{grad_t * 1e6:6.0f} us ({grad_t / grad_c:.1f}x faster)", flush=True)  # fmt: skip


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(
        description=__doc__.splitlines()[0],
        epilog=__doc__.split("Usage::")[1].split("The maps")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--manifolds", nargs="+", choices=MANIFOLDS, default=list(MANIFOLDS))
    parser.add_argument("--repeats", type=positive_int, default=3)
    args = parser.parse_args(argv)
    threads = torch.get_num_threads(), numba.get_num_threads()
    torch.set_num_threads(1)
    numba.set_num_threads(1)
    try:
        print(f"machine: {machine()}, one thread")
        for name in args.manifolds:
            map_rows(name, args.repeats)
    finally:
        torch.set_num_threads(threads[0])
        numba.set_num_threads(threads[1])


if __name__ == "__main__":
    main()
