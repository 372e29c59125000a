"""The alignment engine: Riemannian Time Warping and its TTW/NTW baselines."""

from ._config import (
    METHOD_DEFAULTS,
    METHODS,
    PRESETS,
    AlignmentConfig,
    classification_output_length,
    default_output_length,
    method_defaults,
)
from ._engine import Alignment, align
from ._sinc import tangent_sinc_interpolate

__all__ = [
    "METHODS",
    "METHOD_DEFAULTS",
    "PRESETS",
    "Alignment",
    "AlignmentConfig",
    "align",
    "classification_output_length",
    "default_output_length",
    "method_defaults",
    "tangent_sinc_interpolate",
]
