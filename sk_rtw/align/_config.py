"""Resolution of a method's configuration, in one place: preset, then method, then yours.

:func:`resolve_knobs` starts from the knobs' defaults for the method (the paper's),
applies the preset's changes (:mod:`sk_rtw.align._presets`), then the values given
explicitly (already checked by :func:`check_knobs`; ``"auto"`` leaves the preset's
value). :func:`resolve_config` does that for the engine's methods and adds the output
length from the preset's rule. Every entry point -- :func:`sk_rtw.align`, the method
objects of the estimators -- goes through here, so a preset name means the same
everywhere. The tables of the docs are rendered from the same records
(:func:`presets_markdown`, :func:`knobs_markdown`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass, fields, replace
from typing import Any

import numpy as np
import torch

from ..utils._params import AUTO, InstanceOf, Options, Parameter
from ._knobs import ENGINE_METHODS, KNOBS, method_knobs, owners
from ._presets import PRESETS


@dataclass(frozen=True)
class AlignmentConfig:
    """The resolved configuration of one engine run (RTW, TTW or NTW).

    Every field is the value actually used; fields of knobs the method does not have
    (``hidden_size``, ``init`` and ``warp_knots`` for TTW's sine warps, ``n_components``
    for the networks of RTW and NTW) are None. ``output_length`` is ``Z``, the length of
    ``Alignment.mean`` (shape ``(Z, *point_shape)``) and of every aligned series;
    ``warp_start`` is ``"given"`` when starting warps were passed as an array;
    ``dtw_window`` is the Sakoe-Chiba band of the DTW start (None: none). See
    :func:`sk_rtw.align` and the knobs table of the user guide for each field.
    """

    method: str
    preset: str
    warp: str
    init: str | None
    warp_start: str
    dtw_rounds: int
    output_length: int | None
    n_epochs: int
    learning_rate: float
    sinc_window: int | None
    loss_window: int
    loss_step: int
    penalty: float
    n_components: int | None
    hidden_size: int | None
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
    dtw_window: float | None = None
    refine_steps: int = 0

    def to_dict(self) -> dict[str, Any]:
        """The configuration as a plain dictionary (field name to value).

        Returns
        -------
        config : dict
        """
        return asdict(self)


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


def resolve_config(
    method: str,
    preset: str,
    explicit: Mapping[str, Any],
    *,
    device: str = "cpu",
    given_start: bool = False,
    dtw_window: float | None = None,
) -> AlignmentConfig:
    """The engine configuration of ``method``: preset, then method, then ``explicit``.

    Parameters
    ----------
    method : {"rtw", "ttw", "ntw"}
    preset : str
        A key of :data:`sk_rtw.methods.PRESETS`.
    explicit : mapping
        Checked explicit knob values (:func:`check_knobs`).
    device : str, default="cpu"
        A checked device.
    given_start : bool, default=False
        Starting warps were passed as an array.
    dtw_window : float or None, default=None
        A checked Sakoe-Chiba band of the DTW start.

    Returns
    -------
    AlignmentConfig
        ``output_length`` None unless given: :func:`size_config` applies the preset's
        rule to the series.
    """
    values = resolve_knobs(method, preset, explicit)
    if given_start:
        values["warp_start"] = "given"
    # the knobs; those of other methods (TTW's network, RTW's sine terms) are None
    knobs: dict[str, Any] = {name: values.get(name) for name in _KNOB_FIELDS}
    return AlignmentConfig(
        method=method,
        preset=preset,
        warp="neural" if method in ("rtw", "ntw") else "sine",
        device=device,
        dtw_window=dtw_window,
        **knobs,
    )


def size_config(config: AlignmentConfig, lengths: Any) -> AlignmentConfig:
    """``config`` for series of these ``lengths``: the output length by the preset's rule
    when not given, the sinc window no wider than the longest series (a wider one reads
    no more data).

    Parameters
    ----------
    config : AlignmentConfig
    lengths : array-like of int
        Lengths of the series averaged together.

    Returns
    -------
    AlignmentConfig
    """
    changes: dict[str, Any] = {}
    if config.output_length is None:
        changes["output_length"] = PRESETS[config.preset].output_length(lengths)
    longest = int(np.max(lengths))
    if config.sinc_window is not None and config.sinc_window > longest:
        changes["sinc_window"] = longest
    return replace(config, **changes) if changes else config


#: The fields of :class:`AlignmentConfig` that hold a knob's value.
_KNOB_FIELDS = tuple(f.name for f in fields(AlignmentConfig) if f.name in KNOBS)


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
                cells.append(
                    ", ".join(f"{m.upper()}: {_cell(v)}" for m, v in changed.items())
                )
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
