"""Inverted time warping on S^1 (paper, section V-B, Tables III and IV).

Usage::

    python benchmarks/paper/inverted_s1.py --quick
    python benchmarks/paper/inverted_s1.py --n-signals 4 30 --trials 10 \
        --markdown docs/benchmarks/inverted_s1.md
    python benchmarks/paper/inverted_s1.py --n-signals 30 --output-lengths 400 1000 3000

For each trial a random smooth S^1 signal of length T = 100 is warped by N random monotone
warps (``sk_rtw.datasets.make_warped_signals``); each method re-aligns the N signals and is
scored by restoration accuracy (RA), barycenter loss (BL) and alignment quality (AQ)
(paper eqs. 20a-c: sums over the N signals of path-normalised geodesic DTW), the banded
restoration accuracy (DTW with a 10 % Sakoe-Chiba band, which DTW cannot use to undo
large warps itself), the warp spread (mean over time of the spread across signals of
``true_n(learned_n(z))``; zero when the warps are undone exactly) and the fit time.
Methods: N = 4: MMDDTW (joint DTW on the 4-D grid), TTW, NTW, RTW; N = 30: p-DTW, TTW,
NTW, RTW; DBA (Fréchet-mean DBA) as an extra reference in both.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository; then _shared

from benchmarks._shared import positive_int
from benchmarks.paper import _common as paper
from sk_rtw import metrics
from sk_rtw.datasets import make_warped_signals
from sk_rtw.manifolds import Sphere

T = 100
PAPER = {  # Tables III (N = 4) and IV (N = 30): RA, BL, AQ, CPU seconds
    4: {
        "mmddtw": (0.0601, 0.0552, 0.0403, 3834.33),
        "ttw": (0.1712, 0.1801, 0.0878, 3.37),
        "ntw": (0.0200, 0.0229, 0.0243, 10.72),
        "rtw": (0.0197, 0.0206, 0.0215, 8.49),
    },
    30: {
        "pdtw": (1.0806, 2.1259, 1.2591, 19.53),
        "ttw": (0.6458, 0.7049, 0.4332, 18.88),
        "ntw": (0.0254, 0.2954, 0.3043, 226.97),
        "rtw": (0.0293, 0.0689, 0.0749, 103.14),
    },
}
DEFAULT_METHODS = {
    4: ["mmddtw", "ttw", "ntw", "rtw", "dba"],
    30: ["pdtw", "ttw", "ntw", "rtw", "dba"],
}
COLUMNS = ("RA", "BL", "AQ", "RA band", "warp spread", "seconds")


def warp_spread(learned: np.ndarray, true: np.ndarray) -> float:
    """Spread across signals of ``true_n(learned_n(z))``, averaged over z."""
    grid = np.linspace(0.0, 1.0, true.shape[1])
    composite = np.stack([np.interp(w, grid, t) for w, t in zip(learned, true, strict=True)])
    return float(composite.std(0).mean())


def run(n_signals, methods, trials, epochs, output_length, device, seed):
    M = Sphere(1)
    results = {m: [] for m in ("unaligned", *methods)}
    for trial in range(trials):
        data = make_warped_signals(M, n_signals, T, seed + trial)
        outcomes = {"unaligned": paper.unaligned(data.signals, M)}
        for method in methods:
            outcomes[method] = paper.run_method(
                method,
                data.signals,
                M,
                epochs=epochs,
                output_length=output_length,
                seed=trial,
                device=device,
            )
        for method, outcome in outcomes.items():
            values = paper.score(outcome, data.signals, M, data.original)
            values["RA band"] = metrics.restoration_accuracy(
                outcome.aligned, data.original, M, window=0.1
            )
            values["warp spread"] = warp_spread(outcome.warps, data.warps)
            results[method].append(values)
        print(f"N = {n_signals}: trial {trial + 1}/{trials} done", file=sys.stderr, flush=True)
    return results


def main(argv=None) -> None:
    parser = paper.paper_parser(__doc__, data=False)
    parser.add_argument("--n-signals", type=positive_int, nargs="+", default=[4, 30])
    parser.add_argument("--methods", nargs="+", help="default: the paper's table plus DBA")
    parser.add_argument("--trials", type=positive_int, default=100, help="paper: 100")
    parser.add_argument(
        "--output-lengths", type=positive_int, nargs="+", default=[None],
        help="Z (default: the preset's, min(N, 4) T for RTW/TTW/NTW)",
    )  # fmt: skip
    parser.add_argument("--quick", action="store_true", help="1 trial, 64 epochs")
    args = paper.parse_paper_args(parser, argv)
    if args.quick:
        args.trials, args.epochs = 1, 64
    sections = {}
    for n_signals in args.n_signals:
        methods = args.methods or DEFAULT_METHODS.get(n_signals, ["ttw", "ntw", "rtw", "dba"])
        for output_length in args.output_lengths:
            results = run(
                n_signals, methods, args.trials, args.epochs, output_length, args.device, args.seed
            )
            z = output_length or f"{min(n_signals, 4) * T} (paper presets: {n_signals * T})"
            title = f"N = {n_signals}, T = {T}, Z = {z}, {args.trials} trial(s)"
            sections[title] = paper.markdown_table(results, COLUMNS, PAPER.get(n_signals))
    paper.write_markdown(
        args.markdown,
        "Inverted time warping on S^1 (paper, section V-B, Tables III and IV)",
        f"""
At most {args.epochs} epochs for TTW, NTW and RTW (early stopping); mean ± std over trials.
Columns: restoration accuracy (RA), barycenter loss (BL), alignment quality (AQ) as in the
paper's eqs. 20a-c, each a sum over the N signals of path-normalised geodesic DTW; "RA
band" is RA with a 10 % Sakoe-Chiba band; "warp spread" is zero when the random warps are
undone exactly;
lower is better everywhere, the best method per column in bold. "paper" gives the
paper's RA / BL / AQ / CPU seconds: its DTW normalisation is not published, so compare
rankings, not values. MMDDTW is the joint DTW over the 4-D grid (sum of pairwise
geodesic costs), p-DTW the progressive pairwise average, DBA DTW barycenter averaging
with Fréchet means (not in the paper).
""",
        sections,
    )


if __name__ == "__main__":
    main()
