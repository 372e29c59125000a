"""The orchestration of one batch of alignments: memory check, the frame of extreme
magnitudes, the DTW start, the optimisation, the final means and their refinement, one
:class:`~._result.Alignment` per group.

The estimators average every class of a training set, and k-means every cluster, in
*one* optimisation: :func:`align_collection` takes the stacked series of all groups with
the group of each, and trains the stacked warp models of all groups at once (the groups
share no parameter, so each follows the trajectory of a separate fit; each has its own
seed, best iterate and early stop).
"""

from __future__ import annotations

import sys
import time
from typing import Any

import numpy as np
import torch

from .._heap import heap_for_temporaries
from .._resources import available_memory
from .._threads import limited_threads, threads_for
from ..dtw import path_indices
from ..utils import SeriesCollection
from ._config import AlignmentConfig
from ._layout import GroupLayout
from ._memory import check_memory
from ._narrowing import BatchOptimisation
from ._problem import Problem, check_finite, output_length
from ._refine import refine_mean
from ._result import Alignment
from ._start import dtw_start, path_warp
from ._warps import build_warps


def align_collection(
    collection: SeriesCollection,
    codes: Any,
    seeds: list[int],
    config: AlignmentConfig,
    *,
    given_start: np.ndarray | None = None,
    n_jobs: int | None = None,
    verbose: bool | int = False,
) -> list[Alignment]:
    """Align every group of a stacked collection in one optimisation.

    Parameters
    ----------
    collection : SeriesCollection
        The series of all groups.
    codes : array-like of int, shape (N,)
        Group of every series, ``0..n_groups - 1``.
    seeds : list of int
        One seed per group: ``np.random.default_rng(seed)`` draws the group's network seed,
        then its medoid candidates (as :func:`align` does with ``random_state``).
    config : AlignmentConfig
        The resolved configuration shared by every group.
    given_start : ndarray of shape (N, Z), optional
        Starting warps (``config.warp_start == "given"``).
    n_jobs : int, optional
        Threads for torch and numba during the fit (scikit-learn's convention; None: 1),
        used only when the problem is large enough to gain from them.
    verbose : bool or int
        Loss reports during training (see :func:`align`).

    Returns
    -------
    list of Alignment
        One per group, in group order.
    """
    layout = GroupLayout.from_codes(codes)
    need = check_memory(collection, config, layout.n_groups)
    start_time = time.perf_counter()
    if len(seeds) != layout.n_groups:
        raise ValueError(f"{len(seeds)} seeds for {layout.n_groups} groups")
    rngs = [np.random.default_rng(int(seed)) for seed in seeds]
    torch_seeds = [int(rng.integers(2**31 - 1)) for rng in rngs]
    original = collection  # named in error messages
    # magnitudes beyond 1e+-100: align in a frame rescaled by a power of two
    scale = collection.manifold.extreme_scale(collection.data)
    if scale is not None:
        collection = SeriesCollection(
            data=collection.data / scale, lengths=collection.lengths, manifold=collection.manifold
        )
    work = (
        collection.n_series
        * output_length(config)
        * collection.data[0, 0].size
        * (collection.max_length if config.sinc_window is None else 2 * config.sinc_window + 1)
    )
    # one (N, Z, point) float64 array: the size of most of an epoch's temporaries; the heap
    # kept for them holds up to about twice the estimated peak (9.3-9.9 against 6.0 GB for 8
    # quaternion series of 256,000 samples): only where that fits in the free memory
    temporary = collection.n_series * output_length(config) * collection.data[0, 0].size * 8
    keep_heap = torch.device(config.device).type == "cpu" and 2 * need <= available_memory()
    n_threads = threads_for(n_jobs, work)
    with limited_threads(n_threads), heap_for_temporaries(keep_heap * temporary):
        model = build_warps(config, layout, torch_seeds).to(config.device)
        problem = Problem(collection, layout, config)
        if config.warp_start == "dtw" and layout.max_size > 1:
            given_start = dtw_start(
                collection,
                layout,
                output_length(config),
                config.dtw_rounds,
                lambda warps: check_finite(
                    problem.converged_mean(warps.to(problem.data.device)),
                    original,
                    "the DTW start's mean",
                ),
                rngs,
                smoothing=config.smoothing,
                axis=config.start_axis,
                window=config.dtw_window,
                n_threads=n_threads,
                report=_printer(config.method) if verbose else None,
            )
        if given_start is not None:
            problem.start = torch.as_tensor(given_start, dtype=torch.float64, device=config.device)
        problem.prepare_mean()
        history = np.full((config.n_epochs, layout.n_groups), np.nan)
        best_epoch = np.full(layout.n_groups, -1)
        epochs_run = np.zeros(layout.n_groups, dtype=int)
        trainable = [p for p in model.parameters() if p.requires_grad]
        if layout.max_size > 1 and config.n_epochs > 0 and trainable:
            best_epoch, epochs_run = BatchOptimisation(problem, model, verbose).run(history)
        with torch.no_grad():
            _, group_loss, warps, aligned, mean = problem.forward(model)
            mean = check_finite(problem.converged_mean(warps, start=mean), original, "the mean")
            costs = group_loss.cpu().numpy()
            if config.refine_steps > 0:  # the means as free points, towards a lower DTW cost
                mean, warps, aligned, costs = _refined(problem, collection, layout, mean)
    factor = 1.0 if scale is None else scale
    manifold = collection.manifold
    mean_np, aligned_np, warps_np = mean.cpu().numpy(), aligned.cpu().numpy(), warps.cpu().numpy()
    fit_time = time.perf_counter() - start_time
    results = []
    for g in range(layout.n_groups):
        idx = layout.members(g)
        results.append(
            Alignment(
                mean=manifold.continuous(mean_np[g] * factor),
                aligned=manifold.continuous(aligned_np[idx] * factor),
                warps=warps_np[idx],
                loss_history=history[:, g].copy(),
                best_epoch=int(best_epoch[g]),
                manifold=manifold,
                config=config,
                fit_time=fit_time,
                n_iter=int(epochs_run[g]),
                cost=float(costs[g]),
            )
        )
    return results


