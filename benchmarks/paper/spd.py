"""Time warping of SPD matrices (paper, section V-C, Table VI): MMDDTW_M, MMDDTW_C, RTW.

Usage::

    python benchmarks/paper/spd.py --quick
    python benchmarks/paper/spd.py --markdown docs/benchmarks/spd.md

Part 1 (the paper's Table VI): N = 3 demonstrations of the RCFS letter "G" (T = 200,
``../shared/data/rcfs``, scaled by 0.02 m and centred at (0.55, 0.1) m) are followed by
planar arms of total length 1 m through damped least-squares inverse kinematics. Each
sample gives an SPD matrix: the manipulability ``J J^T`` (SPD(2)) of a 3-link arm, and
the joint-space mass matrices (SPD(8), SPD(32)) of 8- and 32-link arms of uniform rods
(1 kg in total). Part 2: the R-LASA SPD(2) demonstrations
(``../shared/data/r_lasa/SPD``, 30 shapes x 4 demos, subsampled to T = 100).
Methods: MMDDTW_M (joint DTW, affine-invariant geodesic cost), MMDDTW_C (joint DTW on
Cholesky factors), RTW, and DBA with Fréchet means (not in the paper). ``--quick``:
T = 100, 64 epochs, 3 R-LASA shapes.

Matrices of size 16 or more use ``--large-step`` (default 2: T = 100) and
``--large-epochs`` (default 32; ``--quick``: T = 50 and 4 epochs): the tangent-space
sinc interpolation takes one 32 x 32 eigendecomposition per sinc neighbour and output
sample, so an RTW epoch on SPD(32) costs about 15 s at T = 100 on a 2-core CPU.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository; then _shared

from benchmarks._shared import positive_int
from benchmarks.paper import _common as paper
from benchmarks.paper._data import (
    data_dir,
    planar_arm_kinematics,
    planar_arm_mass_matrix,
    rcfs_letter,
    rlasa_shapes,
    rlasa_spd,
    track_with_planar_arm,
)
from sk_rtw.manifolds import SPD

PAPER = {  # Table VI: BL, AQ per matrix size
    2: {"mmddtw": (42.1131, 42.3271), "mmddtw_c": (43.8988, 44.6875), "rtw": (33.5702, 23.0621)},
    8: {"mmddtw": (20.8496, 20.9473), "mmddtw_c": (21.3290, 21.4635), "rtw": (18.8587, 16.6931)},
    32: {"mmddtw": (22.2595, 22.6282), "mmddtw_c": (23.3155, 23.5338), "rtw": (20.7979, 18.7008)},
}
COLUMNS = ("BL", "AQ", "seconds")
ORIGIN = np.array([0.55, 0.1])


def robot_signals(letters: np.ndarray, size: int) -> np.ndarray:
    """SPD(size) sequences ``(N, T, size, size)`` of an arm following the letters."""
    n_links = 3 if size == 2 else size
    lengths = np.full(n_links, 1.0 / n_links)
    q = track_with_planar_arm(0.02 * letters + ORIGIN, lengths)
    if size == 2:
        _, J = planar_arm_kinematics(q, lengths)
        return J @ np.swapaxes(J, -1, -2)
    return planar_arm_mass_matrix(q, lengths, np.full(n_links, 1.0 / n_links))


def spd_of(X) -> SPD:
    """The SPD manifold of the matrices in X, after checking that they are SPD."""
    manifold = SPD(X.shape[-1])
    manifold.validate(X)
    return manifold


def main(argv=None) -> None:
    parser = paper.paper_parser(__doc__)
    parser.add_argument("--methods", nargs="+", default=["mmddtw", "mmddtw_c", "rtw", "dba"])
    parser.add_argument("--sizes", type=positive_int, nargs="+", default=[2, 8, 32])
    parser.add_argument("--letter", default="G")
    parser.add_argument("--n-signals", type=positive_int, default=3)
    parser.add_argument("--step", type=positive_int, default=1,
                        help="RCFS subsampling (T = 200/step)")  # fmt: skip
    parser.add_argument("--lasa-step", type=positive_int, default=10, help="R-LASA subsampling")
    parser.add_argument("--lasa-signals", type=positive_int, default=4)
    parser.add_argument("--shapes", nargs="*", help="R-LASA shapes (default: all 30)")
    parser.add_argument("--large-epochs", type=positive_int, default=32,
                        help="epochs for sizes >= 16")  # fmt: skip
    parser.add_argument("--large-step", type=positive_int, default=2,
                        help="subsampling, sizes >= 16")  # fmt: skip
    parser.add_argument("--quick", action="store_true", help="T = 100, 64 epochs, 3 shapes")
    args = paper.parse_paper_args(parser, argv)
    root = data_dir(args.data_dir)
    shapes = args.shapes or rlasa_shapes(root)
    if args.quick:
        args.step, args.epochs, args.large_epochs, args.large_step = 2, 64, 4, 4
        shapes = args.shapes or ["GShape", "Sshape", "Worm"]

    letters = rcfs_letter(root, args.letter)[: args.n_signals]
    sections = {}
    for size in args.sizes:
        large = size >= 16
        step = max(args.step, args.large_step) if large else args.step
        epochs = args.large_epochs if large else args.epochs
        X = robot_signals(letters[:, ::step], size)
        results = {
            m: [v]
            for m, v in paper.evaluate(
                X, spd_of(X), args.methods, epochs=epochs, seed=args.seed, device=args.device
            ).items()
        }
        what = "manipulability of a 3-link arm" if size == 2 else f"mass matrix, {size} links"
        title = f"SPD({size}): {what}, N = {len(X)}, T = {X.shape[1]}, {epochs} epochs"
        sections[title] = paper.markdown_table(results, COLUMNS, PAPER.get(size))
        print(f"SPD({size}): done", file=sys.stderr, flush=True)

    lasa = {m: [] for m in ("unaligned", *args.methods)}
    for shape in shapes:
        X = rlasa_spd(root, shape)[: args.lasa_signals, :: args.lasa_step]
        scores = paper.evaluate(
            X, spd_of(X), args.methods, epochs=args.epochs, seed=args.seed, device=args.device
        )
        for method, values in scores.items():
            lasa[method].append(values)
        print(f"R-LASA {shape}: done", file=sys.stderr, flush=True)
    title = (
        f"R-LASA SPD(2), {len(shapes)} shapes, N = {args.lasa_signals}, "
        f"T = {1000 // args.lasa_step}"
    )
    sections[title] = "Mean ± std over shapes.\n\n" + paper.markdown_table(lasa, COLUMNS)
    paper.write_markdown(
        args.markdown,
        "SPD matrices (paper, section V-C, Table VI)",
        f"""
Barycenter loss (BL) and alignment quality (AQ) as in the paper (sums over the N signals
of path-normalised DTW with the affine-invariant geodesic distance; lower is better,
best in bold), fit seconds; at most {args.epochs} epochs for RTW (Z = min(N, 4) T). The
paper's arm geometry, masses and DTW normalisation are not published, so its values
("paper": BL / AQ) are not comparable with these; compare rankings. "unaligned"
resamples every series to one length and averages pointwise.
""",
        sections,
    )


if __name__ == "__main__":
    main()
