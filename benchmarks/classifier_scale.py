"""The default classifier on training sets as large as the UCR archive's largest.

Usage::

    python benchmarks/classifier_scale.py                      # both sizes
    python benchmarks/classifier_scale.py --sets electricdevices --methods rtw dba
    python benchmarks/classifier_scale.py --sets handoutlines --methods rtw \
        --n-centroids 8 --nn-test 0                 # 8 per class instead of the default
    python benchmarks/classifier_scale.py --sets handoutlines --methods rtw \
        --n-centroids 8 --dtw-window 0.05 --nn-test 0   # ... and a band of 5%

The archive's largest training sets are not shipped here, so this script makes synthetic
sets of their sizes: ``electricdevices`` (8,926 training series of 96 samples, 7 classes)
and ``handoutlines`` (1,000 series of 2,709 samples, 2 classes). Every class holds two
shapes (smooth random curves), each series one of them under a random monotone time warp
and noise, so that the band and several centroids per class matter.

Prints, per set and method: the fit seconds of the classifier a user gets by default
(``RTWNearestCentroid(method=...)``: band and centroids chosen from a sample of the
training set, then every centroid averaged) and of one mean per class
(``n_centroids=1, dtw_window=None``), their ratio, the choice's seconds, its sample size
and result, test accuracy and prediction seconds; with ``--n-centroids``, the same for
the classifier with those numbers of centroids instead (``auto``: the default), the band
chosen unless ``--dtw-window`` fixes it; and 1-NN DTW (sk_rtw's DTW, no band) on the
first ``--nn-test`` test series (0: skipped), its seconds scaled to the whole test set.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository; then _shared

from benchmarks._shared import machine, non_negative_int, positive_int
from sk_rtw import RTWNearestCentroid, dtw_pairwise_distance

#: (training series, test series, samples, classes) of each synthetic set.
SETS = {
    "electricdevices": (8926, 1000, 96, 7),
    "handoutlines": (1000, 300, 2709, 2),
}


def make_set(n_train: int, n_test: int, length: int, n_classes: int, seed: int = 0):
    """Warped noisy copies of two smooth shapes per class: ``(X_train, y_train, X_test,
    y_test)``, series of ``length`` samples."""
    rng = np.random.default_rng(seed)
    shapes = []
    for _ in range(2 * n_classes):  # a few Gaussian bumps of random place, width, height
        centres, widths = rng.uniform(0.1, 0.9, 4), rng.uniform(0.03, 0.12, 4)
        heights = rng.normal(0.0, 1.0, 4)
        shapes.append(lambda u, c=centres, w=widths, h=heights: (
            h * np.exp(-((u[:, None] - c) ** 2) / (2 * w**2))).sum(1))  # fmt: skip
    n = n_train + n_test
    labels = rng.integers(n_classes, size=n)
    X = np.empty((n, length))
    for i, c in enumerate(labels):
        steps = rng.gamma(20.0, size=length)  # a random monotone warp near the identity
        warp = np.concatenate([[0.0], np.cumsum(steps[:-1])])
        warp /= warp[-1]
        X[i] = shapes[2 * c + rng.integers(2)](warp) + 0.1 * rng.standard_normal(length)
    return X[:n_train], labels[:n_train], X[n_train:], labels[n_train:]


def centroids(text: str) -> int | float | str:
    """An ``n_centroids`` value from the command line: "auto", an integer or a fraction."""
    if text == "auto":
        return text
    try:
        return positive_int(text)
    except argparse.ArgumentTypeError:
        try:
            value = float(text)
        except ValueError:
            value = float("nan")
        if not 0.0 < value <= 1.0:
            raise argparse.ArgumentTypeError(
                f"{text!r} is not auto, an integer >= 1 or a fraction in (0, 1]"
            ) from None
        return value


def window(text: str) -> float | str | None:
    """A ``dtw_window`` value from the command line: "auto", "none" or a fraction."""
    if text in ("auto", "none"):
        return None if text == "none" else text
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0.0 <= value <= 1.0:
        raise argparse.ArgumentTypeError(f"{text!r} is not auto, none or a fraction in [0, 1]")
    return value


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(
        description=__doc__.splitlines()[0],
        epilog=__doc__.split("Usage::")[1].split("The archive")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--sets", nargs="+", choices=list(SETS), default=list(SETS))
    parser.add_argument("--methods", nargs="+", choices=["rtw", "dba"], default=["rtw", "dba"])
    parser.add_argument("--nn-test", type=non_negative_int, default=20,
                        help="test series 1-NN DTW classifies (default 20; 0: none)")  # fmt: skip
    parser.add_argument("--n-centroids", nargs="+", type=centroids, default=["auto"],
                        help="rows beside one mean per class: these n_centroids (auto, the "
                        "default; an integer per class; a fraction), the band still "
                        "chosen unless --dtw-window is given")  # fmt: skip
    parser.add_argument("--dtw-window", type=window, default="auto",
                        help="band of the --n-centroids rows: auto (chosen, the default), "
                        "none or a fraction of the length")  # fmt: skip
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    print(f"machine: {machine()}, one thread per fit")
    for name in args.sets:
        n_train, n_test, length, n_classes = SETS[name]
        X, y, X_test, y_test = make_set(n_train, n_test, length, n_classes, args.seed)
        print(f"\n{name}: {n_train} training series of {length} samples, {n_classes} "
              f"classes, {n_test} test series", flush=True)  # fmt: skip
        for method in args.methods:
            seconds = {}
            rows = [("one mean", {"n_centroids": 1, "dtw_window": None})]
            band = {} if args.dtw_window == "auto" else {"dtw_window": args.dtw_window}
            suffix = "" if not band else f", band {args.dtw_window}"
            rows += [("default" + suffix, band) if k == "auto"
                     else (f"k={k}{suffix}", {"n_centroids": k, **band})
                     for k in args.n_centroids]  # fmt: skip
            for label, params in rows:
                clf = RTWNearestCentroid(method=method, random_state=args.seed, **params)
                start = time.perf_counter()
                clf.fit(X, y)
                seconds[label] = time.perf_counter() - start
                start = time.perf_counter()
                accuracy = clf.score(X_test, y_test)
                predict = time.perf_counter() - start
                line = (f"  {method} {label:>8}: fit {seconds[label]:7.1f} s, accuracy "
                        f"{accuracy:.3f}, prediction {predict:6.1f} s")  # fmt: skip
                if clf.selection_:
                    chosen = clf.selection_
                    line += (f"; choice {chosen['seconds']:.1f} s on {chosen['n_series']} "
                             f"series: dtw_window={clf.dtw_window_}, "
                             f"n_centroids={clf.n_centroids_}")  # fmt: skip
                print(line, flush=True)
            for label in [label for label in seconds if label != "one mean"]:
                ratio = seconds[label] / seconds["one mean"]
                print(f"  {method} {label} / one mean fit: {ratio:.2f}x", flush=True)
        if args.nn_test <= 0:
            continue
        start = time.perf_counter()
        subset = slice(0, args.nn_test)
        nearest = dtw_pairwise_distance(X_test[subset], X).argmin(1)
        per_series = (time.perf_counter() - start) / args.nn_test
        accuracy = float((y[nearest] == y_test[subset]).mean())
        print(f"  1-NN DTW on {args.nn_test} test series: accuracy {accuracy:.3f}, "
              f"{per_series:.2f} s per series ({per_series * n_test:.0f} s for the test set)",
              flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
