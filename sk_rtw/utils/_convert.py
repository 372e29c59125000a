"""Conversions between sk_rtw's time-major layout and aeon's and tslearn's layouts.

sk_rtw: ``(n_series, n_timepoints)`` univariate, ``(n_series, n_timepoints, *point_shape)``,
or a list of ``(T_i, *point_shape)`` series of unequal lengths.

aeon: channels first, ``(n_cases, n_channels, n_timepoints)``, or a list of
``(n_channels, T_i)`` arrays for unequal lengths.

tslearn: ``(n_ts, sz, d)``, with series shorter than ``sz`` padded by NaN at the end.
"""

from __future__ import annotations

from typing import Any

import numpy as np


def _as_float(x: Any, name: str) -> np.ndarray:
    try:
        arr = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be numeric, got {type(x).__name__}") from None
    return arr


def from_aeon(X: Any) -> np.ndarray | list[np.ndarray]:
    """aeon's channels-first collection to sk_rtw's time-major layout.

    Parameters
    ----------
    X : array-like of shape (n_cases, n_channels, n_timepoints) or list of (n_channels, T_i)
        As returned by ``aeon.datasets.load_classification``.

    Returns
    -------
    X : ndarray of shape (n_cases, n_timepoints) if there is one channel, else
        (n_cases, n_timepoints, n_channels); a list of ``(T_i,)`` / ``(T_i, n_channels)``
        arrays for unequal lengths.

    Examples
    --------
    >>> import numpy as np
    >>> from sk_rtw.utils import from_aeon, to_aeon
    >>> X = np.zeros((40, 6, 100))  # aeon: 40 cases, 6 channels, 100 time points
    >>> from_aeon(X).shape
    (40, 100, 6)
    >>> to_aeon(from_aeon(X)).shape
    (40, 6, 100)
    """
    if isinstance(X, np.ndarray) or not isinstance(X, (list, tuple)):
        arr = _as_float(X, "X")
        if arr.ndim != 3:
            raise ValueError(
                f"aeon collections are 3-D (n_cases, n_channels, n_timepoints); got shape "
                f"{arr.shape}"
            )
        return arr[:, 0, :] if arr.shape[1] == 1 else np.swapaxes(arr, 1, 2)
    series = []
    for i, case in enumerate(X):
        case = _as_float(case, f"X[{i}]")
        if case.ndim != 2:
            raise ValueError(
                f"X[{i}] has shape {case.shape}; aeon cases are (n_channels, n_timepoints)"
            )
        series.append(case[0] if case.shape[0] == 1 else case.T)
    return series


def to_aeon(X: Any) -> np.ndarray | list[np.ndarray]:
    """sk_rtw's time-major collection to aeon's channels-first layout.

    Parameters
    ----------
    X : array-like of shape (n, T) or (n, T, d), or list of (T_i,) / (T_i, d) series

    Returns
    -------
    X : ndarray of shape (n, d, T) (``d = 1`` for univariate), or a list of ``(d, T_i)``
        arrays for unequal lengths.
    """
    if isinstance(X, np.ndarray) or not isinstance(X, (list, tuple)):
        arr = _as_float(X, "X")
        if arr.ndim == 2:
            return arr[:, None, :]
        if arr.ndim == 3:
            return np.swapaxes(arr, 1, 2)
        raise ValueError(f"expected (n, T) or (n, T, d), got shape {arr.shape}")
    out = []
    for i, s in enumerate(X):
        s = _as_float(s, f"X[{i}]")
        if s.ndim not in (1, 2):
            raise ValueError(f"X[{i}] has shape {s.shape}; expected (T,) or (T, d)")
        out.append(s[None, :] if s.ndim == 1 else s.T)
    return out


def from_tslearn(X: Any) -> np.ndarray | list[np.ndarray]:
    """tslearn's NaN-padded array to sk_rtw series (unequal lengths become a list).

    Trailing time points that are NaN in every channel are padding and are removed; NaN
    inside a series stays (and is then reported by the estimators as a missing value).

    Parameters
    ----------
    X : array-like of shape (n_ts, sz, d) or (n_ts, sz)

    Returns
    -------
    X : ndarray of shape (n_ts, sz) / (n_ts, sz, d) when nothing was padded, else a list
        of ``(T_i,)`` / ``(T_i, d)`` arrays.
    """
    arr = _as_float(X, "X")
    if arr.ndim == 2:
        arr = arr[:, :, None]
    if arr.ndim != 3:
        raise ValueError(f"tslearn datasets are (n_ts, sz, d); got shape {arr.shape}")
    observed = ~np.isnan(arr).all(axis=2)  # (n, sz)
    lengths = np.where(observed.any(1), arr.shape[1] - np.argmax(observed[:, ::-1], 1), 0)
    if np.any(lengths == 0):
        raise ValueError(f"series {int(np.argmin(lengths))} of X is NaN everywhere")
    squeeze = arr.shape[2] == 1
    if np.all(lengths == arr.shape[1]):
        return arr[:, :, 0] if squeeze else arr
    return [(s[:n, 0] if squeeze else s[:n]) for s, n in zip(arr, lengths, strict=True)]
