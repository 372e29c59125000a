"""The alignment engine: Riemannian Time Warping and its TTW/NTW baselines."""

from .._settings import (
    ENGINE_METHODS,
    KNOBS,
    PRESETS,
    Knob,
    OutputLength,
    Preset,
    check_device,
    knobs_markdown,
    presets_markdown,
)
from ._align import align
from ._config import AlignmentConfig, resolve_config, size_config
from ._fit import align_collection
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
    "align_collection",
    "check_device",
    "knobs_markdown",
    "presets_markdown",
    "resolve_config",
    "size_config",
    "tangent_sinc_interpolate",
]
