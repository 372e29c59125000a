"""Dynamic time warping with geodesic point costs on any manifold."""

from ._dtw import (
    dtw_cost_matrix,
    dtw_distance,
    dtw_pairwise_distance,
    dtw_path,
    point_cost_matrix,
)

__all__ = [
    "dtw_cost_matrix",
    "dtw_distance",
    "dtw_pairwise_distance",
    "dtw_path",
    "point_cost_matrix",
]
