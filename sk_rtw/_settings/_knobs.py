"""Every setting of every averaging method, declared once.

A :class:`Knob` is a declared parameter (name, accepted values, one-line doc with its
unit) and its default for each method that has it: the paper's value (section V) for
RTW, TTW and NTW, Petitjean et al.'s for DBA. A method has exactly the knobs that list
it; a preset (:mod:`sk_rtw._settings._presets`) changes some of these defaults. The
signature and docs of :func:`sk_rtw.align`, of the method objects
(:class:`sk_rtw.methods.RTW`, ...) and their validation are built from this table.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from ..utils._constraints import Boolean, Constant, Interval, Options
from ..utils._params import Parameter

#: Where the DTW start's warps are measured (``start_axis``).
START_AXES = ("average", "reference")
#: Initialisations of the warp networks (``init``).
INITS = ("xavier", "zeros", "zero-readout")

#: The alignment engine's methods (one optimisation loop, three configurations). The
#: estimators' averaging methods, these and DBA, are registered in
#: :data:`sk_rtw.methods.METHODS`.
ENGINE_METHODS = ("rtw", "ttw", "ntw")

WARP_STARTS = ("identity", "dtw")
MEAN_STARTS = ("first", "previous")
#: How the aligned series are weighted in the mean (see :mod:`sk_rtw.align._density`).
MEAN_WEIGHTS = ("equal", "density")

_NEURAL = ("rtw", "ntw")


@dataclass(frozen=True)
class Knob(Parameter):
    """A method setting: a :class:`Parameter` and its default for each method having it."""

    defaults: Mapping[str, Any] = field(default_factory=dict)

    @property
    def methods(self) -> tuple[str, ...]:
        return tuple(self.defaults)


def _every(value: Any, methods: tuple[str, ...] = ENGINE_METHODS) -> dict[str, Any]:
    return dict.fromkeys(methods, value)


def _integer(low: int) -> tuple:
    return (Interval(int, low),)


KNOBS: dict[str, Knob] = {
    knob.name: knob
    for knob in (
        Knob(
            "output_length",
            _integer(2),
            "Length Z of the mean and of every aligned series, in samples (the preset's "
            "rule by default: see the presets table).",
            _every(None),
        ),
        Knob(
            "n_epochs",
            _integer(0),
            "Most Adam epochs; the epoch with the lowest loss is kept.",
            _every(256),
        ),
        Knob(
            "learning_rate",
            (Interval(float, 0.0, closed="neither"),),
            "Adam step size.",
            _every(0.01),
        ),
        Knob(
            "sinc_window",
            (*_integer(0), Constant(None, "the full sinc")),
            "Half-width nu of the sinc interpolation window, in input samples; None: the "
            "full sinc.",
            {"rtw": 10, "ttw": 10, "ntw": None},
        ),
        Knob(
            "loss_window",
            _integer(0),
            "Half-width kappa of the Gaussian window of the loss, in loss steps (0: the "
            "pointwise loss).",
            {"rtw": 5, "ttw": 0, "ntw": 0},
        ),
        Knob(
            "loss_step",
            _integer(1),
            "Spacing rho of the loss window, in output samples.",
            {"rtw": 5, "ttw": 1, "ntw": 1},
        ),
        Knob(
            "penalty",
            (Interval(float, 0.0),),
            "Weight lambda of the monotonicity penalty.",
            {"rtw": 100.0, "ttw": 0.0, "ntw": 100.0},
        ),
        Knob(
            "warp_start",
            (Options(WARP_STARTS),),
            'What the learned warps start from: "identity" (the paper) or "dtw" (warps '
            "read off DTW paths to a reference series, which the learned warps are "
            "composed with).",
            _every("identity"),
        ),
        Knob(
            "init",
            (Options(INITS),),
            'Initial weights of the warp network: "xavier" (RTW), "zeros" (NTW) or '
            '"zero-readout" (Xavier hidden layers, zero output: the warps start at '
            "the DTW start exactly).",
            {"rtw": "xavier", "ntw": "zeros"},
        ),
        Knob(
            "hidden_size",
            _integer(1),
            "Width of the warp network's two hidden layers, in units.",
            _every(512, _NEURAL),
        ),
        Knob(
            "warp_knots",
            (*_integer(2), Constant(None, "every output time")),
            "Times at which the warp network is evaluated, linearly interpolated in "
            "between; None: every output time (the paper).",
            _every(None, _NEURAL),
        ),
        Knob(
            "warp_dtype",
            (Options(("float32", "float64")),),
            'Precision of the warp network, its inputs and its Adam moments: "float32" '
            "(the warps are cast to float64 before interpolation; the manifold operations, "
            'means and losses stay float64) or "float64" throughout (results identical to '
            "float64 runs, or offsets finer than float32's 6e-8 of the time axis).",
            _every("float64", _NEURAL),
        ),
        Knob("n_components", _integer(1), "Sine terms K of the TTW warps.", {"ttw": 8}),
        Knob(
            "tangent_refinements",
            _integer(0),
            "Gauss-Newton refinements of the sinc interpolation's tangent point (0: the "
            "window's centre sample).",
            _every(2),
        ),
        Knob(
            "mean_iterations", _integer(1), "Gauss-Newton steps of the mean per epoch.", _every(5)
        ),
        Knob(
            "mean_start",
            (Options(MEAN_STARTS),),
            'Start of the mean\'s steps in every epoch: the "first" series, every step '
            'differentiated (the paper), or the "previous" epoch\'s mean, the last step '
            "differentiated.",
            _every("first"),
        ),
        Knob(
            "mean_weights",
            (Options(MEAN_WEIGHTS),),
            '"equal": the paper\'s mean of the aligned series; "density": every series '
            "weighted by the samples each output time covers (DBA's counting, for "
            "continuous warps).",
            _every("equal"),
        ),
        Knob(
            "dtw_rounds",
            _integer(1),
            "References of the DTW start: the medoid, then the mean of each round.",
            _every(3),
        ),
        Knob(
            "smoothing",
            (Interval(float, 0.0),),
            "Standard deviation of the Gaussian that smooths the DTW start's warps, in "
            "reference samples (0: none).",
            _every(2.0),
        ),
        Knob(
            "start_axis",
            (Options(START_AXES),),
            'Time axis of the DTW start: "average" (the average timing of the series) or '
            "\"reference\" (the reference's, as DBA's mean).",
            _every("average"),
        ),
        Knob(
            "n_iter_no_change",
            (*_integer(1), Constant(None, "no early stop")),
            "Stop after this many epochs without a relative improvement of tol, keeping "
            "the best; None: run all n_epochs.",
            _every(None),
        ),
        Knob(
            "tol",
            (Interval(float, 0.0),),
            "Relative improvement of the method's objective that counts as progress (RTW, "
            "TTW, NTW: the training loss, for n_iter_no_change; DBA: the DTW cost, it stops "
            "at the first iteration below it).",
            {**_every(1e-4), "dba": 1e-5},
        ),
        Knob(
            "start_patience",
            (*_integer(2), Constant(None, "no such stop")),
            "Stop after this many epochs if the lowest loss since the first epoch is still "
            "more than 2.5 times the first epoch's (the DTW start's), keeping the start; "
            "after 3 epochs if it is still more than 20 times it.",
            _every(None),
        ),
        Knob(
            "cuda_graph",
            (Boolean(),),
            "Capture each epoch in a CUDA graph on a CUDA device (see the GPU guide).",
            _every(False),
        ),
        Knob(
            "refine_steps",
            _integer(0),
            "Steps, at each of two soft-DTW temperatures, of a final refinement of the mean as "
            "free points on the manifold: each step is the weighted Fréchet mean under the "
            "soft-DTW expected alignments to the series, and the mean of lowest DTW cost is "
            "kept (0: none).",
            _every(0),
        ),
        Knob("max_iter", _integer(1), "Most DBA refinement iterations.", {"dba": 10}),
    )
}


def method_knobs(method: str) -> tuple[Knob, ...]:
    """The knobs of ``method``, in declaration order."""
    return tuple(knob for knob in KNOBS.values() if method in knob.defaults)


def method_defaults(method: str) -> dict[str, Any]:
    """The paper's value of every knob of ``method`` (``output_length``: None, the
    preset's rule)."""
    return {knob.name: knob.defaults[method] for knob in method_knobs(method)}


def owners(name: str) -> tuple[str, ...]:
    """The methods that have the knob ``name`` (empty for an unknown name)."""
    knob = KNOBS.get(name)
    return () if knob is None else knob.methods
