"""The alignment engine: RTW, TTW and NTW as configurations of one optimisation loop.

:func:`align` aligns one collection of series. The estimators average every class of a
training set, and k-means every cluster, in *one* optimisation:
:func:`align_collection` takes the stacked series of all groups with the group of each,
and trains the stacked warp models of all groups at once (the groups share no parameter,
so each follows the trajectory of a separate fit; each has its own seed, best iterate and
early stop).
"""

from __future__ import annotations

import copy
import sys
import time
from dataclasses import dataclass, field
from functools import partial
from typing import Any

import numpy as np
import torch

from .._random import check_generator
from .._resources import available_memory, format_bytes
from .._threads import limited_threads, threads_for
from ..dtw import path_indices
from ..manifolds import Manifold
from ..manifolds._mean import frechet_mean
from ..utils import SeriesCollection, check_series_collection
from ..utils._common_params import DTW_WINDOW, MANIFOLD, N_JOBS, RANDOM_STATE, VERBOSE
from ..utils._params import (
    Declaration,
    Options,
    Parameter,
    Satisfies,
    check_signature_defaults,
    drop_auto,
)
from ._config import (
    DEVICE_PARAMETER,
    PRESET_PARAMETER,
    AlignmentConfig,
    check_knobs,
    check_preset,
    resolve_config,
    size_config,
)
from ._density import density_representatives
from ._knobs import ENGINE_METHODS, KNOBS
from ._layout import GroupLayout
from ._loss import window_weights
from ._refine import refine_mean
from ._sinc import SincInterpolator, table_budget
from ._start import dtw_start, path_warp
from ._training import Trainer, early_stop_note, progress_printer
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
    cost : float
        The loss (alignment loss + penalty) at the returned warps.
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
    cost: float = field(default=float("nan"))


def _build_warps(
    config: AlignmentConfig, layout: GroupLayout, seeds: list[int]
) -> NeuralWarps | SineWarps:
    if config.warp == "sine":
        assert config.n_components is not None  # resolved for TTW
        return SineWarps(layout, config.n_components)
    assert config.hidden_size is not None and config.init is not None  # resolved for RTW, NTW
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
        z = output_length(config)
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

    def subset(self, groups: torch.Tensor) -> _Problem:
        """The problem of ``groups`` only (increasing indices): their series, starting
        warps and warm-started means; each computed exactly as in the whole problem."""
        layout, rows = self.layout.subset(groups)
        other = copy.copy(self)
        other.layout = layout
        other.interpolate = self.interpolate.subset(rows)
        # one copy of the series, shared with the interpolator as in the whole problem
        other.data, other.lengths = other.interpolate.data, other.interpolate.lengths
        other.series_weight = self.series_weight[rows]
        other.start = None if self.start is None else self.start[rows]
        other.warm = None if self.warm is None else self.warm[groups].clone()
        return other

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
        codes, sizes = self.layout.codes, self.layout.sizes
        if self.manifold.is_flat:  # exact in one step, from any start
            return frechet_mean(self.manifold, points, weights, codes, sizes=sizes)
        if config.mean_start == "first":
            return frechet_mean(self.manifold, points, weights, codes, sizes=sizes,
                                max_iter=config.mean_iterations, tol=0.0)  # fmt: skip
        if self.warm is None or self.warm.shape[1] != points.shape[1]:
            return frechet_mean(self.manifold, points, weights, codes, sizes=sizes,
                                differentiate="none")  # fmt: skip
        mean = frechet_mean(self.manifold, points, weights, codes, sizes=sizes, start=self.warm,
                            max_iter=config.mean_iterations, tol=0.0,
                            differentiate="last")  # fmt: skip
        self.warm.copy_(mean.detach())
        return mean

    def converged_mean(self, warps: torch.Tensor, start: torch.Tensor | None = None):
        """The converged mean along ``warps`` (no gradient): DTW start and returned mean."""
        with torch.no_grad():
            aligned = self.interpolate(warps)
            points, weights = self.points_and_weights(warps, aligned)
            return frechet_mean(self.manifold, points, weights, self.layout.codes,
                                start=start, differentiate="none",
                                sizes=self.layout.sizes)  # fmt: skip

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


