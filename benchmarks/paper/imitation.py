"""Imitation learning from prepared demonstrations (paper, section V-D, Tables VII-VIII).

Usage::

    python benchmarks/paper/imitation.py --quick                      # within 10 min, 2 cores
    python benchmarks/paper/imitation.py --markdown docs/benchmarks/imitation.md
    python benchmarks/paper/imitation.py --tasks wiping --preparations raw rtw dba

Needs the ``lfd`` extra (``pip install -e ".[lfd]"``: movement-primitives, gmr) and the
demonstration data in ``../shared/data`` (``--data-dir``), read in place.

Protocol (leave one out, as in the paper). For every task and every demonstration ``k``:

1. **Prepare** the other ``N - 1`` demonstrations by one method: ``raw`` (every
   demonstration resampled to one length, the paper's "Raw Data"), ``ttw``, ``ntw``,
   ``rtw`` (``sk_rtw.align`` defaults), ``rtw-paper`` (``preset="paper"``) or ``dba``
   (manifold DBA). The aligned demonstrations are resampled to ``L`` samples, the length
   of the longest training demonstration (geodesic interpolation between neighbouring
   samples), so that every preparation feeds the models the same number of samples.
2. **Learn** one model from the ``N - 1`` prepared demonstrations, with phase
   ``t = l / (L - 1)`` in [0, 1] as the time input of every model:

   * ``DMP``: ``movement_primitives.dmp.DMP`` for positions, ``CartesianDMP`` (Ude et
     al. 2014) for position + unit quaternion, 30 weights per dimension, execution time 1;
     every demonstration is imitated on its own and the weights are averaged (the DMP's
     forcing term is linear in its weights, so this is the least-squares fit to all of
     them), started at the Fréchet mean of the demonstrations' first poses and ending at
     the mean of their last poses;
   * ``GMR``: ``gmr.GMM`` (10 components, full covariances) on the joint samples
     ``(t, c)`` of all demonstrations, where ``c`` are the tangent coordinates of the
     prepared demonstrations at their mean trajectory (:func:`sk_rtw.aligned_statistics`:
     ``Log`` at the mean, orthonormal coordinates; positions, quaternions and their
     product alike); the reproduction is ``Exp`` at the mean of ``E[c | t]``;
   * ``GP``: scikit-learn's ``GaussianProcessRegressor`` (constant x RBF + white noise,
     hyper-parameters by marginal likelihood, normalised targets) on the same ``(t, c)``,
     every demonstration subsampled to 60 phases.

3. **Score** the reproduction (``L`` samples) against the left-out demonstration as
   recorded: DTW with the position distance (metres) and with the sign-invariant
   quaternion distance (radians), normalised by the length of the optimal path (mean
   cost per step).

Tables: mean over the ``N`` left-out demonstrations (and over the shapes or letters of a
dataset). The "speed peak" (largest step over the average step; 1 is constant speed; the measure
of ``docs/benchmarks/pose.md``) is given for the mean trajectory of all ``N``
demonstrations prepared by each method, and for every model's reproductions (median over
the folds): whether what a robot would execute stays smooth.

Tasks and resolution: carrot grating (12 demonstrations, every 10th sample: 233-338) and
circular wiping (4, every 5th sample: 220-292) in R^3 x S^3 from ``icsc_hmm``; R-LASA
shapes in S^3 (4 demonstrations, every 10th sample: 100); RCFS letters in R^2 (the first
8 demonstrations of each letter, 200 samples).
"""

from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository; then _shared

from benchmarks._shared import positive_int
from benchmarks.paper._common import (
    LABELS,
    paper_parser,
    parse_paper_args,
    run_method,
    unaligned,
    write_markdown,
)
from benchmarks.paper._data import (
    data_dir,
    icsc_carrot_grating,
    icsc_wiping,
    rcfs_letter,
    rlasa_quaternions,
)
from sk_rtw import aligned_statistics, dtw_distance
from sk_rtw.manifolds import Euclidean, Manifold, Product, Quaternion

