"""The public :func:`align`: its arguments checked and resolved into one configuration,
its documentation rendered from the declarations, one batch of one group."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np
import torch

from .._random import check_generator
from .._settings import (
    DEVICE_PARAMETER,
    ENGINE_METHODS,
    KNOBS,
    PRESET_PARAMETER,
    check_knobs,
    check_preset,
)
from ..manifolds import Manifold
from ..utils import SeriesCollection, check_series_collection
from ..utils._common_params import DTW_WINDOW, MANIFOLD, N_JOBS, RANDOM_STATE, VERBOSE
from ..utils._constraints import Options, Satisfies
from ..utils._params import Declaration, Parameter, check_signature_defaults, drop_auto
from ._config import resolve_config, size_config
from ._fit import align_collection
from ._result import Alignment


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
ALIGN_WINDOW = replace(
    DTW_WINDOW,
    doc="Sakoe-Chiba band of the DTW start (its medoid and paths), its radius as a fraction "
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