def output_length(config: AlignmentConfig) -> int:
    """``config.output_length``, which the engine needs sized (:func:`size_config`)."""
    if config.output_length is None:
        raise ValueError("the configuration has no output length yet: size it with size_config")
    return config.output_length


def _is_engine_method(value: Any) -> bool:
    return callable(getattr(value, "get_params", None)) and getattr(value, "name", None) in (
        ENGINE_METHODS
    )


ALIGN_VERBOSE = Parameter(
    "verbose",
    VERBOSE.constraints,
    "Print the loss every max(1, n_epochs // 10) epochs (True or 1), or every verbose "
    "epochs (an int > 1).",
)
ALIGN_WINDOW = Parameter(
    "dtw_window",
    DTW_WINDOW.constraints,
    "Sakoe-Chiba band of the DTW start (its medoid and paths), its radius as a fraction "
    "of the shorter series' length; None: no band.",
)
ALIGN_METHOD = Parameter(
    "method",
    (
        Options(ENGINE_METHODS),
        Satisfies("RTW, TTW or NTW", "RTW(), TTW() or NTW()", predicate=_is_engine_method),
    ),
    'The method: "rtw" (neural warps, windowed sinc, Gaussian window loss, monotonicity '
    'penalty), "ntw" (neural warps with zero init, full sinc, pointwise loss) or "ttw" '
    "(sine-series warps with running-maximum monotonicity, windowed sinc, pointwise loss); "
    "or a method object holding settings, RTW(hidden_size=64).",
)


