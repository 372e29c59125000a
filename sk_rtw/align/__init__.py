"""The alignment engine: Riemannian Time Warping and its TTW/NTW baselines."""

from ._align import align
from ._config import AlignmentConfig, knobs_markdown, presets_markdown
from ._knobs import ENGINE_METHODS, KNOBS, Knob
from ._presets import PRESETS, OutputLength, Preset
from ._result import Alignment
from ._sinc import tangent_sinc_interpolate

__all__ = [
    "ENGINE_METHODS",
    "KNOBS",
    "PRESETS",
    "Alignment",
    "AlignmentConfig",
    "Knob",
    "OutputLength",
    "Preset",
    "align",
    "knobs_markdown",
    "presets_markdown",
    "tangent_sinc_interpolate",
]
