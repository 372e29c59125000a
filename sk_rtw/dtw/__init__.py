"""Dynamic time warping with geodesic point costs on any manifold.

Besides the distances, the helpers that the DTW-family baselines and the alignment
engine share (this package's ``__init__`` is their only door to it):
:func:`check_window` (the Sakoe–Chiba argument), :func:`point_cost_matrix` and
:func:`optimal_path` (a path through a point-cost matrix), :func:`path_indices` (the path
between two series), :func:`mean_matched_positions` (the mean matched positions of many
pairs in one compiled pass, for manifolds with :func:`has_compiled_costs`),
:func:`medoid_index` (the DTW medoid of a collection), :func:`multiscale_path` (a
coarse-to-fine banded path for long series, exact below the size
:func:`solved_exactly` tells), :func:`coarse_collection` (series halved by geodesic
midpoints) and :func:`soft_dtw_batch` (soft-DTW values and expected alignments).
:func:`dtw_nearest_distance` finds the nearest series of every group with lower bounds
and early abandoning; :func:`prepare_series` puts a collection in the kernels' form once
for many searches on the calling thread (:func:`nearest_group`, and
:func:`mean_diagonal_cost`, the scale of amerced DTW's penalty). :func:`window_distances`
and :func:`shapelet_features` slide a shapelet over windows of series (``_sliding``);
:func:`read_window`, :func:`series_window_profile` and :func:`series_window_feature` read
the windows of Euclidean series in place (z-normalised as numpy does) and
:func:`linear_percentiles` is numpy's percentile, for one shapelet at a time;
:func:`numpy_column_sum` is numpy's sum of a column, in its order.

The modules stand on floors, each importing only those below it: the compiled point
costs (``_point_costs``, rows of costs from the manifolds' point geometry, which is the
table :mod:`sk_rtw.manifolds._point_kernels`: no module here names a manifold); the
compiled recursion (``_kernels``, and ``_pruned`` with the point costs inside it;
``_soft``); point-cost matrices and the optimal path through them (``_costs``); the
coarse-to-fine band (``_band``); paths between series (``_paths``); the distances
(``_dtw``); their consumers (``_medoid``, ``_search``); prepared series for many
searches (``_prepared``).
"""

from ._band import coarse_collection, multiscale_path, solved_exactly
from ._costs import optimal_path, point_cost_matrix
from ._dtw import check_window, dtw_cost_matrix, dtw_distance, dtw_pairwise_distance, dtw_path
from ._medoid import medoid_index
from ._paths import has_compiled_costs, mean_matched_positions, path_indices
from ._point_costs import kernel_point_form
from ._prepared import EXPONENTS, PreparedSeries, mean_diagonal_cost, nearest_group, prepare_series
from ._search import dtw_nearest_distance
from ._sliding import (
    linear_percentiles,
    numpy_column_sum,
    read_window,
    series_window_feature,
    series_window_profile,
    shapelet_features,
    window_distances,
    window_profiles,
)
from ._soft import soft_dtw_batch

__all__ = [
    "EXPONENTS",
    "PreparedSeries",
    "check_window",
    "coarse_collection",
    "dtw_cost_matrix",
    "dtw_distance",
    "dtw_nearest_distance",
    "dtw_pairwise_distance",
    "dtw_path",
    "has_compiled_costs",
    "kernel_point_form",
    "linear_percentiles",
    "mean_diagonal_cost",
    "mean_matched_positions",
    "medoid_index",
    "multiscale_path",
    "nearest_group",
    "numpy_column_sum",
    "optimal_path",
    "path_indices",
    "point_cost_matrix",
    "prepare_series",
    "read_window",
    "series_window_feature",
    "series_window_profile",
    "shapelet_features",
    "soft_dtw_batch",
    "solved_exactly",
    "window_distances",
    "window_profiles",
]
