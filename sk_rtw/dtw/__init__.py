"""Dynamic time warping with geodesic point costs on any manifold.

Besides the distances, the helpers that the DTW-family baselines and the alignment
engine share: :func:`check_window` (the Sakoe–Chiba argument), :func:`optimal_path` (a
path through a point-cost matrix), :func:`path_indices` (the path between two series) and
:func:`medoid_index` (the DTW medoid of a collection), and :func:`multiscale_path` (a
coarse-to-fine banded path for long series). :func:`dtw_nearest_distance` finds the
nearest series of every group with lower bounds and early abandoning.
"""

from ._band import multiscale_path
from ._dtw import (
    check_window,
    dtw_cost_matrix,
    dtw_distance,
    dtw_pairwise_distance,
    dtw_path,
    point_cost_matrix,
)
from ._paths import medoid_index, optimal_path, path_indices
from ._search import dtw_nearest_distance

__all__ = [
    "check_window",
    "dtw_cost_matrix",
    "dtw_distance",
    "dtw_nearest_distance",
    "dtw_pairwise_distance",
    "dtw_path",
    "medoid_index",
    "multiscale_path",
    "optimal_path",
    "path_indices",
    "point_cost_matrix",
]
