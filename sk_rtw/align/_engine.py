"""The alignment engine: RTW, TTW and NTW as configurations of one optimisation loop.

:func:`align` aligns one collection of series. The estimators average every class of a
training set, and k-means every cluster, in *one* optimisation:
:func:`align_collection` takes the stacked series of all groups with the group of each,
and trains the stacked warp models of all groups at once (the groups share no parameter,
so each follows the trajectory of a separate fit; each has its own seed, best iterate and
early stop).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import torch

from .._random import check_generator
from .._resources import available_memory, format_bytes
from .._threads import limited_threads, threads_for
from ..manifolds import Manifold
from ..utils import SeriesCollection, check_series_collection
from ._config import AlignmentConfig, resolve_config
from ._density import density_representatives
from ._layout import GroupLayout
from ._loss import window_weights
from ._means import converged_group_mean, group_mean
from ._sinc import TABLE_BYTES, SincInterpolator
from ._start import dtw_start
from ._training import Trainer, progress_printer
from ._warps import NeuralWarps, SineWarps, WarpModel, compose_warps, unit_time


@dataclass(frozen=True, eq=False)
class Alignment:
    """Result of :func:`align`.

    Attributes
    ----------
    mean : ndarray of shape (Z, *point_shape)
        Riemannian mean of the aligned signals (on the manifold).
    aligned : ndarray of shape (N, Z, *point_shape)
        Every signal resampled along its warp.
    warps : ndarray of shape (N, Z)
        Warping functions in [0, 1]: ``aligned[n, z]`` is signal ``n`` at relative
        position ``warps[n, z]`` (0 = first sample, 1 = last sample).
    loss_history : ndarray of shape (n_epochs,)
        Total loss (alignment loss + penalty) at every epoch; NaN after an early stop.
    best_epoch : int
        Epoch whose parameters are returned (lowest total loss); -1 when nothing was
        optimised (a single signal, or ``n_epochs=0``).
    manifold : Manifold
    config : AlignmentConfig
    fit_time : float
        Seconds the fit took (for a batch of groups: the whole batch).
    n_iter : int
        Epochs run (fewer than ``config.n_epochs`` after an early stop).
    """

    mean: np.ndarray
    aligned: np.ndarray
    warps: np.ndarray
    loss_history: np.ndarray
    best_epoch: int
    manifold: Manifold
    config: AlignmentConfig
    fit_time: float = field(default=0.0)
    n_iter: int = field(default=0)


def _build_warps(
    config: AlignmentConfig, layout: GroupLayout, seeds: list[int]
) -> NeuralWarps | SineWarps:
    if config.warp == "sine":
        return SineWarps(layout, config.n_components)
    return NeuralWarps(layout, config.hidden_size, config.init, config.warp_knots, seeds)


class _Problem:
    """Everything one forward pass needs, on the right device."""

    def __init__(self, collection: SeriesCollection, layout: GroupLayout, config: AlignmentConfig):
        device = torch.device(config.device)
        self.manifold = collection.manifold
        self.config = config
        self.layout = layout.to(device)
        self.data = torch.as_tensor(collection.data, dtype=torch.float64, device=device)
        self.lengths = torch.as_tensor(collection.lengths, device=device)
        z = config.output_length
        self.zhat = unit_time(z, device=device)
        self.loss_weights = window_weights(z, config.loss_window, config.loss_step, device=device)
        sizes = self.layout.sizes.to(torch.float64)
        #: 1 / (N_g Z) for every series: each group's loss is the paper's mean over its series
        self.series_weight = 1.0 / (self.layout.expand(sizes) * z)
        self.interpolate = SincInterpolator(
            self.manifold,
            self.data,
            self.lengths,
            config.sinc_window,
            config.tangent_refinements,
        )
        #: Starting warps (N, Z) that the learned warps are composed with, or None.
        self.start: torch.Tensor | None = None
        #: The previous epoch's means (``mean_start="previous"``): the next Gauss–Newton start.
        self.warm: torch.Tensor | None = None

    def points_and_weights(self, warps: torch.Tensor, aligned: torch.Tensor):
        """What enters the mean: the aligned points with equal weights, or the stretch
        representatives with their sample counts (``mean_weights="density"``)."""
        if self.config.mean_weights == "density":
            return density_representatives(self.manifold, self.data, self.lengths, warps,
                                           aligned)  # fmt: skip
        return aligned, None

    def average(self, warps: torch.Tensor, aligned: torch.Tensor) -> torch.Tensor:
        """The engine's mean of every group's aligned series (loss and returned mean)."""
        config = self.config
        points, weights = self.points_and_weights(warps, aligned)
        if self.manifold.is_flat:  # exact in one step, from any start
            return group_mean(self.manifold, points, self.layout, weights)
        if config.mean_start == "first":
            return group_mean(self.manifold, points, self.layout, weights,
                              iterations=config.mean_iterations, differentiate="all")  # fmt: skip
        if self.warm is None or self.warm.shape[1] != points.shape[1]:
            return converged_group_mean(self.manifold, points, self.layout, weights)
        mean = group_mean(self.manifold, points, self.layout, weights, start=self.warm,
                          iterations=config.mean_iterations, differentiate="last")  # fmt: skip
        self.warm.copy_(mean.detach())
        return mean

    def converged_mean(self, warps: torch.Tensor, start: torch.Tensor | None = None):
        """The converged mean along ``warps`` (no gradient): DTW start and returned mean."""
        with torch.no_grad():
            aligned = self.interpolate(warps)
            points, weights = self.points_and_weights(warps, aligned)
            return converged_group_mean(self.manifold, points, self.layout, weights,
                                        start=start)  # fmt: skip

    def initial_warps(self) -> torch.Tensor:
        identity = self.zhat.expand(self.layout.n_series, -1)
        return identity if self.start is None else compose_warps(self.start, identity)

    def prepare_mean(self) -> None:
        """The Gauss–Newton start of the first epoch: the converged mean at the start."""
        if self.config.mean_start == "previous" and not self.manifold.is_flat:
            self.warm = self.converged_mean(self.initial_warps()).clone()

    def forward(self, model: WarpModel):
        raw = model(self.zhat)
        warps = model.finalise(raw)
        if self.start is not None:
            warps = compose_warps(self.start, warps)
        aligned = self.interpolate(warps)
        mean = self.average(warps, aligned)
        distances = self.manifold._dist(aligned, self.layout.expand(mean))
        per_series = (distances @ self.loss_weights) * self.series_weight
        if self.config.penalty > 0:
            decrease = torch.relu(raw[:, :-1] - raw[:, 1:]).sum(1)
            per_series = per_series + self.config.penalty * decrease
        group_loss = self.layout.sum(per_series)
        return group_loss.sum(), group_loss, warps, aligned, mean


def align(
    X: Any,
    *,
    manifold: str | Manifold = "euclidean",
    method: str = "rtw",
    preset: str | None = None,
    output_length: int | None = None,
    n_epochs: int = 256,
    learning_rate: float = 0.01,
    sinc_window: int | str | None = None,
    loss_window: int | None = None,
    loss_step: int | None = None,
    penalty: float | None = None,
    warp_start: str | Any = "auto",
    n_iter_no_change: int | str | None = "auto",
    tol: float | None = None,
    random_state: Any = None,
    device: str | torch.device = "cpu",
    n_jobs: int | None = None,
    verbose: bool | int = False,
    **method_options: Any,
) -> Alignment:
    """Jointly align N time series on a Riemannian manifold and compute their mean.

    Learns one monotone warping function per series such that the warped series are
    close to their Riemannian mean, by Adam on the paper's loss. ``method`` selects
    Riemannian Time Warping (``"rtw"``) or the Riemannian forms of its baselines
    Trainable Time Warping (``"ttw"``) and Neural Time Warping (``"ntw"``); all three run
    through the same interpolation, mean, loss and optimisation code. ``preset="paper"``
    gives the paper's exact configuration of each method.

    Parameters
    ----------
    X : array-like or list of array-like
        ``(N, T)`` univariate, ``(N, T, *point_shape)`` or a list of ``(T_n, *point_shape)``
        series of unequal lengths (each is interpolated with its own ``T_n``).
    manifold : str or Manifold, default="euclidean"
        Space of the samples; a name takes its dimension from the data.
    method : {"rtw", "ttw", "ntw"}, default="rtw"
        Warp model, loss and interpolation defaults:

        - ``"rtw"``: neural warps, windowed sinc, Gaussian window loss, monotonicity
          penalty;
        - ``"ntw"``: neural warps (zero init), full sinc, pointwise loss, penalty;
        - ``"ttw"``: sine-series warps with running-maximum monotonicity, windowed sinc,
          pointwise loss.
    preset : {"alignment", "class-means", "paper", "default"} or None, default=None
        None or ``"default"``: ``"alignment"``, ``Z = min(N, 4) T_max``, a warp network of
        width 512 on 64 knots, no tangent-point refinement, the mean warm-started from the
        previous epoch, early stopping, and for RTW the DTW start (``warp_start="dtw"``)
        on the average time axis with a zero-readout network and the paper's equal-weight
        mean. ``"class-means"`` (the estimators' default): width 64, a quicker stop, and
        for RTW the density-weighted mean on the reference's time axis (see
        ``mean_weights`` below). ``"paper"``: the paper's configuration (``Z = N T_max``,
        warps starting at the identity, Xavier-initialised network evaluated at every
        output time, interpolation tangent point refined twice, all epochs). Explicit
        arguments override the preset.
    output_length : int, optional
        Length ``Z`` of the aligned series and mean (preset default: ``min(N, 4) T_max``,
        or ``N T_max`` for the paper).
    n_epochs : int, default=256
        Adam iterations; the parameters of the epoch with the lowest loss are kept.
    learning_rate : float, default=0.01
        Adam learning rate.
    sinc_window : int or "full", optional
        Half-width ``nu`` of the sinc window (method default: 10; ``"full"`` for NTW).
    loss_window, loss_step : int, optional
        ``kappa`` and ``rho`` of the Gaussian-weighted window loss (RTW: 5 and 5;
        TTW/NTW: 0, the pointwise loss).
    penalty : float, optional
        Weight ``lambda`` of the monotonicity penalty (RTW/NTW: 100; TTW: 0).
    warp_start : {"identity", "dtw"} or array-like of shape (N, Z), optional
        What the learned warps start from. ``"identity"``: the paper. ``"dtw"``: warps
        read off DTW paths to a reference series (the medoid, then the mean, for
        ``dtw_rounds`` rounds), centred so that their average is the identity; the
        learned warps are composed with them. An array: your own non-decreasing warps,
        from 0 to 1, at the ``Z`` output times. Default: the preset's (RTW: ``"dtw"``;
        TTW, NTW and the paper preset: ``"identity"``).
    n_iter_no_change : int, None or "auto", default="auto"
        Stop when the loss has not improved by more than ``tol`` (relative) for this many
        epochs in a row, keeping the best iterate; None trains all ``n_epochs``.
        ``"auto"``: the preset's (20; the paper preset: None).
    tol : float, optional
        Relative improvement that counts for ``n_iter_no_change`` (default 1e-4).
    random_state : int, RandomState, Generator or None
        Seeds the network initialisation and the DTW start; equal seeds give identical
        results.
    device : str or torch.device, default="cpu"
        Torch device for the optimisation, e.g. ``"cuda"``. Results are numpy arrays.
    n_jobs : int, optional
        Threads of torch and numba during the fit, scikit-learn's convention (None: 1,
        -1: all cores); more than one only where the problem is large enough to gain from
        them. The caller's thread settings are restored afterwards.
    verbose : bool or int, default=False
        Print the loss every ``max(1, n_epochs // 10)`` epochs (or every ``verbose``
        epochs when an int > 1).
    **method_options
        ``n_components`` (TTW sine terms, default 8), ``hidden_size`` (width of the warp
        network, 512; 64 in ``"class-means"``), ``warp_knots`` (times at which the warp
        network is evaluated and linearly interpolated between; None evaluates it at
        every output time as the paper does), ``tangent_refinements`` (Gauss–Newton
        refinements of the sinc tangent point; 0 uses the centre sample of the window,
        whose tangent vectors are then computed once per fit), ``mean_iterations``
        (Gauss–Newton steps of the mean per epoch, 2; the paper's 5), ``mean_start``
        (``"previous"``: from the previous epoch's mean, only the last step
        differentiated; ``"first"``: the paper's steps from the first series, all
        differentiated), ``mean_weights`` (``"equal"``: the paper's mean of the aligned
        series; ``"density"``: every series weighted by the samples each output time
        covers, see :mod:`sk_rtw.align._density`), ``init`` (``"xavier"``, ``"zeros"`` or
        ``"zero-readout"``), ``dtw_rounds`` (references of the DTW start, 3), ``smoothing``
        (Gaussian smoothing of the DTW path warps, in reference samples, 2.0),
        ``start_axis`` (``"average"`` or ``"reference"``: the time axis of the DTW start),
        ``cuda_graph`` (capture each epoch in a CUDA graph on a CUDA device; off by
        default, see the GPU guide).

    Returns
    -------
    Alignment
        ``mean`` (Z, *point_shape), ``aligned`` (N, Z, *point_shape), ``warps`` (N, Z),
        ``loss_history``, ``best_epoch``, ``n_iter``, ``manifold`` and the resolved
        ``config``.

    Examples
    --------
    >>> import numpy as np
    >>> from sk_rtw import align
    >>> t = np.linspace(0, 1, 50)
    >>> X = np.stack([np.sin(2 * np.pi * t ** p) for p in (0.8, 1.0, 1.25)])
    >>> result = align(X, n_epochs=20, random_state=0)
    >>> result.mean.shape, result.aligned.shape, result.warps.shape
    ((150, 1), (3, 150, 1), (3, 150))
    >>> align(X, preset="paper", n_epochs=2).mean.shape  # Z = N T_max
    (150, 1)
    """
    collection = X if isinstance(X, SeriesCollection) else check_series_collection(X, manifold)
    n_signals = collection.n_series
    given_start = None
    if not isinstance(warp_start, str):
        given_start = _check_warps(warp_start, n_signals, output_length)
        output_length = given_start.shape[1]
    config = resolve_config(
        method,
        n_signals,
        collection.max_length,
        preset=preset,
        output_length=output_length,
        n_epochs=n_epochs,
        learning_rate=learning_rate,
        sinc_window=sinc_window,
        loss_window=loss_window,
        loss_step=loss_step,
        penalty=penalty,
        device=device,
        warp_start="given" if given_start is not None else warp_start,
        n_iter_no_change=n_iter_no_change,
        tol=tol,
        method_options=method_options,
    )
    seed = int(check_generator(random_state).integers(2**31 - 1))
    (result,) = align_collection(
        collection, np.zeros(n_signals, dtype=np.int64), [seed], config,
        given_start=given_start, n_jobs=n_jobs, verbose=verbose,
    )  # fmt: skip
    return result


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
    check_memory(collection, config)
    start_time = time.perf_counter()
    layout = GroupLayout.from_codes(codes)
    if len(seeds) != layout.n_groups:
        raise ValueError(f"{len(seeds)} seeds for {layout.n_groups} groups")
    rngs = [np.random.default_rng(int(seed)) for seed in seeds]
    torch_seeds = [int(rng.integers(2**31 - 1)) for rng in rngs]
    # magnitudes beyond 1e+-100: align in a frame rescaled by a power of two
    scale = collection.manifold.extreme_scale(collection.data)
    if scale is not None:
        collection = SeriesCollection(
            data=collection.data / scale, lengths=collection.lengths, manifold=collection.manifold
        )
    work = (
        collection.n_series
        * config.output_length
        * collection.data[0, 0].size
        * (collection.max_length if config.sinc_window is None else 2 * config.sinc_window + 1)
    )
    with limited_threads(threads_for(n_jobs, work)):
        model = _build_warps(config, layout, torch_seeds).to(config.device)
        problem = _Problem(collection, layout, config)
        if config.warp_start == "dtw" and layout.max_size > 1:
            given_start = dtw_start(
                collection,
                layout,
                config.output_length,
                config.dtw_rounds,
                lambda warps: problem.converged_mean(warps.to(problem.data.device)),
                rngs,
                smoothing=config.smoothing,
                axis=config.start_axis,
            )
        if given_start is not None:
            problem.start = torch.as_tensor(given_start, dtype=torch.float64, device=config.device)
        problem.prepare_mean()
        history = np.full((config.n_epochs, layout.n_groups), np.nan)
        best_epoch = np.full(layout.n_groups, -1)
        epochs_run = np.zeros(layout.n_groups, dtype=int)
        trainable = [p for p in model.parameters() if p.requires_grad]
        if layout.max_size > 1 and config.n_epochs > 0 and trainable:
            best_epoch, epochs_run = _optimise(problem, model, history, verbose)
        with torch.no_grad():
            _, _, warps, aligned, mean = problem.forward(model)
            mean = problem.converged_mean(warps, start=mean)
    factor = 1.0 if scale is None else scale
    manifold = collection.manifold
    fit_time = time.perf_counter() - start_time
    mean_np, aligned_np, warps_np = mean.cpu().numpy(), aligned.cpu().numpy(), warps.cpu().numpy()
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
            )
        )
    return results


def estimated_memory(collection: SeriesCollection, config: AlignmentConfig) -> int:
    """Rough peak bytes of an alignment: activations kept for the backward pass.

    Per output point and series: the interpolated point and its derivative, the
    distances, and for curved spaces the Gauss–Newton iterations of the mean; the table
    of window vectors; the network's activations at its evaluation times.
    """
    n_series, t_max = collection.n_series, collection.max_length
    z = config.output_length
    point = max(1, collection.data[0, 0].size)
    curved = not collection.manifold.is_flat
    steps = config.mean_iterations if config.mean_start == "first" else 1
    per_point = 8 * (point * (6 + (4 * steps if curved else 0)) + 8)
    taps = t_max if config.sinc_window is None else 2 * config.sinc_window + 1
    table = min(8 * n_series * t_max * taps * point, TABLE_BYTES)
    times = z if config.warp_knots is None else min(z, config.warp_knots)
    network = 8 * 3 * times * (2 * config.hidden_size + 1 + n_series) + 8 * 4 * z * n_series
    return n_series * z * per_point + table + network


def check_memory(collection: SeriesCollection, config: AlignmentConfig) -> None:
    """``MemoryError`` naming the sizes when an alignment cannot fit in memory."""
    need, free = estimated_memory(collection, config), available_memory()
    if need > free:
        raise MemoryError(
            f"aligning {collection.n_series} series to output_length Z={config.output_length} "
            f"needs about {format_bytes(need)}, more than the {format_bytes(free)} of memory "
            "available: lower output_length (the paper preset uses N T_max), align fewer "
            "series at once, or use warp_knots"
        )


def _check_warps(warps: Any, n_signals: int, output_length: int | None) -> np.ndarray:
    """Validate starting warps given as an array: (N, Z), non-decreasing, 0 to 1."""
    try:
        warps = np.asarray(warps, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(
            "warp_start must be 'identity', 'dtw' or an array of warps of shape (N, Z)"
        ) from None
    if warps.ndim != 2 or warps.shape[0] != n_signals or warps.shape[1] < 2:
        raise ValueError(
            f"warp_start must have shape (n_series, Z) = ({n_signals}, Z) with Z >= 2, "
            f"got {warps.shape}"
        )
    if output_length is not None and warps.shape[1] != output_length:
        raise ValueError(
            f"warp_start has {warps.shape[1]} time points but output_length is {output_length}"
        )
    if not np.all(np.isfinite(warps)):
        raise ValueError("warp_start contains NaN or infinite values")
    if np.any(np.diff(warps, axis=1) < 0) or np.any(warps < 0) or np.any(warps > 1):
        raise ValueError("warp_start must be non-decreasing and lie in [0, 1]")
    if not (np.allclose(warps[:, 0], 0.0) and np.allclose(warps[:, -1], 1.0)):
        raise ValueError("every warp in warp_start must go from 0 to 1")
    return warps


def _optimise(
    problem: _Problem, model: WarpModel, history: np.ndarray, verbose: bool | int
) -> tuple[np.ndarray, np.ndarray]:
    """Adam over the warp parameters; loads every group's best iterate into ``model``.

    Returns the best epoch and the number of epochs run of every group.
    """
    config = problem.config
    parameters = list(model.parameters())
    trainer = Trainer(
        lambda: problem.forward(model)[:2],
        parameters,
        config.n_epochs,
        config.learning_rate,
        parameter_groups=model.parameter_groups(),
        n_groups=problem.layout.n_groups,
        n_iter_no_change=config.n_iter_no_change,
        tol=config.tol,
        cuda_graph=config.cuda_graph,
    )
    report, every = progress_printer(config.method, config.n_epochs, verbose)
    best_epoch = trainer.run(report, every)
    done = trainer.epochs_done
    history[:done] = trainer.history[:done].cpu().numpy()
    return best_epoch, trainer.epochs_run.cpu().numpy()
