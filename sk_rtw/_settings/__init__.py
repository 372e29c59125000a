"""The settings of the averaging methods, declared once: the knobs (every setting of
RTW, TTW, NTW and DBA with its accepted values and the paper's default), the presets (what
each named configuration changes) and their resolution. Both the alignment engine
(:mod:`sk_rtw.align`) and the method objects (:mod:`sk_rtw.methods`) stand on it.
"""

from ._knobs import (
    ENGINE_METHODS,
    INITS,
    KNOBS,
    START_AXES,
    Knob,
    method_defaults,
    method_knobs,
    owners,
)
from ._presets import PRESETS, OutputLength, Preset
from ._resolve import (
    DEVICE_PARAMETER,
    PRESET_PARAMETER,
    check_device,
    check_knobs,
    check_method,
    check_preset,
    knob_parameter,
    knobs_markdown,
    presets_markdown,
    resolve_knobs,
    settings_table,
)

__all__ = [
    "DEVICE_PARAMETER",
    "ENGINE_METHODS",
    "INITS",
    "KNOBS",
    "PRESETS",
    "PRESET_PARAMETER",
    "START_AXES",
    "Knob",
    "OutputLength",
    "Preset",
    "check_device",
    "check_knobs",
    "check_method",
    "check_preset",
    "knob_parameter",
    "knobs_markdown",
    "method_defaults",
    "method_knobs",
    "owners",
    "presets_markdown",
    "resolve_knobs",
    "settings_table",
]
