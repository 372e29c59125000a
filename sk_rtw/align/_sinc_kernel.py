"""CPU kernel of the normalised sinc window sums: value and derivative in one pass.

For every output point ``(n, z)`` with centre sample ``b`` and fraction ``f`` it
accumulates, over the taps ``j`` of the window (offset ``k`` from ``b``), the barycentric
weights ``c = (-1)^k f / (f - k)`` (``c = 1`` at ``k = 0``) and their derivatives
``dc = (-1)^k (-k) / (f - k)^2`` (0 at ``k = 0``) against the tap vectors, and writes
``u = sum c V / sum c`` and ``du/df = (sum dc V - u sum dc) / sum c`` -- the formulas of
:func:`sk_rtw.align._sinc.barycentric_weights`, without materialising any weight tensor.

Window layouts (``window >= 0``: taps ``j = 0..2 window``, offset ``k = j - window``, every
tap valid; ``window < 0``: the full sinc, taps ``j = 0..T_n - 1``, offset ``k = j - b``).
``values[n, rows[n, z], j]`` is the vector of tap ``j`` for output point ``(n, z)``.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from .._numba import launch


def _window_sums(values, rows, base, frac, lengths, window, u, du):  # pragma: no cover
    n_series, n_points = frac.shape
    dim = values.shape[3]
    width = values.shape[2]
    for n in prange(n_series):
        weights = np.empty(width)
        slopes = np.empty(width)
        for z in range(n_points):
            b = base[n, z]
            f = frac[n, z]
            row = rows[n, z]
            if window >= 0:
                n_taps, centre, first = 2 * window + 1, window, -window
            else:
                n_taps, centre, first = lengths[n], b, -b
            # weights of the window first (a branch-free loop the compiler vectorises);
            # the centre tap divides by f = 0 at integer positions and is overwritten
            for j in range(n_taps):
                k = first + j
                inverse = 1.0 / (f - k)
                signed = (1.0 - 2.0 * (k & 1)) * inverse
                weights[j] = f * signed
                slopes[j] = -k * signed * inverse
            weights[centre] = 1.0
            slopes[centre] = 0.0
            total = 0.0
            slope = 0.0
            for j in range(n_taps):
                total += weights[j]
                slope += slopes[j]
            for d in range(dim):
                acc = 0.0
                dacc = 0.0
                for j in range(n_taps):
                    v = values[n, row, j, d]
                    acc += weights[j] * v
                    dacc += slopes[j] * v
                value = acc / total
                u[n, z, d] = value
                du[n, z, d] = (dacc - value * slope) / total


#: Serial and multi-threaded builds of the same kernel. Threads pay off only for large
#: problems: otherwise they compete with torch's own thread pool during the epoch.
#: IEEE division (``error_model="numpy"``): no zero check per tap.
#: ``nogil``: threads (a grid search on joblib's threading backend) run it side by side.
_OPTIONS = {"cache": True, "nogil": True, "error_model": "numpy"}
window_sums_serial = njit(**_OPTIONS)(_window_sums)
window_sums_parallel = njit(**_OPTIONS, parallel=True)(_window_sums)
#: Taps (N Z K) from which the multi-threaded build is used.
PARALLEL_TAPS = 2_000_000


def window_sums(values, rows, base, frac, lengths, window, u, du) -> None:
    """Fill ``u`` and ``du`` (N, Z, D); see the module docstring for the layouts."""
    n_taps = frac.size * (values.shape[2] if window < 0 else 2 * window + 1)
    launch(window_sums_serial, window_sums_parallel, n_taps, PARALLEL_TAPS,
           values, rows, base, frac, lengths, window, u, du)  # fmt: skip
