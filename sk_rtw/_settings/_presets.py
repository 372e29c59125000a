"""The presets: each one frozen record of what it changes, its output-length rule included.

A preset names a configuration of every method. The knobs' defaults
(:mod:`sk_rtw._settings._knobs`) are the paper's configuration; a preset holds only what it
changes, for the engine's methods together (``engine``) and per method (``methods``),
and the rule that gives the output length ``Z`` from the lengths of the series
averaged together. A preset name means the same in :func:`sk_rtw.align` and in every
estimator: the same series get the same resolved configuration.

* ``"alignment"`` (:func:`sk_rtw.align`'s default): what aligns a few demonstrations best
  for its cost (docs: alignment speed, S^1, poses): ``Z = min(N, 4) T_max``, the network
  on 64 knots, no tangent-point refinement, the mean warm-started from the previous
  epoch, early stopping; RTW starts from DTW paths with a zero readout.
* ``"class-means"`` (the estimators' default): what classifies best on the UCR
  development archive (0.787 against 0.752 for "alignment"'s settings, docs: UCR): the
  same with a width-64 network and a quicker stop, and for RTW the density-weighted mean
  on the DTW reference's time axis, 11 start rounds and lighter smoothing; means as long
  as the median series of their group. Not "alignment" for robots: it halves the S^1
  alignment quality and its pose means move several times faster in places.
* ``"paper"``: the paper's configuration of each method (section V), ``Z = N T_max``;
  in an estimator, one mean per class and no band (the paper's protocol) where the
  other presets choose the band and the centroids from the training data.

DBA's settings are the same in every preset.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ._knobs import ENGINE_METHODS, KNOBS, method_defaults

#: Largest default output length of the "alignment" preset, as a multiple of T_max.
LENGTH_FACTOR = 4


@dataclass(frozen=True)
class OutputLength:
    """A rule for ``Z`` from the lengths of the series averaged together."""

    formula: str
    function: Callable[[np.ndarray], int] = field(compare=False)

    def __call__(self, lengths: Any) -> int:
        lengths = np.asarray(lengths, dtype=np.int64).ravel()
        if lengths.size == 0:
            raise ValueError("an output length needs the lengths of at least one series")
        return max(2, int(self.function(lengths)))


#: ``Z = N T_max``: the paper's, which lets every series be stretched finely.
N_TIMES_LONGEST = OutputLength("N T_max", lambda lengths: lengths.size * lengths.max())
#: ``Z = min(N, 4) T_max``: the paper's value up to 4 series, then linear in N.
CAPPED = OutputLength(
    f"min(N, {LENGTH_FACTOR}) T_max",
    lambda lengths: min(lengths.size, LENGTH_FACTOR) * lengths.max(),
)
#: ``Z`` = the median length: a nearest-centroid classifier loses accuracy when the means
#: are longer than the series they are compared with (on the UCR development archive,
#: DBA's means resampled to 2 T and 4 T fall from 0.783 to 0.750 and 0.720; a mean as
#: long as the longest training series loses 0.12 on GesturePebbleZ1 against the
#: class's median length; docs: class means).
MEDIAN = OutputLength("median length", lambda lengths: np.round(np.median(lengths)))


@dataclass(frozen=True)
class Preset:
    """One preset: what it changes in the methods' defaults, and its output length.

    Attributes
    ----------
    name : str
    summary : str
        One line for the docs' presets table.
    output_length : OutputLength
        ``Z`` when ``output_length`` is not given.
    engine : mapping
        Values for every engine method (RTW, TTW, NTW) that has the knob.
    methods : mapping of str to mapping
        Values for one method, applied after ``engine``.
    chooses : bool
        Whether an estimator's ``"auto"`` band and centroids per class are chosen from
        the training data (:mod:`sk_rtw.estimators._selection`); otherwise ``"auto"`` is
        the paper's protocol, one mean per class and no band.
    """

    name: str
    summary: str
    output_length: OutputLength
    engine: Mapping[str, Any] = field(default_factory=dict)
    methods: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)
    chooses: bool = True

    def defaults(self, method: str) -> dict[str, Any]:
        """Every knob of ``method`` under this preset (``output_length``: None, the rule)."""
        values = method_defaults(method)
        if method in ENGINE_METHODS:
            values.update({k: v for k, v in self.engine.items() if k in values})
        values.update(self.methods.get(method, {}))
        return values


_ALIGNMENT_ENGINE = {
    "warp_knots": 64,
    # the warp network in single precision: 1.5x faster align on N = 30, T = 100, every
    # quality figure within its seeds' spread (docs/benchmarks/align_speed.md); the paper
    # preset keeps float64
    "warp_dtype": "float32",
    "tangent_refinements": 0,
    "mean_iterations": 2,
    "mean_start": "previous",
    "n_iter_no_change": 20,
    "tol": 1e-3,
}
# start from DTW paths; a zero readout makes the learned warp start at the identity, so
# the composed warps start exactly at the DTW start; a start that training has not come
# back to within 2.5 times its loss after 8 epochs is kept (the alignment-speed page:
# chosen on recorded losses of UCR seed 0, generated warped sets and the paper tables,
# confirmed on UCR seeds 1 and 2 and the long demonstrations), and one still more than
# 20 times it after 3 epochs (the rule's early tier, the trainer's)
_DTW_START = {"warp_start": "dtw", "init": "zero-readout", "start_patience": 8}

PRESETS: dict[str, Preset] = {
    preset.name: preset
    for preset in (
        Preset(
            "alignment",
            "aligning a few demonstrations (align's default)",
            CAPPED,
            engine=_ALIGNMENT_ENGINE,
            methods={"rtw": _DTW_START},
        ),
        Preset(
            "class-means",
            "class means for nearest-centroid classification (the estimators' default)",
            MEDIAN,
            engine={**_ALIGNMENT_ENGINE, "hidden_size": 64, "n_iter_no_change": 10},
            methods={
                "rtw": {
                    **_DTW_START,
                    "mean_weights": "density",
                    "start_axis": "reference",
                    "dtw_rounds": 11,
                    "smoothing": 0.5,
                }
            },
        ),
        Preset(
            "paper",
            "the paper's configuration of each method (section V)",
            N_TIMES_LONGEST,
            chooses=False,
        ),
    )
}


def _check_registry() -> None:
    for preset in PRESETS.values():
        unknown = set(preset.engine) | {k for v in preset.methods.values() for k in v}
        unknown -= set(KNOBS)
        if unknown:  # pragma: no cover - a programming error caught at import
            raise RuntimeError(f"preset {preset.name!r} sets unknown knobs {sorted(unknown)}")


_check_registry()