def _refined(problem: Problem, collection: SeriesCollection, layout: GroupLayout, mean):
    """Every group's mean refined (:mod:`sk_rtw.align._refine`), and what describes it:
    each series warped onto its refined mean along their DTW path (as the DTW start
    warps series onto its reference), those aligned series, and the loss at the refined
    mean. Returns ``(mean, warps, aligned, costs)`` as the forward pass does."""
    config, manifold = problem.config, collection.manifold
    means = mean.cpu().numpy().copy()
    warps = np.empty((layout.n_series, output_length(config)))
    for g in range(layout.n_groups):
        members = layout.members(g)
        series = [collection.series(i) for i in members]
        means[g] = refine_mean(series, means[g], manifold, steps=config.refine_steps,
                               window=config.dtw_window).mean  # fmt: skip
        for i, s in zip(members, series, strict=True):
            path, _ = path_indices(means[g], s, manifold, config.dtw_window)
            warps[i] = path_warp(path, len(means[g]), len(s), smoothing=0.0)  # exact path
    device = problem.data.device
    refined = torch.as_tensor(means, dtype=torch.float64, device=device)
    warps_t = torch.as_tensor(warps, dtype=torch.float64, device=device)
    aligned = problem.interpolate(warps_t)
    distances = manifold._dist(aligned, problem.layout.expand(refined))
    costs = problem.layout.sum((distances @ problem.loss_weights) * problem.series_weight)
    return refined, warps_t, aligned, costs.cpu().numpy()


def _printer(method: str):
    """A ``verbose`` line on standard error, tagged with the method (as the epochs')."""

    def report(message: str) -> None:
        print(f"[{method}] {message}", file=sys.stderr, flush=True)

    return report