PREPARATIONS = ("raw", "ttw", "ntw", "dba", "rtw", "rtw-paper")
MODELS = ("DMP", "GMR", "GP")
POSE = Product((Euclidean(3), Quaternion()))
LABELS = {**LABELS, "raw": "Raw Data"}
#: Weights per dimension of the DMPs, GMM components, phases per demonstration for the GP.
DMP_WEIGHTS = 30
GMM_COMPONENTS = 10
GP_PHASES = 60
#: The default R-LASA shapes and RCFS letters (a stated subset).
RLASA_SHAPES = ("BendedLine", "CShape", "GShape", "Khamesh", "Sshape", "Worm")
RCFS_LETTERS = ("C", "G", "S", "W")


# ---------------------------------------------------------------- datasets
TASKS = ("grating", "wiping", "r-lasa", "rcfs")


def load_task(task: str, root: Path, quick: bool) -> tuple[Manifold, list[list[np.ndarray]]]:
    """One task: its manifold and its groups of demonstrations (shapes, letters); only its
    own files are read (a missing one is named with the folder it was looked for in)."""
    if task == "grating":
        grating = [s[::10] for s in icsc_carrot_grating(root)]
        return POSE, [grating[::3] if quick else grating]
    if task == "wiping":
        return POSE, [[s[::5] for s in icsc_wiping(root)]]
    if task == "r-lasa":
        shapes = RLASA_SHAPES[:2] if quick else RLASA_SHAPES
        return Quaternion(), [list(rlasa_quaternions(root, s)[:, ::10]) for s in shapes]
    letters = RCFS_LETTERS[:1] if quick else RCFS_LETTERS
    n_letter = 5 if quick else 8
    return Euclidean(2), [list(rcfs_letter(root, c)[:n_letter]) for c in letters]


def factors(manifold: Manifold) -> dict[str, tuple[slice, Manifold]]:
    """The columns scored as position and as orientation."""
    if manifold == POSE:
        return {"pos": (slice(0, 3), Euclidean(3)), "ori": (slice(3, 7), Quaternion())}
    if isinstance(manifold, Quaternion):
        return {"ori": (slice(0, 4), Quaternion())}
    return {"pos": (slice(0, manifold.point_shape[0]), manifold)}


# ----------------------------------------------------------- preparations
def resample(series: np.ndarray, manifold: Manifold, length: int) -> np.ndarray:
    """Geodesic interpolation of ``series`` (T, *ps) at ``length`` equally spaced times."""
    position = np.linspace(0.0, len(series) - 1, length)
    left = np.minimum(np.floor(position).astype(int), len(series) - 2)
    frac = (position - left).reshape(-1, *([1] * (series.ndim - 1)))
    a, b = series[left], series[left + 1]
    return np.asarray(manifold.exp(a, frac * manifold.log(a, b)))


def prepare(method, demos, manifold, length, epochs, seed) -> tuple[np.ndarray, np.ndarray]:
    """The prepared demonstrations ``(N, length, *ps)`` and their mean ``(length, *ps)``."""
    if method == "raw":
        outcome = unaligned(demos, manifold, length)
    else:
        z = None if method.endswith("-paper") else length
        outcome = run_method(method, demos, manifold, epochs=epochs, output_length=z, seed=seed)
    aligned = np.stack([resample(a, manifold, length) for a in outcome.aligned])
    mean = resample(np.asarray(outcome.mean), manifold, length)
    return manifold.continuous(aligned), manifold.continuous(mean)


# ------------------------------------------------------------------ models
def _continuous_quaternions(q: np.ndarray, reference: np.ndarray) -> np.ndarray:
    q = Quaternion().continuous(q)
    return q if float(np.dot(q[0], reference)) >= 0 else -q


