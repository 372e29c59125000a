"""The alignment engine: Riemannian Time Warping and its TTW/NTW baselines."""

from ._engine import (
    METHOD_DEFAULTS,
    METHODS,
    Alignment,
    AlignmentConfig,
    align,
    default_output_length,
)
from ._sinc import tangent_sinc_interpolate

__all__ = [
    "METHODS",
    "METHOD_DEFAULTS",
    "Alignment",
    "AlignmentConfig",
    "align",
    "default_output_length",
    "tangent_sinc_interpolate",
]
