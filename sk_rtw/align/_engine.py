"""The alignment engine: RTW, TTW and NTW as configurations of one optimisation loop."""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
import torch

from .._random import check_generator
from ..manifolds import Manifold
from ..utils import SeriesCollection, check_series_collection
from ._loss import monotonicity_penalty, window_loss, window_weights
from ._sinc import SincInterpolator
from ._training import Trainer, progress_printer
from ._warps import NeuralWarps, SineWarps, unit_time

METHODS = ("rtw", "ttw", "ntw")

#: Engine defaults of each method (paper, section V). ``sinc_window=None`` is the full sinc.
METHOD_DEFAULTS: dict[str, dict[str, Any]] = {
    "rtw": {
        "warp": "neural",
        "init": "xavier",
        "sinc_window": 10,
        "loss_window": 5,
        "loss_step": 5,
        "penalty": 100.0,
    },
    "ntw": {
        "warp": "neural",
        "init": "zeros",
        "sinc_window": None,
        "loss_window": 0,
        "loss_step": 1,
        "penalty": 100.0,
    },
    "ttw": {
        "warp": "sine",
        "init": "zeros",
        "sinc_window": 10,
        "loss_window": 0,
        "loss_step": 1,
        "penalty": 0.0,
    },
}

#: Largest default output length, as a multiple of the longest input series.
DEFAULT_LENGTH_FACTOR = 4
#: Times at which the warp network is evaluated (None: every output time, as the paper).
#: Measured on the S^1 benchmark (docs: alignment speed): same barycenter loss and
#: alignment quality as at every output time, at a fraction of the cost.
DEFAULT_WARP_KNOTS: int | None = 64
#: Gauss–Newton refinements of the interpolation tangent point (the paper: "a few").
#: Without refinement the tangent vectors of every window are computed once per fit;
#: measured on the real demonstrations, interpolated points move by at most 2e-4 of a
#: sample spacing.
DEFAULT_REFINEMENTS = 0


@dataclass(frozen=True)
class AlignmentConfig:
    """The resolved configuration of one :func:`align` run.

    Every field is the value actually used (method defaults filled in); ``output_length``
    is ``Z``, the length of ``Alignment.mean`` (shape ``(Z, *point_shape)``) and of every
    aligned series. See :func:`align` for the meaning of each field.
    """

    method: str
    warp: str
    init: str
    output_length: int
    n_epochs: int
    learning_rate: float
    sinc_window: int | None
    loss_window: int
    loss_step: int
    penalty: float
    n_components: int
    hidden_size: int
    warp_knots: int | None
    tangent_refinements: int
    mean_iterations: int
    device: str
    cuda_graph: bool = False

    def to_dict(self) -> dict[str, Any]:
        """The configuration as a plain dictionary (field name to value).

        Returns
        -------
        config : dict
        """
        return asdict(self)


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


def _check_int(name, value, minimum, allow_none=False):
    if value is None and allow_none:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(value)


def _check_positive(name, value, allow_zero=False):
    if (
        isinstance(value, bool)
        or not isinstance(value, (int, float, np.number))
        or not (math.isfinite(value) and (value > 0 or (allow_zero and value == 0)))
    ):
        bound = ">= 0" if allow_zero else "> 0"
        raise ValueError(f"{name} must be a finite number {bound}, got {value!r}")
    return float(value)


def default_output_length(n_signals: int, max_length: int) -> int:
    """``Z = min(N, 4) * T_max``: the paper's ``N * T_max``, capped at four times ``T_max``.

    The cap keeps memory and time linear in ``N`` for large classes; see the output-length
    study in the docs for the measurements behind the factor.

    Parameters
    ----------
    n_signals : int
        Number of series N aligned together.
    max_length : int
        Length of the longest series, ``T_max``.

    Returns
    -------
    Z : int
        Length of the mean, shape ``(Z, *point_shape)``, and of every aligned series.
    """
    return max(2, min(n_signals, DEFAULT_LENGTH_FACTOR) * max_length)


def resolve_config(
    method: str,
    n_signals: int,
    max_length: int,
    *,
    output_length,
    n_epochs,
    learning_rate,
    sinc_window,
    loss_window,
    loss_step,
    penalty,
    device,
    method_options: dict[str, Any],
) -> AlignmentConfig:
    """Merge the method defaults with explicit arguments and check every value."""
    if not isinstance(method, str) or method.lower() not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    method = method.lower()
    defaults = METHOD_DEFAULTS[method]
    options = dict(method_options)
    n_components = _check_int("n_components", options.pop("n_components", 8), 1)
    hidden_size = _check_int("hidden_size", options.pop("hidden_size", 512), 1)
    warp_knots = _check_int(
        "warp_knots", options.pop("warp_knots", DEFAULT_WARP_KNOTS), 2, allow_none=True
    )
    refinements = _check_int(
        "tangent_refinements", options.pop("tangent_refinements", DEFAULT_REFINEMENTS), 0
    )
    mean_iterations = _check_int("mean_iterations", options.pop("mean_iterations", 5), 1)
    cuda_graph = options.pop("cuda_graph", False)
    if not isinstance(cuda_graph, bool):
        raise ValueError(f"cuda_graph must be True or False, got {cuda_graph!r}")
    init = options.pop("init", defaults["init"])
    if init not in ("xavier", "zeros"):
        raise ValueError(f"init must be 'xavier' or 'zeros', got {init!r}")
    if options:
        raise TypeError(f"unknown option(s) for align(): {sorted(options)}")
    if sinc_window is None:
        sinc_window = defaults["sinc_window"]
    elif sinc_window == "full":
        sinc_window = None
    else:
        sinc_window = _check_int("sinc_window", sinc_window, 0)
    if output_length is None:
        output_length = default_output_length(n_signals, max_length)
    return AlignmentConfig(
        method=method,
        warp=defaults["warp"],
        init=init,
        output_length=_check_int("output_length", output_length, 2),
        n_epochs=_check_int("n_epochs", n_epochs, 0),
        learning_rate=_check_positive("learning_rate", learning_rate),
        sinc_window=sinc_window,
        loss_window=_check_int(
            "loss_window", defaults["loss_window"] if loss_window is None else loss_window, 0
        ),
        loss_step=_check_int(
            "loss_step", defaults["loss_step"] if loss_step is None else loss_step, 1
        ),
        penalty=_check_positive(
            "penalty", defaults["penalty"] if penalty is None else penalty, allow_zero=True
        ),
        n_components=n_components,
        hidden_size=hidden_size,
        warp_knots=warp_knots,
        tangent_refinements=refinements,
        mean_iterations=mean_iterations,
        device=str(torch.device(device)),
        cuda_graph=cuda_graph,
    )