def fit_dmp(prepared: np.ndarray, manifold: Manifold) -> np.ndarray:
    """A DMP per demonstration, weights averaged; reproduces ``(L, *ps)``."""
    from movement_primitives.dmp import DMP, CartesianDMP

    n, length = prepared.shape[:2]
    t = np.linspace(0.0, 1.0, length)
    if isinstance(manifold, Euclidean):
        make = lambda: DMP(manifold.dim, execution_time=1.0, dt=1.0 / (length - 1),  # noqa: E731
                           n_weights_per_dim=DMP_WEIGHTS)  # fmt: skip
        demos = list(prepared)
    else:  # quaternions (with zero positions) or poses: the Cartesian DMP
        make = lambda: CartesianDMP(execution_time=1.0, dt=1.0 / (length - 1),  # noqa: E731
                                    n_weights_per_dim=DMP_WEIGHTS)  # fmt: skip
        if isinstance(manifold, Quaternion):
            prepared = np.concatenate([np.zeros((n, length, 3)), prepared], axis=-1)
        reference = prepared[0, 0, 3:]
        demos = [np.concatenate([d[:, :3], _continuous_quaternions(d[:, 3:], reference)], 1)
                 for d in prepared]  # fmt: skip
    weights = []
    for demo in demos:
        dmp = make()
        dmp.imitate(t, demo)
        weights.append(dmp.get_weights())
    dmp = make()
    dmp.set_weights(np.mean(weights, axis=0))
    space = manifold if not isinstance(manifold, Quaternion) else POSE
    start = np.asarray(space.mean(np.stack([d[0] for d in demos])))
    goal = np.asarray(space.mean(np.stack([d[-1] for d in demos])))
    if not isinstance(manifold, Euclidean):  # the hemisphere the demonstrations use
        start[3:] *= np.sign(np.dot(start[3:], demos[0][0, 3:])) or 1.0
        goal[3:] *= np.sign(np.dot(goal[3:], demos[0][-1, 3:])) or 1.0
    dmp.configure(start_y=start, goal_y=goal)
    _, reproduction = dmp.open_loop()
    reproduction = reproduction[:length]
    if isinstance(manifold, Quaternion):
        reproduction = reproduction[:, 3:]
    if not isinstance(manifold, Euclidean):
        q = reproduction[..., -4:]
        reproduction[..., -4:] = q / np.linalg.norm(q, axis=-1, keepdims=True)
    return reproduction


def _regression_data(prepared, manifold, phases=None):
    stats = aligned_statistics(aligned=prepared, mean=manifold.mean(prepared), manifold=manifold)
    length = prepared.shape[1]
    t = np.linspace(0.0, 1.0, length)
    keep = np.arange(length) if phases is None else np.linspace(0, length - 1, phases).round()
    keep = keep.astype(int)
    inputs = np.tile(t[keep], len(prepared))[:, None]
    outputs = stats.coordinates[:, keep].reshape(-1, stats.dim)
    return stats, t, inputs, outputs


def _from_coordinates(stats, manifold, coords) -> np.ndarray:
    vectors = manifold.from_coordinates(stats.mean, coords)
    return np.asarray(manifold.exp(stats.mean, vectors))


def fit_gmr(prepared: np.ndarray, manifold: Manifold, seed: int) -> np.ndarray:
    """GMM/GMR on (phase, tangent coordinates at the mean); reproduces ``(L, *ps)``."""
    from gmr import GMM

    stats, t, inputs, outputs = _regression_data(prepared, manifold)
    gmm = GMM(n_components=GMM_COMPONENTS, random_state=seed)
    gmm.from_samples(np.hstack([inputs, outputs]))
    coords = gmm.predict(np.array([0]), t[:, None])
    return _from_coordinates(stats, manifold, coords)


