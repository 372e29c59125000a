"""Configuration of one alignment: method defaults, presets, checked values.

Three presets (explicit arguments always override them):

* ``"alignment"`` (:func:`sk_rtw.align`'s default): the settings that measured better or
  cheaper for aligning demonstrations (docs: alignment speed): ``Z = min(N, 4) T_max``, a
  warp network of width 64 on 64 knots, no tangent-point refinement, the mean warm-started
  from the previous epoch, early stopping, and for RTW warps that start from DTW paths
  to a reference series on the average time axis (see :mod:`sk_rtw.align._start`), with
  the paper's equal-weight mean.
* ``"class-means"`` (the estimators' default): the same, and for RTW the
  density-weighted mean (:mod:`sk_rtw.align._density`) on the time axis of the DTW
  reference, 11 start rounds, lighter smoothing of the path warps and a quicker stop;
  means as long as the median series of their class. Nearest-centroid accuracy on the UCR
  development archive: 0.787 against 0.752 (docs: class means); on the S^1 experiment it
  halves alignment quality, hence a separate preset.
* ``"paper"``: the paper's configuration of each method (section V): output length
  ``Z = N T_max``, the warp network 1-512-512-1025-(N-1) evaluated at every output time,
  the interpolation tangent point refined twice, warps starting at the identity, five
  Gauss–Newton steps of the mean per epoch, all 256 epochs.

``"default"`` (or None) names the caller's own preset: ``"alignment"`` for
:func:`sk_rtw.align`, ``"class-means"`` for the estimators. TTW and NTW keep the identity
start and equal-weight mean of their published form in every preset.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any, Literal, overload

import numpy as np
import torch

from ._start import START_AXES
from ._warps import INITS

METHODS = ("rtw", "ttw", "ntw")
PRESETS = ("default", "alignment", "class-means", "paper")
WARP_STARTS = ("identity", "dtw")

#: The paper's defaults of each method (section V). ``sinc_window=None`` is the full sinc.
METHOD_DEFAULTS: dict[str, dict[str, Any]] = {
    "rtw": {
        "warp": "neural",
        "init": "xavier",
        "sinc_window": 10,
        "loss_window": 5,
        "loss_step": 5,
        "penalty": 100.0,
        "warp_start": "identity",
    },
    "ntw": {
        "warp": "neural",
        "init": "zeros",
        "sinc_window": None,
        "loss_window": 0,
        "loss_step": 1,
        "penalty": 100.0,
        "warp_start": "identity",
    },
    "ttw": {
        "warp": "sine",
        "init": "zeros",
        "sinc_window": 10,
        "loss_window": 0,
        "loss_step": 1,
        "penalty": 0.0,
        "warp_start": "identity",
    },
}

#: Settings of each preset shared by all methods.
PRESET_DEFAULTS: dict[str, dict[str, Any]] = {
    "alignment": {
        "warp_knots": 64,
        "tangent_refinements": 0,
        "hidden_size": 512,
        "mean_iterations": 2,
        "mean_start": "previous",
        "n_iter_no_change": 20,
        "tol": 1e-3,
    },
    "paper": {
        "warp_knots": None,
        "tangent_refinements": 2,
        "hidden_size": 512,
        "mean_iterations": 5,
        "mean_start": "first",
        "n_iter_no_change": None,
    },
}
PRESET_DEFAULTS["class-means"] = {
    **PRESET_DEFAULTS["alignment"],
    "hidden_size": 64,
    "n_iter_no_change": 10,
}
MEAN_STARTS = ("first", "previous")
#: How the aligned series are weighted in the mean (see :mod:`sk_rtw.align._density`).
MEAN_WEIGHTS = ("equal", "density")

#: What each preset changes in a method's paper defaults.
PRESET_METHODS: dict[str, dict[str, dict[str, Any]]] = {
    # start from DTW paths; a zero readout makes the learned warp start at the identity,
    # so the composed warps start exactly at the DTW start
    "alignment": {"rtw": {"warp_start": "dtw", "init": "zero-readout"}},
    "class-means": {
        "rtw": {
            "warp_start": "dtw",
            "init": "zero-readout",
            "mean_weights": "density",
            "start_axis": "reference",
            "dtw_rounds": 11,
            "smoothing": 0.5,
        }
    },
    "paper": {},
}

#: Options of every method and preset.
COMMON_DEFAULTS: dict[str, Any] = {
    "n_components": 8,
    "dtw_rounds": 3,
    "smoothing": 2.0,
    "start_axis": "average",
    "mean_weights": "equal",
    "tol": 1e-4,
    "cuda_graph": False,
}
#: Options that ``align`` takes as keywords beyond its named parameters.
METHOD_OPTIONS = (
    "n_components", "dtw_rounds", "cuda_graph", "init", "warp_knots", "tangent_refinements",
    "hidden_size", "mean_iterations", "mean_start", "mean_weights", "smoothing",
    "start_axis",
)  # fmt: skip


def method_defaults(
    method: str, preset: str | None = None, own: str = "alignment"
) -> dict[str, Any]:
    """Every engine default of ``method`` under ``preset``.

    Parameters
    ----------
    method : {"rtw", "ttw", "ntw"}
    preset : {"default", "alignment", "class-means", "paper"} or None
        None and ``"default"`` mean ``own``.
    own : {"alignment", "class-means"}, default="alignment"
        The caller's own preset.

    Returns
    -------
    defaults : dict
    """
    method, preset = check_method(method), check_preset(preset, own)
    return {
        **COMMON_DEFAULTS,
        **METHOD_DEFAULTS[method],
        **PRESET_DEFAULTS[preset],
        **PRESET_METHODS[preset].get(method, {}),
    }


#: Largest default output length of ``align``, as a multiple of the longest series.
DEFAULT_LENGTH_FACTOR = 4


def default_output_length(n_signals: int, max_length: int, preset: str = "default") -> int:
    """Length ``Z`` of the aligned series and mean that :func:`align` uses by default.

    ``"paper"``: ``Z = N T_max``. ``"default"``: ``Z = min(N, 4) T_max``, the paper's
    value for up to 4 series, capped so that time and memory stay linear in ``N``. A
    finer ``Z`` lets the warps resample more finely: the aligned series agree better
    under DTW (docs: output length). The estimators use ``Z = T_max`` instead (see
    :func:`classification_output_length`).

    Parameters
    ----------
    n_signals : int
        Number of series N aligned together.
    max_length : int
        Length of the longest series, ``T_max``.
    preset : {"default", "paper"}

    Returns
    -------
    Z : int
        Length of the mean, shape ``(Z, *point_shape)``, and of every aligned series.
    """
    if check_preset(preset) == "paper":
        return max(2, n_signals * max_length)
    return max(2, min(n_signals, DEFAULT_LENGTH_FACTOR) * max_length)


def classification_output_length(lengths: Any, preset: str = "default") -> int:
    """Length ``Z`` of the mean of one class (or cluster) of the estimators.

    ``"default"``: the median length of the class's series (``T`` for series of one
    length). A nearest-centroid classifier compares each series with the means by DTW,
    and loses accuracy when the means are longer than the series: on the UCR development
    archive, DBA's own means resampled to 2 T and 4 T fall from 0.783 to 0.750 and 0.720
    mean accuracy; on the unequal-length sets a mean as long as the longest series of the
    training set loses 0.12 on GesturePebbleZ1 against one of the class's median length
    (docs: class means). ``"paper"``: ``N T_max`` for the class's ``N`` series.

    Parameters
    ----------
    lengths : array-like of int
        Lengths of the class's training series.
    preset : {"default", "paper"}

    Returns
    -------
    Z : int
    """
    lengths = np.asarray(lengths, dtype=np.int64).ravel()
    if lengths.size == 0:
        raise ValueError("a class needs at least one series")
    if check_preset(preset) == "paper":
        return max(2, int(lengths.size * lengths.max()))
    return max(2, int(np.round(np.median(lengths))))


@dataclass(frozen=True)
class AlignmentConfig:
    """The resolved configuration of one :func:`align` run.

    Every field is the value actually used (preset and method defaults filled in);
    ``output_length`` is ``Z``, the length of ``Alignment.mean`` (shape
    ``(Z, *point_shape)``) and of every aligned series; ``warp_start`` is ``"given"``
    when starting warps were passed as an array. See :func:`align` for each field.
    """

    method: str
    preset: str
    warp: str
    init: str
    warp_start: str
    dtw_rounds: int
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
    mean_start: str
    mean_weights: str
    smoothing: float
    start_axis: str
    n_iter_no_change: int | None
    tol: float
    device: str
    cuda_graph: bool = False

    def to_dict(self) -> dict[str, Any]:
        """The configuration as a plain dictionary (field name to value).

        Returns
        -------
        config : dict
        """
        return asdict(self)


def check_method(method: Any) -> str:
    if not isinstance(method, str) or method.lower() not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    return method.lower()


def check_preset(preset: Any, own: str = "alignment") -> str:
    """The preset's name, with None and ``"default"`` resolved to the caller's ``own``."""
    if preset is None:
        return own
    if not isinstance(preset, str) or preset.lower() not in PRESETS:
        raise ValueError(f"preset must be one of {PRESETS} or None, got {preset!r}")
    preset = preset.lower()
    return own if preset == "default" else preset


@overload
def check_int(name: str, value: Any, minimum: int, allow_none: Literal[False] = ...) -> int: ...


@overload
def check_int(name: str, value: Any, minimum: int, allow_none: Literal[True]) -> int | None: ...


def check_int(name: str, value: Any, minimum: int, allow_none: bool = False) -> int | None:
    if value is None and allow_none:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(value)


def check_choice(name: str, value: Any, choices: tuple[str, ...]) -> str:
    if not isinstance(value, str) or value.lower() not in choices:
        raise ValueError(f"{name} must be one of {choices}, got {value!r}")
    return value.lower()


def check_positive(name: str, value: Any, allow_zero: bool = False) -> float:
    if (
        isinstance(value, bool)
        or not isinstance(value, (int, float, np.number))
        or not (math.isfinite(value) and (value > 0 or (allow_zero and value == 0)))
    ):
        bound = ">= 0" if allow_zero else "> 0"
        raise ValueError(f"{name} must be a finite number {bound}, got {value!r}")
    return float(value)


def resolve_config(
    method: str,
    n_signals: int,
    max_length: int,
    *,
    preset: str | None = None,
    output_length=None,
    n_epochs=256,
    learning_rate=0.01,
    sinc_window=None,
    loss_window=None,
    loss_step=None,
    penalty=None,
    device="cpu",
    warp_start: str = "auto",
    n_iter_no_change: Any = "auto",
    tol: Any = None,
    method_options: dict[str, Any] | None = None,
    own_preset: str = "alignment",
) -> AlignmentConfig:
    """Merge preset and method defaults with explicit arguments; check every value.

    ``warp_start`` is the name of the start (``"identity"``, ``"dtw"``), ``"given"`` for
    starting warps passed as an array, or ``"auto"`` for the preset's choice.
    """
    method, preset = check_method(method), check_preset(preset, own_preset)
    defaults = method_defaults(method, preset)
    options = dict(method_options or {})
    unknown = set(options) - set(METHOD_OPTIONS)
    if unknown:
        raise TypeError(f"unknown option(s) for align(): {sorted(unknown)}")
    value = {**defaults, **options}
    init = value["init"]
    if init not in INITS:
        raise ValueError(f"init must be one of {INITS}, got {init!r}")
    if warp_start == "auto":
        warp_start = defaults["warp_start"]
    elif warp_start not in (*WARP_STARTS, "given"):
        raise ValueError(
            f"warp_start must be one of {WARP_STARTS} or an array of warps, got {warp_start!r}"
        )
    if not isinstance(value["cuda_graph"], bool):
        raise ValueError(f"cuda_graph must be True or False, got {value['cuda_graph']!r}")
    if sinc_window is None:
        sinc_window = defaults["sinc_window"]
    elif sinc_window == "full":
        sinc_window = None
    else:
        sinc_window = check_int("sinc_window", sinc_window, 0)
    if output_length is None:
        output_length = default_output_length(n_signals, max_length, preset)
    if value["mean_start"] not in MEAN_STARTS:
        raise ValueError(f"mean_start must be one of {MEAN_STARTS}, got {value['mean_start']!r}")
    if isinstance(n_iter_no_change, str) and n_iter_no_change == "auto":
        n_iter_no_change = defaults["n_iter_no_change"]
    tol = value["tol"] if tol is None else tol
    return AlignmentConfig(
        method=method,
        preset=preset,
        warp=defaults["warp"],
        init=init,
        warp_start=warp_start,
        dtw_rounds=check_int("dtw_rounds", value["dtw_rounds"], 1),
        output_length=check_int("output_length", output_length, 2),
        n_epochs=check_int("n_epochs", n_epochs, 0),
        learning_rate=check_positive("learning_rate", learning_rate),
        sinc_window=sinc_window,
        loss_window=check_int(
            "loss_window", defaults["loss_window"] if loss_window is None else loss_window, 0
        ),
        loss_step=check_int(
            "loss_step", defaults["loss_step"] if loss_step is None else loss_step, 1
        ),
        penalty=check_positive(
            "penalty", defaults["penalty"] if penalty is None else penalty, allow_zero=True
        ),
        n_components=check_int("n_components", value["n_components"], 1),
        hidden_size=check_int("hidden_size", value["hidden_size"], 1),
        warp_knots=check_int("warp_knots", value["warp_knots"], 2, allow_none=True),
        tangent_refinements=check_int("tangent_refinements", value["tangent_refinements"], 0),
        mean_iterations=check_int("mean_iterations", value["mean_iterations"], 1),
        mean_start=value["mean_start"],
        mean_weights=check_choice("mean_weights", value["mean_weights"], MEAN_WEIGHTS),
        smoothing=check_positive("smoothing", value["smoothing"], allow_zero=True),
        start_axis=check_choice("start_axis", value["start_axis"], START_AXES),
        n_iter_no_change=check_int(
            'n_iter_no_change (an integer >= 1, None or "auto")',
            n_iter_no_change,
            1,
            allow_none=True,
        ),
        tol=check_positive("tol", tol, allow_zero=True),
        device=check_device(device),
        cuda_graph=value["cuda_graph"],
    )


def check_device(device: Any) -> str:
    """A torch device that exists on this machine, as a string; clear errors otherwise."""
    try:
        resolved = torch.device(device)
    except (RuntimeError, TypeError, ValueError):
        raise ValueError(
            f"device must be a torch device such as 'cpu', 'cuda' or 'cuda:0', got {device!r}"
        ) from None
    if resolved.type == "cuda" and not torch.cuda.is_available():
        build = "a CPU-only build" if torch.version.cuda is None else "a CUDA build"
        raise ValueError(
            f"device={device!r}, but torch finds no CUDA device (torch {torch.__version__} is "
            f"{build}); use device='cpu' or install a CUDA build of torch on a GPU machine"
        )
    if resolved.type == "cuda" and resolved.index is not None:
        if resolved.index >= torch.cuda.device_count():
            raise ValueError(
                f"device={device!r}, but only {torch.cuda.device_count()} CUDA device(s) exist"
            )
    if resolved.type == "mps" and not torch.backends.mps.is_available():
        raise ValueError(f"device={device!r}, but torch finds no MPS device")
    return str(resolved)
