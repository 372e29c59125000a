"""The engine's configuration: the resolved record of one run and its sizing to the
series.

:func:`resolve_config` resolves a method's settings (:func:`sk_rtw._settings.
resolve_knobs`: preset, then method, then yours) into an :class:`AlignmentConfig`, the
record the engine receives; :func:`size_config` adds what depends on the series (the
output length from the preset's rule).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass, fields, replace
from typing import Any

import numpy as np

from .._settings import KNOBS, PRESETS, resolve_knobs


@dataclass(frozen=True)
class AlignmentConfig:
    """The resolved configuration of one engine run (RTW, TTW or NTW).

    Every field is the value actually used; fields of knobs the method does not have
    (``hidden_size``, ``init``, ``warp_knots`` and ``warp_dtype`` for TTW's sine warps,
    ``n_components`` for the networks of RTW and NTW) are None. ``output_length`` is
    ``Z``, the length of ``Alignment.mean`` (shape ``(Z, *point_shape)``) and of every
    aligned series; ``warp_start`` is ``"given"`` when starting warps were passed as an
    array; ``dtw_window`` is the Sakoe-Chiba band of the DTW start (None: none). See
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
    warp_dtype: str | None = None
    start_patience: int | None = None

    def to_dict(self) -> dict[str, Any]:
        """The configuration as a plain dictionary (field name to value).

        Returns
        -------
        config : dict
        """
        return asdict(self)


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