def fit_gp(prepared: np.ndarray, manifold: Manifold, seed: int) -> np.ndarray:
    """A Gaussian process on (phase, tangent coordinates at the mean)."""
    from sklearn.gaussian_process import GaussianProcessRegressor
    from sklearn.gaussian_process.kernels import RBF, ConstantKernel, WhiteKernel

    stats, t, inputs, outputs = _regression_data(prepared, manifold, GP_PHASES)
    kernel = ConstantKernel(1.0) * RBF(length_scale=0.1, length_scale_bounds=(1e-3, 10.0))
    kernel += WhiteKernel(1e-2, noise_level_bounds=(1e-8, 10.0))
    gp = GaussianProcessRegressor(kernel=kernel, normalize_y=True, random_state=seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # convergence chatter of the kernel optimiser
        gp.fit(inputs, outputs)
    coords = gp.predict(t[:, None]).reshape(len(t), -1)
    return _from_coordinates(stats, manifold, coords)


def reproduce(model: str, prepared: np.ndarray, manifold: Manifold, seed: int) -> np.ndarray:
    if model == "DMP":
        return fit_dmp(prepared, manifold)
    if model == "GMR":
        return fit_gmr(prepared, manifold, seed)
    return fit_gp(prepared, manifold, seed)


# -------------------------------------------------------------- evaluation
def speed_peak(mean: np.ndarray, manifold: Manifold) -> float:
    """Largest step of the mean trajectory over its average step (position, else angle)."""
    steps = np.asarray(manifold.dist(mean[:-1], mean[1:])) if manifold != POSE else (
        np.linalg.norm(np.diff(mean[:, :3], axis=0), axis=1)
    )  # fmt: skip
    return float(steps.max() / max(steps.mean(), 1e-300))


def evaluate(task, manifold, groups, preparations, models, args) -> dict:
    """Mean reproduction errors {(preparation, model, factor): value}, speed peaks, times."""
    errors: dict[tuple[str, str, str], list[float]] = {}
    peaks: dict[str, list[float]] = {p: [] for p in preparations}
    reproduction_peaks: dict[tuple[str, str], list[float]] = {}
    seconds: dict[str, float] = {p: 0.0 for p in preparations}
    scored = factors(manifold)
    for group in groups:
        length = max(len(d) for d in group)
        folds = range(len(group)) if args.folds is None else range(min(args.folds, len(group)))
        for method in preparations:
            _, mean = prepare(method, group, manifold, length, args.epochs, args.seed)
            peaks[method].append(speed_peak(mean, manifold))
        for k in folds:
            train = [d for i, d in enumerate(group) if i != k]
            left_out = group[k]
            length = max(len(d) for d in train)
            for method in preparations:
                start = time.perf_counter()
                prepared, _ = prepare(method, train, manifold, length, args.epochs, args.seed)
                seconds[method] += time.perf_counter() - start
                for model in models:
                    out = reproduce(model, prepared, manifold, args.seed)
                    reproduction_peaks.setdefault((method, model), []).append(
                        speed_peak(out, manifold)
                    )
                    for name, (cols, space) in scored.items():
                        value = dtw_distance(out[:, cols], left_out[:, cols], manifold=space,
                                             normalize="path")  # fmt: skip
                        errors.setdefault((method, model, name), []).append(value)
            print(f"{task}: fold {k + 1}/{len(folds)} done", file=sys.stderr, flush=True)
    return {
        "errors": {key: float(np.mean(v)) for key, v in errors.items()},
        "peaks": {m: float(np.mean(v)) for m, v in peaks.items()},
        "reproduction_peaks": {k: float(np.median(v)) for k, v in reproduction_peaks.items()},
        "seconds": seconds,
        "factors": list(scored),
    }


def table(result: dict, preparations, models) -> str:
    """Rows: models; columns: DTW per factor for every preparation (Tables VII-VIII)."""
    names = {"pos": "DTW_pos", "ori": "DTW_ori"}
    header = ["model"] + [f"{names[f]} {LABELS.get(p, p)}" for f in result["factors"]
                          for p in preparations]  # fmt: skip
    lines = ["| " + " | ".join(header) + " |", "|" + " --- |" * len(header)]
    for model in models:
        cells = [model]
        for factor in result["factors"]:
            values = {p: result["errors"][(p, model, factor)] for p in preparations}
            best = min(values.values())
            cells += [f"**{v:.4f}**" if v == best else f"{v:.4f}" for v in values.values()]
        lines.append("| " + " | ".join(cells) + " |")
    peaks = " / ".join(f"{LABELS.get(p, p)} {result['peaks'][p]:.2f}" for p in preparations)
    times = " / ".join(f"{LABELS.get(p, p)} {result['seconds'][p]:.0f} s" for p in preparations)
    lines += ["", f"- Speed peak of the mean of all demonstrations: {peaks}."]
    for model in models:
        values = " / ".join(f"{LABELS.get(p, p)} {result['reproduction_peaks'][(p, model)]:.2f}"
                            for p in preparations)  # fmt: skip
        lines.append(f"- Speed peak of the {model} reproductions (median over folds): {values}.")
    lines.append(f"- Preparation time over the folds: {times}.")
    return "\n".join(lines)


def main(argv=None) -> None:
    parser = paper_parser(
        __doc__, engine=False, epilog=__doc__.split("Usage::")[1].split("Needs the")[0]
    )
    parser.add_argument("--tasks", nargs="+", default=list(TASKS), choices=list(TASKS))
    parser.add_argument("--preparations", nargs="+", default=list(PREPARATIONS),
                        choices=list(PREPARATIONS))  # fmt: skip
    parser.add_argument("--models", nargs="+", default=list(MODELS), choices=list(MODELS))
    parser.add_argument("--folds", type=positive_int, default=None, help="first folds only")
    parser.add_argument(
        "--quick", action="store_true",
        help="4 grating demonstrations, 2 R-LASA shapes, 1 RCFS letter of 5, 64 epochs",
    )  # fmt: skip
    args = parse_paper_args(parser, argv)
    if args.quick:
        args.epochs = min(args.epochs, 64)
    root = data_dir(args.data_dir)
    started = time.perf_counter()
    selected = [task for task in TASKS if task in args.tasks]
    try:  # every file the run needs, read before the first (minutes-long) task
        loaded = {task: load_task(task, root, args.quick) for task in selected}
    except FileNotFoundError as exc:
        raise SystemExit(f"error: {exc}") from None
    sections: dict[str, str] = {}

    def write(done: bool) -> None:
        status = (
            f"Total time {time.perf_counter() - started:.0f} s."
            if done
            else f"Partial: {len(sections)} of {len(selected)} tasks done."
        )
        write_markdown(
            args.markdown,
            "Imitation learning from prepared demonstrations (paper, Tables VII-VIII)",
            "Protocol"
            + __doc__.split("Protocol", 1)[1]
            + f"\nAt most {args.epochs} epochs for TTW, NTW and RTW (early stopping); "
            f"seed {args.seed}. {status}",
            sections,
            quiet=not done,
        )

    for task, (manifold, groups) in loaded.items():
        result = evaluate(task, manifold, groups, args.preparations, args.models, args)
        sizes = sorted({len(g) for g in groups})
        lengths = sorted({len(d) for g in groups for d in g})
        title = (
            f"{task}: {len(groups)} set(s) of {'/'.join(map(str, sizes))} demonstrations "
            f"on {manifold!r}, T = {lengths[0]}-{lengths[-1]}"
        )
        sections[title] = table(result, args.preparations, args.models)
        print(f"## {title}\n\n{sections[title]}\n", flush=True)
        print(f"{task}: done", file=sys.stderr, flush=True)
        if len(sections) < len(selected):
            write(done=False)  # a finished task is never lost to a later one's failure
    write(done=True)


if __name__ == "__main__":
    main()