def _build_warps(config: AlignmentConfig, n_signals: int) -> torch.nn.Module:
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

    def forward(self, model: torch.nn.Module):
        raw = model(self.zhat)
        warps = model.finalise(raw)
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
    output_length: int | None = None,
    n_epochs: int = 256,
    learning_rate: float = 0.01,
    sinc_window: int | str | None = None,
    loss_window: int | None = None,
    loss_step: int | None = None,
    penalty: float | None = None,
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
    through the same interpolation, mean, loss and optimisation code.

    Parameters
    ----------
    X : array-like or list of array-like
        ``(N, T)`` univariate, ``(N, T, *point_shape)`` or a list of ``(T_n, *point_shape)``
        series of unequal lengths (each is interpolated with its own ``T_n``).
    manifold : str or Manifold, default="euclidean"
        Space of the samples; a name takes its dimension from the data.
    method : {"rtw", "ttw", "ntw"}, default="rtw"
        Warp model, loss and interpolation defaults:

        - ``"rtw"``: neural warps (Xavier init), windowed sinc, Gaussian window loss,
          monotonicity penalty;
        - ``"ntw"``: neural warps (zero init), full sinc, pointwise loss, penalty;
        - ``"ttw"``: sine-series warps with running-maximum monotonicity, windowed sinc,
          pointwise loss.
    output_length : int, optional
        Length ``Z`` of the aligned series and mean. Default ``min(N, 4) * T_max``
        (the paper's ``N * T_max``, capped so that memory and time stay linear in ``N``).
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
    random_state : int, RandomState, Generator or None
        Seeds the network initialisation; equal seeds give identical results.
    device : str or torch.device, default="cpu"
        Torch device for the optimisation, e.g. ``"cuda"``. Results are numpy arrays.
    verbose : bool or int, default=False
        Print the loss every ``max(1, n_epochs // 10)`` epochs (or every ``verbose``
        epochs when an int > 1).
    **method_options
        ``n_components`` (TTW sine terms, default 8), ``hidden_size`` (512),
        ``warp_knots`` (times at which the warp network is evaluated and linearly
        interpolated between, 64; None evaluates it at every output time as the paper
        does), ``tangent_refinements`` (Gauss–Newton refinements of the sinc tangent
        point, 0: the centre sample of the window, whose tangent vectors are then computed
        once per fit), ``mean_iterations`` (Gauss–Newton iterations of the mean per epoch,
        5), ``init`` (``"xavier"`` or ``"zeros"``), ``cuda_graph`` (capture each epoch
        in a CUDA graph on a CUDA device; off by default, see the GPU guide).

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
    """
    collection = X if isinstance(X, SeriesCollection) else check_series_collection(X, manifold)
    n_signals = collection.n_series
    config = resolve_config(
        method,
        n_signals,
        collection.max_length,
        output_length=output_length,
        n_epochs=n_epochs,
        learning_rate=learning_rate,
        sinc_window=sinc_window,
        loss_window=loss_window,
        loss_step=loss_step,
        penalty=penalty,
        device=device,
        method_options=method_options,
    )
    start = time.perf_counter()
    seed = int(check_generator(random_state).integers(2**31 - 1))
    with torch.random.fork_rng(devices=[]):
        torch.manual_seed(seed)
        model = _build_warps(config, n_signals).to(config.device)
    problem = _Problem(collection, config)
    history = np.full(config.n_epochs, np.nan)
    best_epoch = -1
    trainable = [p for p in model.parameters() if p.requires_grad]
    if n_signals > 1 and config.n_epochs > 0 and trainable:
        best_epoch = _optimise(problem, model, history, verbose)
    with torch.no_grad():
        _, warps, aligned, mean = problem.forward(model)
    return Alignment(
        mean=collection.manifold.continuous(mean.cpu().numpy()),
        aligned=collection.manifold.continuous(aligned.cpu().numpy()),
        warps=warps.cpu().numpy(),
        loss_history=history,
        best_epoch=best_epoch,
        manifold=collection.manifold,
        config=config,
        fit_time=time.perf_counter() - start,
    )


def _optimise(
    problem: _Problem, model: torch.nn.Module, history: np.ndarray, verbose: bool | int
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
