"""DTW-family baselines for aligning and averaging N series on a manifold.

- :func:`dba_average`: DTW barycenter averaging with Fréchet means.
- :func:`pdtw_average`: progressive pairwise DTW averaging (p-DTW).
- :func:`mmddtw_align`: globally optimal joint DTW of N series (MMDDTW), geodesic or
  Cholesky distance.
- :func:`qdtw`, :func:`qdtw_align`: quaternion DTW with a sign-invariant cost, for two
  or N series.

All return a :class:`MultipleAlignment` (mean, aligned series, matched indices), except
:func:`qdtw`, which returns a path and a distance like :func:`sk_rtw.dtw_path`.
"""

from ._dba import dba_average
from ._mmddtw import grid_bytes, mmddtw_align
from ._pdtw import pdtw_average
from ._qdtw import qdtw, qdtw_align, quaternion_cost_matrix
from ._result import MultipleAlignment

__all__ = [
    "MultipleAlignment",
    "dba_average",
    "grid_bytes",
    "mmddtw_align",
    "pdtw_average",
    "qdtw",
    "qdtw_align",
    "quaternion_cost_matrix",
]
