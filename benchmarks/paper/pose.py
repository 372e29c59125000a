"""Real pose demonstrations in R^3 x S^3 (paper, section V-D): interpolation, TTW, NTW, RTW.

Usage::

    python benchmarks/paper/pose.py --quick
    python benchmarks/paper/pose.py --markdown docs/benchmarks/pose.md \
        --figure-dir docs/benchmarks

Data (``../shared/data/icsc_hmm``, read in place): the 12 carrot-grating demonstrations
(three groups of four executions, 2322-3371 samples) and the 4 circular-wiping
demonstrations (1096-1457 samples, whose quaternions flip sign q -> -q 94-140 times; the
``Quaternion`` factor's sign-invariant log and distance absorb the flips). Both are
subsampled (every 10th / 5th sample) unless ``--full-resolution`` is given. Methods:
naive interpolation (every series resampled to one length, pointwise Fréchet mean),
TTW, NTW, RTW, and DBA with Fréchet means (not in the paper). Metrics: barycenter loss
(BL) and alignment quality (AQ) with the pose distance sqrt(|dp|^2 + dist_S3^2) (metres
and radians), their position and orientation parts, and the speed peak of the mean
(largest step over the mean step, which the paper uses to say that TTW compresses
motion). With ``--figure-dir`` each task gets a figure of the mean trajectories with
tool frames.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository; then _shared

from benchmarks._shared import check_writable
from benchmarks.paper import _common as paper
from benchmarks.paper._data import data_dir, icsc_carrot_grating, icsc_wiping
from sk_rtw import metrics
from sk_rtw.manifolds import Euclidean, Product, Quaternion

COLUMNS = ("BL", "AQ", "AQ position", "AQ orientation", "speed peak", "seconds")
TASKS = {"grating": (icsc_carrot_grating, 10), "wiping": (icsc_wiping, 5)}


def speed_peak(mean: np.ndarray) -> float:
    """Largest position step of the mean over its average step."""
    steps = np.linalg.norm(np.diff(mean[:, :3], axis=0), axis=1)
    return float(steps.max() / steps.mean())


def rotation_matrices(q: np.ndarray) -> np.ndarray:
    """Rotation matrices ``(..., 3, 3)`` of unit quaternions ``(..., 4)``, w first."""
    w, x, y, z = np.moveaxis(q, -1, 0)
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        -2,
    )


def evaluate(series, methods, epochs, seed, device):
    M = Product((Euclidean(3), Quaternion()))
    outcomes = {"interpolation": paper.unaligned(series, M)}
    for method in methods:
        outcomes[method] = paper.run_method(
            method, series, M, epochs=epochs, seed=seed, device=device
        )
    results = {}
    for method, outcome in outcomes.items():
        values = paper.score(outcome, series, M)
        for part, space, cols in (
            ("position", Euclidean(3), slice(0, 3)),
            ("orientation", Quaternion(), slice(3, 7)),
        ):
            values[f"AQ {part}"] = metrics.alignment_quality(
                outcome.aligned[..., cols], outcome.mean[..., cols], space
            )
        values["speed peak"] = speed_peak(outcome.mean)
        results[method] = values
    return outcomes, results


def draw(task: str, series, outcomes: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(4 * len(outcomes), 4.4))
    span = np.ptp(np.concatenate([s[:, :3] for s in series]), axis=0).max()
    for k, (method, outcome) in enumerate(outcomes.items()):
        ax = fig.add_subplot(1, len(outcomes), k + 1, projection="3d")
        for s in series:
            ax.plot(*s[:, :3].T, color="0.75", lw=0.7)
        mean = outcome.mean
        colors = plt.cm.viridis(np.linspace(0, 1, len(mean)))
        ax.scatter(*mean[:, :3].T, c=colors, s=3)
        frames = np.linspace(0, len(mean) - 1, 10).astype(int)
        R = rotation_matrices(mean[frames, 3:])
        for axis, color in zip(range(3), ("tab:red", "tab:green", "tab:blue"), strict=True):
            ax.quiver(*mean[frames, :3].T, *R[:, :, axis].T, length=0.08 * span, color=color)
        ax.set_title(paper.LABELS.get(method, method))
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_zlabel("z [m]")
    fig.suptitle(f"{task}: mean pose trajectory (colour: time; frames: tool x/y/z axes)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"figure written to {path}", file=sys.stderr)


def main(argv=None) -> None:
    parser = paper.paper_parser(__doc__)
    parser.add_argument("--tasks", nargs="+", default=list(TASKS), choices=list(TASKS))
    parser.add_argument("--methods", nargs="+", default=["ttw", "ntw", "rtw", "dba"])
    parser.add_argument("--figure-dir", help="write pose_<task>.png figures here")
    parser.add_argument("--quick", action="store_true", help="64 epochs, 4 grating demos")
    parser.add_argument(
        "--full-resolution", action="store_true",
        help="every sample (grating 2,322-3,371, wiping 1,096-1,457) instead of every 10th / 5th",
    )  # fmt: skip
    args = paper.parse_paper_args(parser, argv)
    if args.figure_dir:
        check_writable(args.figure_dir, directory=True)
    root = data_dir(args.data_dir)
    if args.quick:
        args.epochs = 64
    sections = {}
    for task in args.tasks:
        loader, step = TASKS[task]
        step = 1 if args.full_resolution else step
        series = [s[::step] for s in loader(root)]
        if args.quick and task == "grating":
            series = series[::3]
        outcomes, results = evaluate(series, args.methods, args.epochs, args.seed, args.device)
        lengths = sorted(len(s) for s in series)
        every = "every sample" if step == 1 else f"every {step}th sample"
        title = f"{task}: N = {len(series)}, T = {lengths[0]}-{lengths[-1]} ({every})"
        sections[title] = paper.markdown_table({m: [v] for m, v in results.items()}, COLUMNS)
        if args.figure_dir:
            draw(task, series, outcomes, Path(args.figure_dir) / f"pose_{task}.png")
            sections[title] += f"\n\n![{task}](pose_{task}.png)"
        print(f"{task}: done", file=sys.stderr, flush=True)
    paper.write_markdown(
        args.markdown,
        "Real pose demonstrations in R^3 x S^3 (paper, section V-D)",
        f"""
At most {args.epochs} epochs for TTW, NTW and RTW (the defaults stop early; the paper preset runs
all of them), Z = min(N, 4) T_max. Barycenter loss (BL) and
alignment quality (AQ) are sums over the N demonstrations of path-normalised DTW with the
pose distance; "AQ position" (metres) and "AQ orientation" (radians, sign-invariant)
score the two factors separately; "speed peak" is the largest step of the mean position
over its average step (1 for constant speed; large values mean compressed motion that
a robot would have to execute fast). Lower is better, best in bold. The paper reports
this experiment with figures and robot executions, not with these numbers.
""",
        sections,
    )


if __name__ == "__main__":
    main()
