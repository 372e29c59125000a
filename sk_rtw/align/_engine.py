"""The alignment engine: RTW, TTW and NTW as configurations of one optimisation loop."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import torch

from .._random import check_generator
from .._resources import available_memory, format_bytes
from ..manifolds import Manifold
from ..utils import SeriesCollection, check_series_collection
from ._config import AlignmentConfig, resolve_config
from ._loss import monotonicity_penalty, window_loss, window_weights
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
        Total loss (alignment loss + penalty) at every epoch.
    best_epoch : int
        Epoch whose parameters are returned (lowest total loss); -1 when nothing was
        optimised (a single signal).
    manifold : Manifold
    config : AlignmentConfig
    """

    mean: np.ndarray
    aligned: np.ndarray
    warps: np.ndarray
    loss_history: np.ndarray
    best_epoch: int
    manifold: Manifold
    config: AlignmentConfig
    fit_time: float = field(default=0.0)


def _build_warps(config: AlignmentConfig, n_signals: int) -> NeuralWarps | SineWarps:
    if config.warp == "sine":
        return SineWarps(n_signals, config.n_components)
    return NeuralWarps(n_signals, config.hidden_size, config.init, config.warp_knots)


class _Problem:
    """Everything one forward pass needs, on the right device."""

    def __init__(self, collection: SeriesCollection, config: AlignmentConfig):
        device = torch.device(config.device)
        self.manifold = collection.manifold
        self.config = config
        self.data = torch.as_tensor(collection.data, dtype=torch.float64, device=device)
        self.lengths = torch.as_tensor(collection.lengths, device=device)
        self.zhat = unit_time(config.output_length, device=device)
        self.loss_weights = window_weights(
            config.output_length, config.loss_window, config.loss_step, device=device
        )
        self.mean_iterations = 1 if self.manifold.is_flat else config.mean_iterations
        self.interpolate = SincInterpolator(
            self.manifold,
            self.data,
            self.lengths,
            config.sinc_window,
            config.tangent_refinements,
        )
        #: Starting warps (N, Z) that the learned warps are composed with, or None.
        self.start: torch.Tensor | None = None

    def forward(self, model: WarpModel):
        raw = model(self.zhat)
        warps = model.finalise(raw)
        if self.start is not None:
            warps = compose_warps(self.start, warps)
        aligned = self.interpolate(warps)
        mean = self.manifold.mean(aligned, axis=0, max_iter=self.mean_iterations, tol=0.0)
        distances = self.manifold._dist(aligned, mean.unsqueeze(0))
        loss = window_loss(distances, self.loss_weights)
        if self.config.penalty > 0:
            loss = loss + self.config.penalty * monotonicity_penalty(raw)
        return loss, warps, aligned, mean


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
    random_state: Any = None,
    device: str | torch.device = "cpu",
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
    preset : {"default", "paper"} or None, default=None (``"default"``)
        ``"paper"``: the paper's configuration (``Z = N T_max``, warps starting at the
        identity, Xavier-initialised network evaluated at every output time, interpolation
        tangent point refined twice). ``"default"``: ``Z = min(N, 4) T_max``, network on 64
        knots, no refinement, and for RTW the DTW start (``warp_start="dtw"``) with a
        zero-readout network. Explicit arguments override the preset.
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
    random_state : int, RandomState, Generator or None
        Seeds the network initialisation and the DTW start; equal seeds give identical
        results.
    device : str or torch.device, default="cpu"
        Torch device for the optimisation, e.g. ``"cuda"``. Results are numpy arrays.
    verbose : bool or int, default=False
        Print the loss every ``max(1, n_epochs // 10)`` epochs (or every ``verbose``
        epochs when an int > 1).
    **method_options
        ``n_components`` (TTW sine terms, default 8), ``hidden_size`` (512),
        ``warp_knots`` (times at which the warp network is evaluated and linearly
        interpolated between; None evaluates it at every output time as the paper
        does), ``tangent_refinements`` (Gauss–Newton refinements of the sinc tangent
        point; 0 uses the centre sample of the window, whose tangent vectors are then
        computed once per fit), ``mean_iterations`` (Gauss–Newton iterations of the mean
        per epoch, 5), ``init`` (``"xavier"``, ``"zeros"`` or ``"zero-readout"``),
        ``dtw_rounds`` (references of the DTW start, 3), ``cuda_graph`` (capture each
        epoch in a CUDA graph on a CUDA device; off by default, see the GPU guide).

    Returns
    -------
    Alignment
        ``mean`` (Z, *point_shape), ``aligned`` (N, Z, *point_shape), ``warps`` (N, Z),
        ``loss_history``, ``best_epoch``, ``manifold`` and the resolved ``config``.

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
        method_options=method_options,
    )
    check_memory(collection, config)
    start = time.perf_counter()
    rng = check_generator(random_state)
    seed = int(rng.integers(2**31 - 1))
    # magnitudes beyond 1e+-100: align in a frame rescaled by a power of two
    scale = collection.manifold.extreme_scale(collection.data)
    if scale is not None:
        collection = SeriesCollection(
            data=collection.data / scale, lengths=collection.lengths, manifold=collection.manifold
        )
    with torch.random.fork_rng(devices=[]):
        torch.manual_seed(seed)
        model = _build_warps(config, n_signals)
        model.to(config.device)
    problem = _Problem(collection, config)
    if config.warp_start == "dtw" and n_signals > 1:
        given_start = dtw_start(
            collection,
            config.output_length,
            config.dtw_rounds,
            lambda warps: problem.interpolate(warps.to(problem.data.device)),
            rng,
        )
    if given_start is not None:
        problem.start = torch.as_tensor(given_start, dtype=torch.float64, device=config.device)
    history = np.full(config.n_epochs, np.nan)
    best_epoch = -1
    trainable = [p for p in model.parameters() if p.requires_grad]
    if n_signals > 1 and config.n_epochs > 0 and trainable:
        best_epoch = _optimise(problem, model, history, verbose)
    with torch.no_grad():
        _, warps, aligned, mean = problem.forward(model)
    factor = 1.0 if scale is None else scale
    return Alignment(
        mean=collection.manifold.continuous(mean.cpu().numpy() * factor),
        aligned=collection.manifold.continuous(aligned.cpu().numpy() * factor),
        warps=warps.cpu().numpy(),
        loss_history=history,
        best_epoch=best_epoch,
        manifold=collection.manifold,
        config=config,
        fit_time=time.perf_counter() - start,
    )


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
    per_point = 8 * (point * (6 + (4 * config.mean_iterations if curved else 0)) + 8)
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
) -> int:
    """Adam over the warp parameters; loads the best iterate into ``model``."""
    config = problem.config
    trainer = Trainer(
        lambda: problem.forward(model)[0],
        [p for p in model.parameters() if p.requires_grad],
        config.n_epochs,
        config.learning_rate,
        cuda_graph=config.cuda_graph,
    )
    report, every = progress_printer(config.method, config.n_epochs, verbose)
    best_epoch = trainer.run(report, every)
    history[:] = trainer.history[: config.n_epochs].cpu().numpy()
    return best_epoch
