"""The settings of the averaging methods resolved in one place: preset, then method,
then yours.

:func:`resolve_knobs` starts from the knobs' defaults for the method (the paper's),
applies the preset's changes (:mod:`._presets`), then the values given explicitly
(already checked by :func:`check_knobs`; ``"auto"`` leaves the preset's value). Every
entry point -- :func:`sk_rtw.align`, the method objects of the estimators -- goes through
here, so a preset name means the same everywhere. The tables of the docs are rendered
from the same records (:func:`presets_markdown`, :func:`knobs_markdown`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import torch

from ..utils._constraints import AUTO, InstanceOf, Options
from ..utils._params import Parameter
from ._knobs import ENGINE_METHODS, KNOBS, method_knobs, owners
from ._presets import PRESETS


def check_method(method: Any, methods: tuple[str, ...] = ENGINE_METHODS) -> str:
    """The method's name in lower case, or a ``ValueError`` listing ``methods``."""
    return Parameter("method", (Options(methods),), "").check(method)


def check_preset(preset: Any) -> str:
    """The preset's name in lower case, or a ``ValueError`` listing the presets."""
    return PRESET_PARAMETER.check(preset)


def check_device(device: Any) -> str:
    """A torch device that exists on this machine, as a string; clear errors otherwise."""
    return DEVICE_PARAMETER.check(device)


def _device(name: str, device: Any) -> str:
    try:
        resolved = torch.device(device)
    except (RuntimeError, TypeError, ValueError):
        raise ValueError(
            f"{name} must be a torch device such as 'cpu', 'cuda' or 'cuda:0', got {device!r}"
        ) from None
    if resolved.type == "cuda" and not torch.cuda.is_available():
        build = "a CPU-only build" if torch.version.cuda is None else "a CUDA build"
        raise ValueError(
            f"{name}={device!r}, but torch finds no CUDA device (torch {torch.__version__} is "
            f"{build}); use device='cpu' or install a CUDA build of torch on a GPU machine"
        )
    if resolved.type == "cuda" and resolved.index is not None:
        if resolved.index >= torch.cuda.device_count():
            raise ValueError(
                f"{name}={device!r}, but only {torch.cuda.device_count()} CUDA device(s) exist"
            )
    if resolved.type == "mps" and not torch.backends.mps.is_available():
        raise ValueError(f"{name}={device!r}, but torch finds no MPS device")
    return str(resolved)


PRESET_PARAMETER = Parameter(
    "preset",
    (Options(tuple(PRESETS)),),
    "Named configuration of the averaging method, resolved before explicit settings: "
    + "; ".join(f'"{p.name}": {p.summary}' for p in PRESETS.values())
    + ". The presets table of the user guide lists every value.",
)
DEVICE_PARAMETER = Parameter(
    "device",
    (
        InstanceOf(
            "str or torch.device", "a torch device", types=(str, torch.device), normaliser=_device
        ),
    ),
    'Torch device of the engine\'s optimisation (RTW, TTW, NTW), e.g. "cuda"; results '
    "are numpy arrays. DBA and the DTW computations run on the CPU.",
)


def knob_parameter(name: str) -> Parameter:
    """The declared knob ``name``, accepting ``"auto"`` (the preset's value) too."""
    return KNOBS[name].with_auto()


def check_knobs(method: str, values: Mapping[str, Any], owner: str = "align()") -> dict[str, Any]:
    """Check explicit knob values for ``method``; the canonical ones, ``"auto"`` dropped.

    Raises
    ------
    TypeError
        For a name that is no knob, or a knob of other methods only (naming them).
    InvalidParameterError
        For a value the knob does not accept.
    """
    label = method.upper()
    mine = {knob.name for knob in method_knobs(method)}
    checked = {}
    for name, value in values.items():
        if name not in mine:
            others = owners(name)
            if not others:
                raise TypeError(
                    f"unknown option {name!r} for {owner}; {label}'s settings are {sorted(mine)}"
                )
            raise TypeError(
                f"{name} is not a setting of {label} (it sets "
                f"{', '.join(m.upper() for m in others)}); {label}'s settings are "
                f"{sorted(mine)}"
            )
        canonical = knob_parameter(name).check(value)
        if not (isinstance(canonical, str) and canonical == AUTO):
            checked[name] = canonical
    return checked