def align(
    X: Any,
    *,
    manifold: str | Manifold = "euclidean",
    method: Any = "rtw",
    preset: str = "alignment",
    dtw_window: float | None = None,
    random_state: Any = None,
    device: str | torch.device = "cpu",
    n_jobs: int | None = None,
    verbose: bool | int = False,
    **settings: Any,
) -> Alignment:
    """Jointly align N time series on a Riemannian manifold and compute their mean.

    Learns one monotone warping function per series such that the warped series are
    close to their Riemannian mean, by Adam on the paper's loss. ``method`` selects
    Riemannian Time Warping (``"rtw"``) or the Riemannian forms of its baselines
    Trainable Time Warping (``"ttw"``) and Neural Time Warping (``"ntw"``); all three run
    through the same interpolation, mean, loss and optimisation code. ``preset="paper"``
    gives the paper's exact configuration of each method; every other setting (the
    knobs below) defaults to ``"auto"``, the preset's value, resolved as in the
    estimators: the same preset gives the same configuration for the same series.

    The length of the mean and of the aligned series, ``Z`` (``output_length``), is by
    default ``min(N, 4) T_max`` (the ``"alignment"`` preset: the paper's ``N T_max`` up
    to 4 series, then linear in ``N``); ``preset="paper"`` gives ``N T_max``, and
    ``preset="class-means"`` the median length of the series.

    Parameters
    ----------
    X : array-like or list of array-like
        ``(N, T)`` univariate, ``(N, T, *point_shape)`` or a list of ``(T_n, *point_shape)``
        series of unequal lengths (each is interpolated with its own ``T_n``).
    %(parameters)s
    **settings
        The knobs of the method (all ``"auto"`` by default): %(knobs)s. ``warp_start``
        also takes your own starting warps, an array of shape (N, Z), non-decreasing
        from 0 to 1. A knob of another method is a ``TypeError`` naming it.

    Returns
    -------
    Alignment
        ``mean`` (Z, *point_shape), ``aligned`` (N, Z, *point_shape), ``warps`` (N, Z),
        ``loss_history``, ``best_epoch``, ``n_iter``, ``cost``, ``manifold`` and the
        resolved ``config``.

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
    if (isinstance(method, str) and method.lower() == "dba") or getattr(
        method, "name", ""
    ) == "dba":
        raise ValueError(
            'align runs the engine\'s methods ("rtw", "ttw", "ntw"); DBA has its own '
            "function: sk_rtw.baselines.dba_average(X, manifold=...), or "
            'RTWNearestCentroid(method="dba") for class means'
        )
    method = ALIGN_METHOD.check(method)
    if not isinstance(method, str):  # a method object: its settings, then the keywords
        settings = {**drop_auto(method.get_params(deep=False)), **settings}
        method = method.name
    preset = check_preset(preset)
    window = ALIGN_WINDOW.check(dtw_window)
    device_name = DEVICE_PARAMETER.check(device)
    RANDOM_STATE.check(random_state)
    N_JOBS.check(n_jobs)
    ALIGN_VERBOSE.check(verbose)
    given = settings.get("warp_start")
    given_start = None
    if given is not None and not isinstance(given, str):
        settings = {k: v for k, v in settings.items() if k != "warp_start"}
    explicit = check_knobs(method, settings)
    collection = X if isinstance(X, SeriesCollection) else check_series_collection(X, manifold)
    n_signals = collection.n_series
    if given is not None and not isinstance(given, str):
        given_start = _check_warps(given, n_signals, explicit.get("output_length"))
        explicit["output_length"] = given_start.shape[1]
    config = size_config(
        resolve_config(method, preset, explicit, device=device_name,
                       given_start=given_start is not None, dtw_window=window),
        collection.lengths,
    )  # fmt: skip
    seed = int(check_generator(random_state).integers(2**31 - 1))
    (result,) = align_collection(
        collection, np.zeros(n_signals, dtype=np.int64), [seed], config,
        given_start=given_start, n_jobs=n_jobs, verbose=verbose,
    )  # fmt: skip
    return result


def _align_docs() -> None:
    """``align``'s "Parameters" from the declarations, the knobs listed (the signature is
    the written one: the knobs arrive in ``**settings``)."""
    own = Declaration(
        (MANIFOLD, ALIGN_METHOD, PRESET_PARAMETER, ALIGN_WINDOW, RANDOM_STATE,
         DEVICE_PARAMETER, N_JOBS, ALIGN_VERBOSE),
        {"manifold": "euclidean", "method": "rtw", "preset": "alignment", "dtw_window": None,
         "random_state": None, "device": "cpu", "n_jobs": None, "verbose": False},
    )  # fmt: skip
    check_signature_defaults(align, own)
    knobs = [KNOBS[name] for name in KNOBS if set(KNOBS[name].methods) & set(ENGINE_METHODS)]
    listing = ", ".join(f"``{k.name}``" for k in knobs)
    doc = align.__doc__ or ""
    indent = "    "
    block = "\n".join(indent + line if line else line for line in own.docs().splitlines())
    align.__doc__ = doc.replace("    %(parameters)s", block).replace("%(knobs)s", listing)


_align_docs()


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
    check_memory(collection, config, layout.n_groups)
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
    with limited_threads(threads_for(n_jobs, work)):
        model = _build_warps(config, layout, torch_seeds).to(config.device)
        problem = _Problem(collection, layout, config)
        if config.warp_start == "dtw" and layout.max_size > 1:
            given_start = dtw_start(
                collection,
                layout,
                output_length(config),
                config.dtw_rounds,
                lambda warps: _finite(
                    problem.converged_mean(warps.to(problem.data.device)),
                    original,
                    "the DTW start's mean",
                ),
                rngs,
                smoothing=config.smoothing,
                axis=config.start_axis,
                window=config.dtw_window,
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
            _, group_loss, warps, aligned, mean = problem.forward(model)
            mean = _finite(problem.converged_mean(warps, start=mean), original, "the mean")
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


def _refined(problem: _Problem, collection: SeriesCollection, layout: GroupLayout, mean):
    """Every group's mean refined (:mod:`sk_rtw.align._refine`), and what describes it:
    each series warped onto its refined mean along their DTW path (as the DTW start
    warps series onto its reference), those aligned series, and the loss at the refined
    mean. Returns ``(mean, warps, aligned, costs)`` as the forward pass does."""
    config, manifold = problem.config, collection.manifold
    band = -1.0 if config.dtw_window is None else float(config.dtw_window)
    means = mean.cpu().numpy().copy()
    warps = np.empty((layout.n_series, output_length(config)))
    for g in range(layout.n_groups):
        members = layout.members(g)
        series = [collection.series(i) for i in members]
        means[g] = refine_mean(series, means[g], manifold, steps=config.refine_steps,
                               window=config.dtw_window).mean  # fmt: skip
        for i, s in zip(members, series, strict=True):
            path, _ = path_indices(means[g], s, manifold, band)
            warps[i] = path_warp(path, len(means[g]), len(s), smoothing=0.0)  # exact path
    device = problem.data.device
    refined = torch.as_tensor(means, dtype=torch.float64, device=device)
    warps_t = torch.as_tensor(warps, dtype=torch.float64, device=device)
    aligned = problem.interpolate(warps_t)
    distances = manifold._dist(aligned, problem.layout.expand(refined))
    costs = problem.layout.sum((distances @ problem.loss_weights) * problem.series_weight)
    return refined, warps_t, aligned, costs.cpu().numpy()


def _finite(values: torch.Tensor, collection: SeriesCollection, what: str) -> torch.Tensor:
    """``values``, or a ``ValueError`` when float64 could not follow the geometry."""
    if not bool(torch.isfinite(values).all()):
        note = collection.manifold.spread_note(collection.data)
        raise ValueError(
            f"aligning these series on {collection.manifold!r} left float64 arithmetic "
            f"(non-finite values in {what})" + (f": {note}" if note else "") + "; the "
            "geodesics between such points overflow: rescale or regularise the data"
        )
    return values


def estimated_memory(
    collection: SeriesCollection, config: AlignmentConfig, n_groups: int = 1
) -> int:
    """Rough peak bytes of an alignment: activations kept for the backward pass.

    Per output point and series: the interpolated point and its derivative, the
    distances, and for curved spaces the Gauss–Newton iterations of the mean; the table
    of window vectors; the network's activations at its evaluation times.
    """
    n_series, t_max = collection.n_series, collection.max_length
    z = output_length(config)
    point = max(1, collection.data[0, 0].size)
    curved = not collection.manifold.is_flat
    steps = config.mean_iterations if config.mean_start == "first" else 1
    per_point = 8 * (point * (6 + (4 * steps if curved else 0)) + 8)
    taps = t_max if config.sinc_window is None else 2 * config.sinc_window + 1
    table = 8 * n_series * t_max * taps * point
    table = table if table <= table_budget(torch.device(config.device)) else 0
    times = z if config.warp_knots is None else min(z, config.warp_knots)
    width = config.hidden_size or 0  # TTW's sine warps have no network
    network = 8 * 3 * times * (2 * width + 1 + n_series) + 8 * 4 * z * n_series
    parameters = network_memory(config, n_series, n_groups)
    return n_series * z * per_point + table + network + parameters


def network_memory(config: AlignmentConfig, n_series: int, n_groups: int = 1) -> int:
    """Bytes of the warp networks' weights with their gradients and Adam's two moments:
    one 1-H-H-(2H+1)-(N_g-1) network per group, about ``H^2 + 2 H N`` weights in all
    (none for TTW)."""
    width = config.hidden_size or 0
    per_group = width * width + 5 * width
    weights = n_groups * per_group + (2 * width + 1) * max(n_series - n_groups, 0)
    return 8 * 4 * weights


def check_memory(collection: SeriesCollection, config: AlignmentConfig, n_groups: int = 1) -> None:
    """``MemoryError`` naming the sizes when an alignment cannot fit in memory."""
    need, free = estimated_memory(collection, config, n_groups), available_memory()
    if need <= free:
        return
    network = network_memory(config, collection.n_series, n_groups)
    if network > need / 2:
        raise MemoryError(
            f"the warp network of hidden_size={config.hidden_size} for "
            f"{collection.n_series} series needs about {format_bytes(network)} for its "
            f"weights and their optimiser state, more than the {format_bytes(free)} of "
            "memory available: lower hidden_size (the paper's is 512)"
        )
    raise MemoryError(
        f"aligning {collection.n_series} series to output_length Z={output_length(config)} "
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
    n_groups = problem.layout.n_groups
    trainer = Trainer(
        partial(_stage_loss, problem, model),
        list(model.parameters()),
        config.n_epochs,
        config.learning_rate,
        parameter_groups=model.parameter_groups(),
        n_groups=n_groups,
        n_iter_no_change=config.n_iter_no_change,
        tol=config.tol,
        cuda_graph=config.cuda_graph,
    )
    show, every = progress_printer(config.method, config.n_epochs, verbose)
    whole = np.full(history.shape, np.nan)
    running = torch.arange(n_groups)  # the trainer's groups, in the whole problem's numbering

    def report(done: int, part: np.ndarray) -> None:
        whole[:done, running.numpy()] = part
        show(done, whole[:done])

    best_epoch, epochs_run = np.full(n_groups, -1), np.zeros(n_groups, dtype=int)
    narrowing = trainer.device.type == "cpu" and n_groups > 1 and hasattr(model, "subset")
    stage_problem, stage_model = problem, model
    while True:
        best = trainer.run(report, every, pause=_half_stopped if narrowing else None)
        ids = running.numpy()
        whole[:, ids] = trainer.history.cpu().numpy()
        best_epoch[ids] = trainer.best_epoch.cpu().numpy()
        epochs_run[ids] = trainer.epochs_run.cpu().numpy()
        if best is not None:  # finished: the stage model holds every group's best iterate
            if stage_model is not model:
                _write_back(model, running, list(stage_model.parameters()))
            break
        # the stopped groups' best iterates go back to the whole model; the rest go on alone
        stopped = torch.nonzero(~trainer.active.cpu()).flatten()
        _write_back(model, running[stopped], trainer.best, trainer.rows(stopped))
        keep = torch.nonzero(trainer.active.cpu()).flatten()
        stage_problem = stage_problem.subset(keep.to(stage_problem.layout.codes.device))
        stage_model = stage_model.subset(keep.to(trainer.device))
        trainer = trainer.narrow(
            keep,
            partial(_stage_loss, stage_problem, stage_model),
            list(stage_model.parameters()),
            stage_model.parameter_groups(),
        )
        running = running[keep]
    done = trainer.epochs_done
    note = early_stop_note(config.method, done, config.n_epochs, best_epoch,
                           config.n_iter_no_change, config.tol)  # fmt: skip
    if verbose and note:
        print(note, file=sys.stderr, flush=True)
    history[:done] = whole[:done]
    return best_epoch, epochs_run


def _half_stopped(active: torch.Tensor) -> bool:
    """Narrow the batch once half of its groups have stopped: a stopped group's epochs
    are wasted work, and at most log2(groups) narrowings are paid."""
    return 2 * int(active.sum()) <= active.numel()


def _stage_loss(problem: _Problem, model: WarpModel):
    """The trainer's loss: total and per-group losses of ``model`` on ``problem``."""
    return problem.forward(model)[:2]


def _write_back(
    whole: WarpModel,
    groups: torch.Tensor,
    values: list[torch.Tensor],
    rows: list[torch.Tensor] | None = None,
) -> None:
    """Copy a narrowed model's parameter ``values`` (or their ``rows``) for ``groups``
    (the whole model's numbering) into ``whole``'s parameters."""
    groups = groups.to(next(whole.parameters()).device)
    picks: list[torch.Tensor | None] = list(rows) if rows is not None else [None] * len(values)
    with torch.no_grad():
        for target, owner, value, picked in zip(whole.parameters(), whole.parameter_groups(),
                                                values, picks, strict=True):  # fmt: skip
            target[torch.isin(owner, groups)] = value if picked is None else value[picked]
