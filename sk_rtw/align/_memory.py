"""The memory an alignment needs, estimated before any work, and a clear refusal when it
does not fit."""

from __future__ import annotations

import torch

from .._resources import available_memory, format_bytes
from ..utils import SeriesCollection
from ._config import AlignmentConfig
from ._problem import output_length
from ._sinc import table_budget


def estimated_memory(
    collection: SeriesCollection, config: AlignmentConfig, n_groups: int = 1
) -> int:
    """Rough peak bytes of an alignment: activations kept for the backward pass.

    Per output point and series: the interpolated point and its derivative, the
    distances, and for curved spaces the Gauss–Newton iterations of the mean; the table
    of window vectors; the network's activations at its evaluation times.
    """
    n_series, t_max = collection.n_series, collection.max_length
    z = output_length(config)
    point = max(1, collection.data[0, 0].size)
    curved = not collection.manifold.is_flat
    steps = config.mean_iterations if config.mean_start == "first" else 1
    per_point = 8 * (point * (6 + (4 * steps if curved else 0)) + 8)
    taps = t_max if config.sinc_window is None else 2 * config.sinc_window + 1
    table = 8 * n_series * t_max * taps * point
    table = table if table <= table_budget(torch.device(config.device)) else 0
    times = z if config.warp_knots is None else min(z, config.warp_knots)
    width = config.hidden_size or 0  # TTW's sine warps have no network
    network = 8 * 3 * times * (2 * width + 1 + n_series) + 8 * 4 * z * n_series
    parameters = network_memory(config, n_series, n_groups)
    return n_series * z * per_point + table + network + parameters


def network_memory(config: AlignmentConfig, n_series: int, n_groups: int = 1) -> int:
    """Bytes of the warp networks' weights with their gradients and Adam's two moments:
    one 1-H-H-(2H+1)-(N_g-1) network per group, about ``H^2 + 2 H N`` weights in all
    (none for TTW)."""
    width = config.hidden_size or 0
    per_group = width * width + 5 * width
    weights = n_groups * per_group + (2 * width + 1) * max(n_series - n_groups, 0)
    return 8 * 4 * weights


def check_memory(collection: SeriesCollection, config: AlignmentConfig, n_groups: int = 1) -> int:
    """``MemoryError`` naming the sizes when an alignment cannot fit in memory; else the
    estimated bytes (:func:`estimated_memory`)."""
    need, free = estimated_memory(collection, config, n_groups), available_memory()
    if need <= free:
        return need
    network = network_memory(config, collection.n_series, n_groups)
    if network > need / 2:
        raise MemoryError(
            f"the warp network of hidden_size={config.hidden_size} for "
            f"{collection.n_series} series needs about {format_bytes(network)} for its "
            f"weights and their optimiser state, more than the {format_bytes(free)} of "
            "memory available: lower hidden_size (the paper's is 512)"
        )
    raise MemoryError(
        f"aligning {collection.n_series} series to output_length Z={output_length(config)} "
        f"needs about {format_bytes(need)}, more than the {format_bytes(free)} of memory "
        "available: lower output_length (the paper preset uses N T_max), align fewer "
        "series at once, or use warp_knots"
    )