def resolve_knobs(method: str, preset: str, explicit: Mapping[str, Any]) -> dict[str, Any]:
    """Every knob of ``method``: its default, the preset's change, the explicit value."""
    values = PRESETS[preset].defaults(method)
    values.update(explicit)
    return values


# ------------------------------------------------------------------ docs tables
#: The methods the knobs are declared for, in declaration order (the table's columns).
_METHODS = tuple(dict.fromkeys(m for knob in KNOBS.values() for m in knob.methods))


def _cell(value: Any) -> str:
    if value is None:
        return "None"
    if isinstance(value, str):
        return f'"{value}"'
    return f"{value:g}" if isinstance(value, float) else str(value)


def presets_markdown() -> str:
    """The presets table of the user guide: the paper's value of every knob per method,
    and what each other preset changes."""
    others = [p for p in PRESETS if p != "paper"]
    header = ["knob", " / ".join(m.upper() for m in _METHODS) + " (paper)", *others]
    lines = ["| " + " | ".join(header) + " |", "|" + " --- |" * len(header)]
    for name, knob in KNOBS.items():
        if name == "output_length":
            cells = [PRESETS["paper"].output_length.formula]
            cells += [PRESETS[p].output_length.formula for p in others]
            lines.append("| " + " | ".join([f"`{name}`", *cells]) + " |")
            continue
        paper = " / ".join(_cell(knob.defaults.get(m)) if m in knob.defaults else "–"
                           for m in _METHODS)  # fmt: skip
        cells = [paper]
        for p in others:
            changed = {
                m: PRESETS[p].defaults(m)[name]
                for m in knob.methods
                if PRESETS[p].defaults(m)[name] != knob.defaults[m]
            }
            values = set(map(_cell, changed.values()))
            if not changed:
                cells.append("")
            elif len(values) == 1 and set(changed) == set(knob.methods) - {"dba"}:
                cells.append(values.pop())
            else:
                cells.append(", ".join(f"{m.upper()}: {_cell(v)}" for m, v in changed.items()))
        lines.append("| " + " | ".join([f"`{name}`", *cells]) + " |")
    return "\n".join(lines)


def settings_table(method: str, first: str) -> str:
    """Every setting of ``method`` with its value under each preset, ``first`` first: an
    reStructuredText table for the estimators' docstrings (``help()`` shows what runs).

    Parameters
    ----------
    method : str
        A method the knobs are declared for ("rtw", ..., "dba").
    first : str
        The preset shown first (the estimator's default).

    Returns
    -------
    str
    """
    presets = [first, *(p for p in PRESETS if p != first)]
    rows = [["setting", *(f'preset="{p}"' for p in presets)]]
    for knob in method_knobs(method):
        if knob.name == "output_length":
            cells = [PRESETS[p].output_length.formula for p in presets]
        else:
            cells = [_cell(PRESETS[p].defaults(method)[knob.name]) for p in presets]
        rows.append([f"``{knob.name}``", *cells])
    widths = [max(len(row[i]) for row in rows) for i in range(len(rows[0]))]
    rule = "  ".join("=" * w for w in widths)
    lines = [rule, "  ".join(c.ljust(w) for c, w in zip(rows[0], widths, strict=True)).rstrip(),
             rule]  # fmt: skip
    lines += ["  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)).rstrip()
              for row in rows[1:]]  # fmt: skip
    return "\n".join([*lines, rule])


def knobs_markdown() -> str:
    """The knobs table of the user guide: methods, accepted values, meaning."""
    lines = ["| knob | methods | accepts | meaning |", "| --- | --- | --- | --- |"]
    for name, knob in KNOBS.items():
        methods = ", ".join(m.upper() for m in knob.methods)
        accepts = knob.with_auto().type_doc().replace("|", "\\|")
        lines.append(f"| `{name}` | {methods} | {accepts} | {knob.doc} |")
    return "\n".join(lines)
