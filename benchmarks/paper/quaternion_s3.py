"""Time warping of unit quaternions (paper, section V-C, Table V): QDTW vs RTW.

Usage::

    python benchmarks/paper/quaternion_s3.py --quick
    python benchmarks/paper/quaternion_s3.py --markdown docs/benchmarks/quaternion_s3.md

Part 1 (the paper's Table V): N = 4 demonstrations of the RCFS handwritten letter "G"
(T = 200, ``../shared/data/rcfs``) mapped onto S^3 as PbDlib does: ``u = c [x1, x2, x2]``,
``q = (0, 1, 0, 0) ⊗ Exp(u)`` with ``c = 0.05`` (rotations up to about 55 degrees).
Part 2: the real R-LASA quaternion demonstrations (``../shared/data/r_lasa/UQ``, 30
shapes x 4 demos, subsampled from T = 1000 to T = 100). Methods: QDTW in its N-signal
form (joint DTW over the 4-D grid with the sign-invariant geodesic cost, as in the
paper's footnote), RTW, and DBA with Fréchet means as an extra reference. The joint grid
of N = 4, T = 200 takes 12.8 GB; ``--quick`` halves T (0.8 GB), runs 64 epochs and 3
R-LASA shapes.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository; then _shared

from benchmarks._shared import positive_float, positive_int
from benchmarks.paper import _common as paper
from benchmarks.paper._data import (
    data_dir,
    letters_on_s3,
    rcfs_letter,
    rlasa_quaternions,
    rlasa_shapes,
)
from sk_rtw.manifolds import Quaternion

PAPER = {"qdtw": (0.0359, 0.0338), "rtw": (0.0339, 0.0338)}  # Table V: BL, AQ
COLUMNS = ("BL", "AQ", "seconds")


def main(argv=None) -> None:
    parser = paper.paper_parser(__doc__)
    parser.add_argument("--methods", nargs="+", default=["qdtw", "rtw", "dba"])
    parser.add_argument("--letter", default="G")
    parser.add_argument("--n-signals", type=positive_int, default=4)
    parser.add_argument("--scale", type=positive_float, default=0.05,
                        help="c in u = c [x1, x2, x2]")  # fmt: skip
    parser.add_argument("--step", type=positive_int, default=1,
                        help="RCFS subsampling (T = 200/step)")  # fmt: skip
    parser.add_argument("--lasa-step", type=positive_int, default=10, help="R-LASA subsampling")
    parser.add_argument("--shapes", nargs="*", help="R-LASA shapes (default: all 30)")
    parser.add_argument("--quick", action="store_true", help="T = 100, 64 epochs, 3 shapes")
    args = paper.parse_paper_args(parser, argv)
    root = data_dir(args.data_dir)
    shapes = args.shapes or rlasa_shapes(root)
    if args.quick:
        args.step, args.epochs = 2, 64
        shapes = args.shapes or ["GShape", "Sshape", "Worm"]

    letters = rcfs_letter(root, args.letter)[: args.n_signals, :: args.step]
    X = letters_on_s3(letters, args.scale)
    rcfs = {
        m: [v]
        for m, v in paper.evaluate(
            X, Quaternion(), args.methods, epochs=args.epochs, seed=args.seed, device=args.device
        ).items()
    }
    print(f"RCFS {args.letter}: done", file=sys.stderr, flush=True)

    lasa = {m: [] for m in ("unaligned", *args.methods)}
    for shape in shapes:
        X = rlasa_quaternions(root, shape)[:, :: args.lasa_step]
        scores = paper.evaluate(
            X, Quaternion(), args.methods, epochs=args.epochs, seed=args.seed, device=args.device
        )
        for method, values in scores.items():
            lasa[method].append(values)
        print(f"R-LASA {shape}: done", file=sys.stderr, flush=True)

    T = letters.shape[1]
    paper.write_markdown(
        args.markdown,
        "Unit quaternions S^3 (paper, section V-C, Table V)",
        f"""
Barycenter loss (BL) and alignment quality (AQ) as in the paper (sums over the N signals
of path-normalised DTW with the sign-invariant geodesic distance on S^3; lower is
better, best in bold), fit seconds; at most {args.epochs} epochs for RTW (Z = 4T). QDTW is the
N-signal joint DTW with the sign-invariant geodesic cost; DBA uses Fréchet means (not in
the paper); "unaligned" resamples every series to one length and averages pointwise.
"paper" gives Table V (BL / AQ); its DTW normalisation is not published, so compare
rankings, not values.
""",
        {
            f"RCFS letter {args.letter}, N = {len(letters)}, T = {T}, c = {args.scale}": (
                paper.markdown_table(rcfs, COLUMNS, PAPER)
            ),
            f"R-LASA quaternions, {len(shapes)} shapes, N = 4, T = {1000 // args.lasa_step}": (
                "Mean ± std over shapes.\n\n" + paper.markdown_table(lasa, COLUMNS)
            ),
        },
    )


if __name__ == "__main__":
    main()
